// SPDX-License-Identifier: Apache-2.0
#include "app/sculpt_controller.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#define GLFW_INCLUDE_NONE // key codes only: this file uses no window
#include <GLFW/glfw3.h>

#include "io/baked_tool.h"
#include "io/fluid_cache.h"
#include "io/mesh_file.h"
#include "levelset/band.h"
#include "levelset/raycast.h"

namespace sweepers {

namespace {

glm::dvec3 toGlm(const Eigen::Vector3d& v) {
    return {v.x(), v.y(), v.z()};
}
Eigen::Vector3d toEigen3(const glm::dvec3& v) {
    return {v.x, v.y, v.z};
}

} // namespace

void SculptController::setDocument(Document* doc) {
    wait();
    collect();
    doc_ = doc;
    drag_ = DragKind::None;
    pending_ = releasing_ = false;
    if (doc_) {
        doc_->setInterrupter(&stop_);
        volume_ = doc_->mesher().enclosedVolume();
    }
}

void SculptController::setViewport(int width, int height) {
    width_ = std::max(width, 1);
    height_ = std::max(height, 1);
}

void SculptController::onButton(int button, bool press, double x, double y, bool shift, bool ctrl) {
    if (!doc_) return;
    cursorX_ = x;
    cursorY_ = y;
    if (sizing_ != Sizing::None) {
        // The click that ends F or Shift-F keeps what the mouse set; it sculpts nothing.
        if (press && button == 0) sizing_ = Sizing::None;
        return;
    }
    if (!press) {
        if (drag_ == DragKind::Sculpt) {
            // The last position counts; the drag ends once its work is done.
            pending_ = true;
            releasing_ = true;
            step();
        } else {
            drag_ = DragKind::None;
        }
        return;
    }
    if (busy() || drag_ == DragKind::Sculpt) return;
    pressX_ = lastX_ = x;
    pressY_ = lastY_ = y;
    if (button == 1 || button == 2) {
        drag_ = DragKind::Pan;
        return;
    }
    mode_ = shift ? SculptMode::Smooth : settings_.mode;
    inverted_ = ctrl;
    const auto hit = sculpting_ ? pick(x, y) : std::nullopt;
    if (!hit) {
        drag_ = DragKind::Orbit;
        return;
    }
    grab_ = *hit;
    axis_ = glm::normalize(camera_.eye() - camera_.target);
    last_ = placementAt(x, y);
    drag_ = DragKind::Sculpt;
    pending_ = false;
    stop_.reset();
    if (topologyMode()) {
        beginTopologyDrag();
        return;
    }
    if (mode_ == SculptMode::Swirl || mode_ == SculptMode::Fluid || dabMode()) {
        doc_->beginEdit();
        if (dabMode()) {
            pendingSince_ = Clock::now();
            mode_ == SculptMode::Clay ? dab(grab_) : smoothDab(grab_);
        }
        return;
    }
    ToolSpec tool;
    tool.shape = ToolShapeKind::Ball;
    tool.size = Eigen::Vector3d::Constant(settings_.radius);
    tool.falloff = settings_.falloff;
    tool.path = {last_};
    if (settings_.bakedTool && mode_ != SculptMode::Inflate) {
        // The baked tool at the size the radius asks (its own half-size is 1), with a band
        // for this falloff (loaded again only when the falloff outgrows the last band).
        tool.shape = ToolShapeKind::Baked;
        tool.source = settings_.bakedSource;
        tool.size = Eigen::Vector3d::Constant(settings_.radius / settings_.bakedRadius);
        try {
            tool.baked =
                loadBakedTool(tool.source, "", tool.size.x(), tool.falloff / tool.size.x());
        } catch (const std::exception& e) {
            message_ = e.what();
            drag_ = DragKind::None;
            return;
        }
    }
    SweepStroke stroke;
    stroke.mirror = settings_.mirror;
    stroke.tools = {tool};
    stroke.strength = settings_.strength;
    stroke.radial = radial();
    doc_->beginStroke(stroke);
}

RadialSymmetry SculptController::radial() const {
    RadialSymmetry r;
    r.axis = Eigen::Vector3d::Unit(std::clamp(settings_.radialAxis, 0, 2));
    r.count = std::clamp(settings_.radialCount, 1, 64);
    return r;
}

void SculptController::useToolFile(const std::string& path) {
    BakedToolSource source;
    source.kind = isMeshPath(path) ? BakedToolSource::Kind::Mesh : BakedToolSource::Kind::Vdb;
    source.file = std::filesystem::absolute(path).lexically_normal().string();
    if (source.kind == BakedToolSource::Kind::Mesh && doc_)
        source.voxelSize = doc_->grid().voxelSize()[0];
    const auto shape = loadBakedTool(source, "", 1.0, settings_.falloff);
    const Box b = shape->place(Eigen::Affine3d::Identity())->bounds();
    settings_.bakedTool = shape;
    settings_.bakedSource = source;
    settings_.bakedRadius = 0.5 * b.extent().maxCoeff();
}

void SculptController::useBall() {
    settings_.bakedTool.reset();
}

// Pinch and strangle: the press finds where the view ray leaves the shape again; the
// stroke is set up between the two sides.
void SculptController::beginTopologyDrag() {
    const glm::dvec3 dir = glm::normalize(grab_ - camera_.eye());
    const auto out =
        exitLevelSet(doc_->grid(), toEigen3(grab_), toEigen3(dir), 1e3 * camera_.distance);
    if (!out) {
        message_ = "the view ray does not come out of the shape there";
        drag_ = DragKind::None;
        return;
    }
    through_ = 0.5 * (grab_ + toGlm(*out));
    depth_ = glm::length(toGlm(*out) - grab_);
    axis_ = dir;
    applied_ = false;
}

std::optional<Stroke> SculptController::topologyStroke() const {
    if (!doc_ || drag_ != DragKind::Sculpt || !topologyMode()) return std::nullopt;
    const glm::dvec3 w =
        camera_.dragInViewPlane(grab_, pressX_, pressY_, cursorX_, cursorY_, width_, height_);
    const double h = doc_->grid().voxelSize()[0], f = settings_.falloff;
    if (mode_ == SculptMode::Pinch) {
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
    s.open = settings_.radius;
    return s;
}

void SculptController::stepTopologyDrag() {
    pending_ = false; // the preview follows the cursor by itself
    if (!releasing_) return;
    if (applied_) {
        finishDrag(); // its work is done
        return;
    }
    const std::optional<Stroke> stroke = topologyStroke();
    if (!stroke) {
        message_ = "drag across the limb: the drag's length is the strangling circle's radius";
        drag_ = DragKind::None;
        releasing_ = false;
        return;
    }
    applied_ = true;
    doc_->beginEdit();
    Document* doc = doc_;
    pendingSince_ = Clock::now();
    launch([doc, st = *stroke] { return doc->applyStroke(st); });
}

// Clay mode: one inflation of the tool's radius (2.30) centred half a radius under the
// surface point p (along the view ray), so that it adds the whole ball (a centre inside
// the material gives the inserted ball its sign).
// With Ctrl, a ball sucked back into its centre (2.31), which takes away the material
// inside it: a whole radius under the surface, so that all of it is material and a dab
// takes away what one adds. A dab's radial copies are dabs turned about the axis.
void SculptController::dab(const glm::dvec3& p) {
    const double depth = (inverted_ ? 1.0 : 0.5) * settings_.radius;
    const glm::dvec3 in = p + depth * glm::normalize(p - camera_.eye());
    InflateStroke stroke{toEigen3(in), settings_.radius};
    stroke.strength = settings_.strength;
    stroke.remove = inverted_;
    stroke.radial = radial();
    Document* doc = doc_;
    launch([doc, stroke] { return doc->applyStroke(stroke); });
    lastDab_ = p;
    dabX_ = cursorX_;
    dabY_ = cursorY_;
}

// One dab of smoothing centred on the surface point p, and its radial copies. (Smoothing
// has no inverse worth having: sharpening is the heat equation run backward, which blows
// up the finest noise first. Ctrl changes nothing.)
void SculptController::smoothDab(const glm::dvec3& p) {
    SmoothStroke stroke;
    stroke.tool.size = Eigen::Vector3d::Constant(settings_.radius);
    stroke.tool.falloff = settings_.falloff;
    stroke.strength = settings_.smoothStrength;
    stroke.radial = radial();
    Placement at;
    at.t = toEigen3(p);
    stroke.tool.path = {at};
    Document* doc = doc_;
    launch([doc, stroke] { return doc->applyStroke(stroke); });
    lastDab_ = p;
    dabX_ = cursorX_;
    dabY_ = cursorY_;
}

void SculptController::onMove(double x, double y) {
    const double dx = x - lastX_, dy = y - lastY_;
    cursorX_ = x;
    cursorY_ = y;
    if (sizing_ != Sizing::None) {
        moveSizing(x, y);
        lastX_ = x;
        lastY_ = y;
        return;
    }
    switch (drag_) {
    case DragKind::Orbit:
        camera_.orbit(-dx * 0.008, dy * 0.008);
        break;
    case DragKind::Pan:
        camera_.pan(dx / height_, dy / height_);
        break;
    case DragKind::Sculpt:
        // Coalesced: one piece per step, at the latest position; its latency counts from
        // the first event it absorbs.
        if (!pending_) pendingSince_ = Clock::now();
        pending_ = true;
        break;
    case DragKind::None:
        break;
    }
    lastX_ = x;
    lastY_ = y;
}

void SculptController::onScroll(double dy, bool ctrl) {
    if (ctrl)
        settings_.radius = std::clamp(settings_.radius * std::pow(1.1, dy), 0.02, 2.0);
    else
        camera_.zoom(std::pow(0.9, dy));
}

KeyAction SculptController::onKey(int key, bool ctrl, bool shift) {
    if (!doc_) return KeyAction::None;
    if (key == GLFW_KEY_ESCAPE) {
        if (sizing_ != Sizing::None) {
            (sizing_ == Sizing::Radius ? settings_.radius : sizedStrength()) = sizingFrom_;
            sizing_ = Sizing::None;
            return KeyAction::None;
        }
        if (busy()) cancel();
        return KeyAction::Cancel;
    }
    if (ctrl && busy()) return KeyAction::None; // undo and save wait for the sculpting
    if (ctrl && key == 'Z') {
        shift ? doc_->redo() : doc_->undo();
        volume_ = doc_->mesher().enclosedVolume();
        return KeyAction::None;
    }
    if (ctrl && key == 'S') return KeyAction::Save;
    if (ctrl || (drag_ == DragKind::Sculpt && std::isalpha(key))) return KeyAction::None;
    for (const ModeInfo& m : kModes)
        if (key == m.key) {
            settings_.mode = m.mode;
            return KeyAction::None;
        }
    double& size = shift ? settings_.falloff : settings_.radius; // [ and ]: shift for falloff
    switch (key) {
    case 'F':
        if (drag_ == DragKind::None) beginSizing(shift ? Sizing::Strength : Sizing::Radius);
        break;
    case GLFW_KEY_HOME:
        if (!busy()) frameView();
        break;
    case 'W':
        settings_.wireframe = !settings_.wireframe;
        break;
    case 'M':
        settings_.mirror = MirrorAxis((int(settings_.mirror) + 1) % 4);
        break;
    case '[':
        size = std::max(0.02, size / 1.1);
        break;
    case ']':
        size = std::min(2.0, size * 1.1);
        break;
    case GLFW_KEY_LEFT:
        camera_.orbit(-0.1, 0);
        break;
    case GLFW_KEY_RIGHT:
        camera_.orbit(0.1, 0);
        break;
    case GLFW_KEY_UP:
        camera_.orbit(0, 0.1);
        break;
    case GLFW_KEY_DOWN:
        camera_.orbit(0, -0.1);
        break;
    case GLFW_KEY_EQUAL:
        camera_.zoom(0.9);
        break;
    case GLFW_KEY_MINUS:
        camera_.zoom(1.0 / 0.9);
        break;
    default:
        break;
    }
    return KeyAction::None;
}

void SculptController::dispatch(const InputEvent& e) {
    switch (e.type) {
    case InputEvent::Type::Press:
    case InputEvent::Type::Release:
        onMove(e.x, e.y);
        onButton(e.button, e.type == InputEvent::Type::Press, e.x, e.y, e.shift, e.ctrl);
        break;
    case InputEvent::Type::Move:
        onMove(e.x, e.y);
        break;
    case InputEvent::Type::Key:
        onKey(e.key, e.ctrl, e.shift);
        break;
    case InputEvent::Type::Scroll:
        onScroll(e.dy, e.ctrl);
        break;
    case InputEvent::Type::Drop:
        break;
    }
}

std::optional<glm::dvec3> SculptController::pick(double x, double y) const {
    if (!doc_) return std::nullopt;
    const Ray r = camera_.rayThrough(x, y, width_, height_);
    const auto hit = raycastLevelSet(doc_->grid(), toEigen3(r.origin), toEigen3(r.direction),
                                     1e3 * camera_.distance);
    if (!hit) return std::nullopt;
    return toGlm(*hit);
}

// F: the circle is drawn about the surface point under the cursor when F was pressed (or
// the view's centre off the shape), and the mouse's distance from that point on the screen,
// taken into the view plane there, is the radius. Shift-F: that distance over a fifth of
// the window's height is the strength.
void SculptController::beginSizing(Sizing what) {
    sizing_ = what;
    sizingX_ = cursorX_;
    sizingY_ = cursorY_;
    sizingAt_ = pick(cursorX_, cursorY_).value_or(camera_.target);
    sizingFrom_ = what == Sizing::Radius ? settings_.radius : sizedStrength();
}

void SculptController::moveSizing(double x, double y) {
    if (sizing_ == Sizing::Radius) {
        const glm::dvec3 w =
            camera_.dragInViewPlane(sizingAt_, sizingX_, sizingY_, x, y, width_, height_);
        settings_.radius = std::clamp(glm::length(w), 0.02, 2.0);
    } else {
        // A fifth of the window's height is full strength: 1, or the smooth tool's most.
        const double pixels = std::hypot(x - sizingX_, y - sizingY_);
        const double most = settings_.mode == SculptMode::Smooth ? kMostSmoothStrength : 1.0;
        sizedStrength() = std::clamp(most * pixels / (0.2 * height_), 0.01, most);
    }
}

double& SculptController::sizedStrength() {
    return settings_.mode == SculptMode::Smooth ? settings_.smoothStrength : settings_.strength;
}

std::optional<glm::dvec3> SculptController::toolCentre() const {
    if (sizing_ != Sizing::None) return sizingAt_;
    if (drag_ == DragKind::Sculpt) {
        if (dabMode() || topologyMode()) return std::nullopt;
        return toGlm(last_.t);
    }
    if (drag_ == DragKind::None && !busy() && sculpting_) return pick(cursorX_, cursorY_);
    return std::nullopt;
}

void SculptController::frameView() {
    if (!doc_) return;
    const Box b = activeWorldBox(doc_->grid());
    camera_.frame(toGlm(b.min), toGlm(b.max));
    volume_ = doc_->mesher().enclosedVolume();
}

// The tool placement for the cursor at (x, y) during a drag, by mode; with Ctrl, the
// hand's motion reversed (grab, swirl and fluid pull the other way, twist turns back,
// inflate deflates).
Placement SculptController::placementAt(double x, double y) const {
    Placement p;
    p.t = toEigen3(grab_);
    const double sign = inverted_ ? -1.0 : 1.0;
    switch (mode_) {
    case SculptMode::Grab:
    case SculptMode::Swirl:
    case SculptMode::Fluid:
    case SculptMode::Clay:
    case SculptMode::Pinch:
    case SculptMode::Strangle:
    case SculptMode::Smooth:
        p.t = toEigen3(grab_ +
                       (topologyMode() ? 1.0 : sign) *
                           camera_.dragInViewPlane(grab_, pressX_, pressY_, x, y, width_, height_));
        break;
    case SculptMode::Twist:
        p.axis = toEigen3(axis_);
        p.angleDegrees = sign * std::clamp(0.5 * (x - pressX_), -720.0, 720.0);
        break;
    case SculptMode::Inflate:
        p.scale = Eigen::Vector3d::Constant(
            std::exp(sign * std::clamp(-(y - pressY_), -400.0, 400.0) * 0.004));
        break;
    }
    return p;
}

std::vector<Placement> SculptController::placementsTo(const Placement& target) const {
    if (mode_ != SculptMode::Twist) return {target};
    // The cursor gives an absolute angle; the hand's way from the last one is the
    // difference, however large, cut into equal turns no larger than the limit.
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

void SculptController::launch(std::function<SegmentReport()> task) {
    workSince_ = pendingSince_;
    // A replay waits for each piece, so the window's thread runs it itself. On a worker
    // thread, the worker and TBB's thread it wakes can queue on one of the two vCPUs of a
    // virtual machine whose kernel sees no shared cache (so a wakeup looks for no idle
    // core) while the other stays idle: a replay, which measures latency, would measure
    // the scheduler instead of the engine.
    work_ = std::async(waitEach_ ? std::launch::deferred : std::launch::async, std::move(task));
    if (waitEach_) work_.wait();
}

// Takes finished work (its report, or why it failed).
void SculptController::collect() {
    if (!busy() || work_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    try {
        finished_ = Finished{work_.get(), workSince_};
    } catch (const Cancelled&) {
        // The document has put the edit back already.
        drag_ = DragKind::None;
        releasing_ = pending_ = false;
        volume_ = doc_->mesher().enclosedVolume();
        message_ = "the stroke was cancelled; the shape is as it was before it";
    } catch (const std::exception& e) {
        doc_->endEdit();
        drag_ = DragKind::None;
        releasing_ = pending_ = false;
        message_ = e.what();
    }
}

void SculptController::finishDrag() {
    doc_->endEdit();
    volume_ = doc_->mesher().enclosedVolume();
    drag_ = DragKind::None;
    releasing_ = false;
}

// One piece of sculpting for the latest cursor position of a drag: a sweep segment (or a
// few, for a fast twist), a swirl ring, a fluid push or a dab of clay.
void SculptController::step() {
    collect();
    if (busy()) return;
    if (idle_) idle_();
    if (drag_ != DragKind::Sculpt) return;
    if (topologyMode()) {
        stepTopologyDrag();
        return;
    }
    if (pending_) {
        pending_ = false;
        Document* doc = doc_;
        if (dabMode()) {
            // A new dab of clay once the cursor has moved half a radius, of smoothing a
            // quarter (in the view plane: the surface under a still cursor rises with every
            // dab of clay).
            const double moved = glm::length(camera_.dragInViewPlane(
                lastDab_, dabX_, dabY_, cursorX_, cursorY_, width_, height_));
            const double spacing = mode_ == SculptMode::Clay ? 0.5 : 0.25;
            if (moved >= spacing * settings_.radius) {
                if (const auto hit = pick(cursorX_, cursorY_)) {
                    mode_ == SculptMode::Clay ? dab(*hit) : smoothDab(*hit);
                    return;
                }
            }
        } else if (const Placement p = placementAt(cursorX_, cursorY_); !(p == last_)) {
            if (mode_ == SculptMode::Swirl) {
                // A swirl ring carries the clay from the last position to this one.
                SwirlStroke sw;
                sw.at = last_.t;
                sw.move = p.t - last_.t;
                sw.radius = settings_.radius;
                sw.strength = settings_.strength;
                sw.radial = radial();
                launch([doc, sw] { return doc->applyStroke(sw); });
            } else if (mode_ == SculptMode::Fluid) {
                // The ball pushes the clay as through a fluid from the last position to this
                // one. The first fluid piece of a run finds the solution (from the cache, or
                // a solve of a few seconds) on the worker, not in the window's thread.
                FluidStroke fl;
                fl.radius = settings_.radius;
                fl.path = {last_.t, p.t};
                fl.strength = settings_.strength;
                launch([doc, fl]() mutable {
                    fl.fluid = sweptFluid();
                    return doc->applyStroke(fl);
                });
            } else {
                const std::vector<Placement> path = placementsTo(p);
                launch([doc, path] {
                    SegmentReport r;
                    for (const Placement& q : path)
                        r = doc->extendStroke(q);
                    return r;
                });
            }
            last_ = p;
            return;
        }
    }
    if (releasing_) finishDrag();
}

namespace {

// A circle of radius r about c in the plane normal to n, as 48 segments.
void addCircle(std::vector<glm::dvec3>& lines, const glm::dvec3& c, const glm::dvec3& n, double r) {
    const glm::dvec3 a = glm::normalize(
        glm::cross(n, std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
    const glm::dvec3 b = glm::cross(n, a);
    const int segments = 48;
    for (int i = 0; i < segments; ++i)
        for (int k : {i, i + 1}) {
            const double t = 2.0 * M_PI * k / segments;
            lines.push_back(c + r * (std::cos(t) * a + std::sin(t) * b));
        }
}

} // namespace

std::vector<glm::dvec3> SculptController::symmetryPreview(const glm::dvec3& centre) const {
    std::vector<glm::dvec3> lines;
    const glm::dvec3 facing = glm::normalize(camera_.eye() - camera_.target);
    std::vector<glm::dvec3> copies;
    const RadialSymmetry r = radial();
    copies.reserve(2 * std::size_t(r.count));
    for (int k = 0; k < r.count; ++k)
        copies.push_back(toGlm(r.turn(k) * toEigen3(centre)));
    // Mirror planes copy the sweeps (grab, twist, inflate) only.
    const SculptMode m = settings_.mode;
    const bool sweeps = m == SculptMode::Grab || m == SculptMode::Twist || m == SculptMode::Inflate;
    if (settings_.mirror != MirrorAxis::None && sweeps) {
        const int axis = int(settings_.mirror) - 1;
        for (std::size_t k = 0, n = copies.size(); k < n; ++k) {
            glm::dvec3 m = copies[k];
            m[axis] = -m[axis];
            copies.push_back(m);
        }
    }
    for (std::size_t k = 1; k < copies.size(); ++k)
        addCircle(lines, copies[k], facing, settings_.radius);
    return lines;
}

std::vector<glm::dvec3> strokePreview(const Stroke& stroke) {
    std::vector<glm::dvec3> lines;
    if (const auto* p = std::get_if<PinchStroke>(&stroke)) {
        const glm::dvec3 at = toGlm(p->at), axis = glm::normalize(toGlm(p->axis));
        for (double side : {1.0, -1.0})
            lines.insert(lines.end(), {at + side * p->size * axis, at});
        addCircle(lines, at, axis, p->open);
    } else if (const auto* s = std::get_if<StrangleStroke>(&stroke)) {
        const glm::dvec3 at = toGlm(s->at), axis = glm::normalize(toGlm(s->axis));
        addCircle(lines, at, axis, s->size);
        lines.insert(lines.end(), {at - 0.5 * s->open * axis, at + 0.5 * s->open * axis});
    }
    return lines;
}

ReplayClock::ReplayClock(std::vector<InputEvent> events)
    : events_(std::move(events)), lastFrame_(events_.empty() ? 1 : events_.back().frame + 2) {}

void ReplayClock::deliver(const SculptController& controller,
                          const std::function<void(const InputEvent&)>& dispatch) {
    if (!controller.readyForEvents()) return;
    for (; next_ < events_.size() && events_[next_].frame == frame_; ++next_)
        dispatch(events_[next_]);
}

void ReplayClock::endFrame(const SculptController& controller) {
    if (controller.readyForEvents()) ++frame_;
}

void replayEvents(SculptController& controller, const std::vector<InputEvent>& events) {
    ReplayClock clock(events);
    while (!clock.over() || controller.busy() || controller.drag() != DragKind::None) {
        clock.deliver(controller, [&](const InputEvent& e) { controller.dispatch(e); });
        controller.step();
        clock.endFrame(controller);
        if (clock.overtime() > 1000) break; // a drag never released: stop waiting for it
    }
    controller.wait();
    controller.step();
}

} // namespace sweepers
