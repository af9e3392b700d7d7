// SPDX-License-Identifier: Apache-2.0
#include "app/gestures.h"

#include <algorithm>
#include <cmath>

#include "app/glm_eigen.h"
#include "io/baked_tool.h"
#include "io/fluid_cache.h"
#include "levelset/raycast.h"

namespace sweepers {

namespace {

// The hand's motion since the press, in the view plane; with Ctrl, reversed.
Placement translation(const GestureTools& t, const Press& p) {
    Placement q;
    q.t = toEigen3(p.at + (p.inverted ? -1.0 : 1.0) * t.dragFrom(p.at, p.x, p.y));
    return q;
}

// Grab, twist and inflate: one sweep stroke for the drag, a segment for each piece (a few,
// for a fast twist). With Ctrl, the hand's motion reversed: grab pulls the other way, twist
// turns back, inflate deflates.
class SweepGesture : public Gesture {
  public:
    SweepGesture(SculptMode mode, const Press& p) : mode_(mode), press_(p) {}

    std::optional<std::string> press(const GestureTools& t) override {
        axis_ = glm::normalize(t.camera.eye() - t.camera.target);
        last_ = placementAt(t);
        const ToolSettings& s = t.settings;
        ToolSpec tool;
        tool.shape = ToolShapeKind::Ball;
        tool.size = Eigen::Vector3d::Constant(s.radius);
        tool.falloff = s.falloff;
        tool.path = {last_};
        if (s.bakedTool && mode_ != SculptMode::Inflate) {
            // The baked tool at the size the radius asks (its own half-size is 1), with a band
            // for this falloff (loaded again only when the falloff outgrows the last band).
            tool.shape = ToolShapeKind::Baked;
            tool.source = s.bakedSource;
            tool.size = Eigen::Vector3d::Constant(s.radius / s.bakedRadius);
            try {
                tool.baked =
                    loadBakedTool(tool.source, "", tool.size.x(), tool.falloff / tool.size.x());
            } catch (const std::exception& e) {
                return std::string(e.what());
            }
        }
        SweepStroke stroke;
        stroke.mirror = s.mirror;
        stroke.tools = {tool};
        stroke.strength = s.strength;
        stroke.radial = t.radial;
        t.doc.beginStroke(stroke);
        return std::nullopt;
    }

    bool move(const GestureTools& t) override {
        const Placement p = placementAt(t);
        if (p == last_) return false;
        Document* doc = &t.doc;
        t.launch([doc, path = placementsTo(p)] {
            SegmentReport r;
            for (const Placement& q : path)
                r = doc->extendStroke(q);
            return r;
        });
        last_ = p;
        return true;
    }

    std::optional<glm::dvec3> toolCentre() const override { return toGlm(last_.t); }

  private:
    Placement placementAt(const GestureTools& t) const {
        const double sign = press_.inverted ? -1.0 : 1.0;
        if (mode_ == SculptMode::Grab) return translation(t, press_);
        Placement p;
        p.t = toEigen3(press_.at);
        if (mode_ == SculptMode::Twist) {
            p.axis = toEigen3(axis_);
            p.angleDegrees = sign * std::clamp(0.5 * (t.cursorX - press_.x), -720.0, 720.0);
        } else {
            p.scale = Eigen::Vector3d::Constant(
                std::exp(sign * std::clamp(-(t.cursorY - press_.y), -400.0, 400.0) * 0.004));
        }
        return p;
    }

    // The placements from the last one to `target`: a twist's cursor gives an absolute angle,
    // and the hand's way from the last one is the difference, however large, cut into equal
    // turns no larger than the limit.
    std::vector<Placement> placementsTo(const Placement& target) const {
        if (mode_ != SculptMode::Twist) return {target};
        const double turn = target.angleDegrees - last_.angleDegrees;
        const int pieces = std::max(1, int(std::ceil(std::abs(turn) / kMaxTwistStepDegrees)));
        std::vector<Placement> out;
        for (int k = 1; k <= pieces; ++k) {
            Placement p = target;
            p.angleDegrees =
                k == pieces ? target.angleDegrees : last_.angleDegrees + turn * double(k) / pieces;
            out.push_back(p);
        }
        return out;
    }

    SculptMode mode_;
    Press press_;
    glm::dvec3 axis_{0, 0, 1}; // a twist's: the view's at the press
    Placement last_;
};

// Swirl and fluid: each piece carries the clay from the last position to the cursor's,
// keeping its volume: a swirl ring (4.1), or the ball pushed as through a fluid (4.2).
class PushGesture : public Gesture {
  public:
    PushGesture(bool fluid, const Press& p) : fluid_(fluid), press_(p) {}

    std::optional<std::string> press(const GestureTools& t) override {
        last_ = translation(t, press_);
        t.doc.beginEdit();
        return std::nullopt;
    }

    bool move(const GestureTools& t) override {
        const Placement p = translation(t, press_);
        if (p == last_) return false;
        Document* doc = &t.doc;
        const ToolSettings& s = t.settings;
        if (fluid_) {
            // The first fluid piece of a run finds the solution (from the cache, or a solve of
            // a few seconds) on the worker, not in the window's thread.
            FluidStroke fl;
            fl.radius = s.radius;
            fl.path = {last_.t, p.t};
            fl.strength = s.strength;
            t.launch([doc, fl]() mutable {
                fl.fluid = sweptFluid();
                return doc->applyStroke(fl);
            });
        } else {
            SwirlStroke sw;
            sw.at = last_.t;
            sw.move = p.t - last_.t;
            sw.radius = s.radius;
            sw.strength = s.strength;
            sw.radial = t.radial;
            t.launch([doc, sw] { return doc->applyStroke(sw); });
        }
        last_ = p;
        return true;
    }

    std::optional<glm::dvec3> toolCentre() const override { return toGlm(last_.t); }

  private:
    bool fluid_;
    Press press_;
    Placement last_;
};

// Clay and smooth: a dab under the cursor at the press, and a new one once the cursor has
// moved half a radius (clay) or a quarter (smoothing), in the view plane: the surface under a
// still cursor rises with every dab of clay.
class DabGesture : public Gesture {
  public:
    DabGesture(bool smooth, const Press& p) : smooth_(smooth), press_(p) {}

    std::optional<std::string> press(const GestureTools& t) override {
        t.doc.beginEdit();
        dab(t, press_.at);
        return std::nullopt;
    }

    bool move(const GestureTools& t) override {
        const double moved = glm::length(t.dragFrom(last_, x_, y_));
        if (moved < (smooth_ ? 0.25 : 0.5) * t.settings.radius) return false;
        const auto hit = t.pick(t.cursorX, t.cursorY);
        if (!hit) return false;
        dab(t, *hit);
        return true;
    }

  private:
    void dab(const GestureTools& t, const glm::dvec3& p) {
        Document* doc = &t.doc;
        const ToolSettings& s = t.settings;
        if (smooth_) {
            // Smoothing has no inverse worth having (sharpening is the heat equation run
            // backward, which blows up the finest noise first): Ctrl changes nothing.
            SmoothStroke stroke;
            stroke.tool.size = Eigen::Vector3d::Constant(s.radius);
            stroke.tool.falloff = s.falloff;
            stroke.strength = s.smoothStrength;
            stroke.radial = t.radial;
            Placement at;
            at.t = toEigen3(p);
            stroke.tool.path = {at};
            t.launch([doc, stroke] { return doc->applyStroke(stroke); });
        } else {
            // One inflation of the tool's radius (2.30) centred half a radius under the
            // surface point (along the view ray), so that it adds the whole ball (a centre
            // inside the material gives the inserted ball its sign). With Ctrl, a ball sucked
            // back into its centre (2.31), a whole radius under the surface, so that all of it
            // is material and a dab takes away what one adds.
            const double depth = (press_.inverted ? 1.0 : 0.5) * s.radius;
            const glm::dvec3 in = p + depth * glm::normalize(p - t.camera.eye());
            InflateStroke stroke{toEigen3(in), s.radius};
            stroke.strength = s.strength;
            stroke.remove = press_.inverted;
            stroke.radial = t.radial;
            t.launch([doc, stroke] { return doc->applyStroke(stroke); });
        }
        last_ = p;
        x_ = t.cursorX;
        y_ = t.cursorY;
    }

    bool smooth_;
    Press press_;
    glm::dvec3 last_{0.0}; // the last dab's surface point, and the cursor there
    double x_ = 0, y_ = 0;
};

// Pinch and strangle: the press finds where the view ray leaves the shape again, the drag
// sets the stroke up between the two sides (shown as a preview), the release applies it.
class TopologyGesture : public Gesture {
  public:
    TopologyGesture(bool pinch, const Press& p) : pinch_(pinch), press_(p) {}

    std::optional<std::string> press(const GestureTools& t) override {
        const glm::dvec3 dir = glm::normalize(press_.at - t.camera.eye());
        const auto out =
            exitLevelSet(t.doc.grid(), toEigen3(press_.at), toEigen3(dir), 1e3 * t.camera.distance);
        if (!out) return std::string("the view ray does not come out of the shape there");
        through_ = 0.5 * (press_.at + toGlm(*out));
        depth_ = glm::length(toGlm(*out) - press_.at);
        axis_ = dir;
        return std::nullopt;
    }

    bool move(const GestureTools&) override { return false; } // the preview follows by itself

    Release release(const GestureTools& t, std::string& message) override {
        if (applied_) return Release::Done; // its work is done
        const std::optional<Stroke> s = stroke(t);
        if (!s) {
            message = "drag across the limb: the drag's length is the strangling circle's radius";
            return Release::Refused;
        }
        applied_ = true;
        t.doc.beginEdit();
        Document* doc = &t.doc;
        t.launch([doc, st = *s] { return doc->applyStroke(st); });
        return Release::Launched;
    }

    std::optional<Stroke> stroke(const GestureTools& t) const override {
        const glm::dvec3 w = t.dragFrom(press_.at, press_.x, press_.y);
        const double h = t.doc.grid().voxelSize()[0], f = t.settings.falloff;
        if (pinch_) {
            // The tips start half a falloff outside both sides; the drag opens the hole. The
            // needles' funnels are as thin as their falloff allows: below about 13 voxels the
            // grid loses them on axes off its own (measured on a unit sphere at 1/32: a plug
            // stays for 10 voxels along (1, 1, 1), not for 12.8), so the falloff is at least 16.
            PinchStroke s;
            const double falloff = std::max(f, kMinPinchFalloffVoxels * h);
            s.at = toEigen3(through_);
            s.axis = toEigen3(axis_);
            s.size = 0.5 * depth_ + 0.5 * falloff;
            s.falloff = falloff;
            s.open = std::max(glm::length(w), 2.0 * h);
            return s;
        }
        // The drag goes across the limb: its length is the circle's radius, and with the view
        // ray it spans the circle's plane.
        if (glm::length(w) < 2.0 * h) return std::nullopt;
        StrangleStroke s;
        s.at = toEigen3(through_);
        s.axis = toEigen3(glm::normalize(glm::cross(w, axis_)));
        s.size = glm::length(w);
        s.falloff = f;
        s.open = t.settings.radius;
        return s;
    }

  private:
    bool pinch_;
    Press press_;
    // The middle of the shape along the view ray, its depth there, the ray's direction.
    glm::dvec3 through_{0.0}, axis_{0, 0, 1};
    double depth_ = 0.0;
    bool applied_ = false;
};

} // namespace

std::unique_ptr<Gesture> makeGesture(SculptMode mode, const Press& press) {
    switch (mode) {
    case SculptMode::Grab:
    case SculptMode::Twist:
    case SculptMode::Inflate:
        return std::make_unique<SweepGesture>(mode, press);
    case SculptMode::Swirl:
    case SculptMode::Fluid:
        return std::make_unique<PushGesture>(mode == SculptMode::Fluid, press);
    case SculptMode::Clay:
    case SculptMode::Smooth:
        return std::make_unique<DabGesture>(mode == SculptMode::Smooth, press);
    case SculptMode::Pinch:
    case SculptMode::Strangle:
        return std::make_unique<TopologyGesture>(mode == SculptMode::Pinch, press);
    }
    return nullptr;
}

// F: the circle is drawn about the surface point under the cursor when F was pressed (or the
// view's centre off the shape), and the mouse's distance from that point on the screen, taken
// into the view plane there, is the radius. Shift-F: that distance over a fifth of the
// window's height is the strength: the smooth tool's own, or every other tool's.
ToolSizing::ToolSizing(Sizing what, double x, double y, const glm::dvec3& at,
                       ToolSettings& settings)
    : what_(what), x_(x), y_(y), from_(0), at_(at) {
    from_ = what == Sizing::Radius ? settings.radius : strengthOf(settings);
}

double& ToolSizing::strengthOf(ToolSettings& s) {
    return s.mode == SculptMode::Smooth ? s.smoothStrength : s.strength;
}

void ToolSizing::move(double x, double y, const OrbitCamera& camera, int width, int height,
                      ToolSettings& settings) const {
    if (what_ == Sizing::Radius) {
        const glm::dvec3 w = camera.dragInViewPlane(at_, x_, y_, x, y, width, height);
        settings.radius = std::clamp(glm::length(w), 0.02, 2.0);
    } else {
        // A fifth of the window's height is full strength: 1, or the smooth tool's most.
        const double pixels = std::hypot(x - x_, y - y_);
        const double most = settings.mode == SculptMode::Smooth ? kMostSmoothStrength : 1.0;
        strengthOf(settings) = std::clamp(most * pixels / (0.2 * height), 0.01, most);
    }
}

void ToolSizing::putBack(ToolSettings& settings) const {
    (what_ == Sizing::Radius ? settings.radius : strengthOf(settings)) = from_;
}

} // namespace sweepers
