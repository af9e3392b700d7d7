// SPDX-License-Identifier: Apache-2.0
#include "sculpt/stroke.h"

#include <cmath>
#include <stdexcept>

#include "tools/ellipsoid.h"

namespace sweepers {

Eigen::Affine3d RadialSymmetry::turn(int k) const {
    return Eigen::Translation3d(center) *
           Eigen::AngleAxisd(2.0 * M_PI * k / count, axis.normalized()) *
           Eigen::Translation3d(-center);
}

std::vector<Eigen::Vector3d> FluidStroke::ballPath() const {
    std::vector<Eigen::Vector3d> out = path;
    for (Eigen::Vector3d& p : out)
        p = path.front() + strength * (p - path.front());
    return out;
}

Sweep toSweep(const SweepStroke& stroke) {
    Sweep sweep;
    sweep.mirror = stroke.mirror;
    for (const ToolSpec& t : stroke.tools) {
        SweptTool st;
        switch (t.shape) {
        case ToolShapeKind::Ball:
            st.shape = std::make_shared<EllipsoidShape>(t.size.x());
            break;
        case ToolShapeKind::Ellipsoid:
            st.shape = std::make_shared<EllipsoidShape>(t.size);
            break;
        case ToolShapeKind::Baked:
            if (!t.baked)
                throw std::invalid_argument("the baked tool " + t.source.file + " was not loaded");
            st.shape = t.baked;
            break;
        }
        st.falloff = t.falloff;
        st.path = t.path;
        // A fraction of the hand's motion: each placement that fraction of the way from the
        // first along the motion to it, exp(s log(P_k P_0^-1)) P_0 (as 3.12's sub-steps are).
        if (stroke.strength != 1.0)
            for (std::size_t k = 1; k < st.path.size(); ++k) {
                const auto along = placementAlong(t.path.front(), t.path[k], stroke.strength);
                if (!along)
                    throw std::invalid_argument("a placement of the stroke has no fraction of "
                                                "its motion (strength)");
                st.path[k] = *along;
            }
        sweep.tools.push_back(std::move(st));
    }
    // Radial copies: every tool turned about the axis, each copy a simultaneous tool of the
    // same sweep, blended with the others by the normalized log blend (3.16-3.18) as mirror
    // copies are (3.3.2). A turned placement T R S stays of that form: A T R S with A a
    // rotation about the axis is T' (R_A R) S.
    const RadialSymmetry& radial = stroke.radial;
    if (radial.count > 1) {
        const std::size_t originals = sweep.tools.size();
        for (int k = 1; k < radial.count; ++k) {
            const Eigen::Affine3d turn = radial.turn(k);
            for (std::size_t i = 0; i < originals; ++i) {
                SweptTool copy = sweep.tools[i];
                for (Placement& p : copy.path) {
                    const auto turned = placementOf((turn * p.matrix()).matrix());
                    if (!turned)
                        throw std::invalid_argument("a radial copy of a placement is not a "
                                                    "placement");
                    p = *turned;
                }
                sweep.tools.push_back(std::move(copy));
            }
        }
    }
    return sweep;
}

SwirlSpec toSwirl(const SwirlStroke& stroke, int copy) {
    const Eigen::Affine3d turn = stroke.radial.turn(copy);
    SwirlSpec s;
    s.at = turn * stroke.at;
    s.move = stroke.strength * (turn.linear() * stroke.move);
    s.radius = stroke.radius;
    s.ring = stroke.ring;
    s.swirls = stroke.swirls;
    return s;
}

double keyedDuration(const Stroke& stroke) {
    if (const auto* k = std::get_if<KeyframedStroke>(&stroke)) return k->keys.times.back();
    if (const auto* sl = std::get_if<SlideStroke>(&stroke)) return sl->frame.times.back();
    return 0.0;
}

std::vector<std::unique_ptr<SweepSegment>> planKeyedStroke(const Stroke& stroke, double time) {
    std::vector<std::unique_ptr<SweepSegment>> parts;
    if (const auto* k = std::get_if<KeyframedStroke>(&stroke)) {
        const Placement rest = k->keys.placements.front();
        const Placement target = keyedPlacement(k->keys, time);
        if (target == rest) return parts;
        SweepStroke grab;
        grab.tools = {k->tool};
        grab.tools[0].path = {rest, target};
        parts.push_back(std::make_unique<SweepSegment>(toSweep(grab), 0));
        return parts;
    }
    const auto* slide = std::get_if<SlideStroke>(&stroke);
    if (!slide) throw std::invalid_argument("not a keyed stroke");
    const Eigen::Matrix4d F = keyedPlacement(slide->frame, time).matrix().matrix();
    SweepStroke moved = slide->local;
    for (ToolSpec& tool : moved.tools)
        for (Placement& p : tool.path) {
            // A uniform scale commutes with the rotations: F P is T R S again.
            const std::optional<Placement> q = placementOf(F * p.matrix().matrix());
            if (!q) throw std::invalid_argument("a slide's frame must scale uniformly");
            p = *q;
        }
    const Sweep sweep = toSweep(moved);
    for (std::size_t k = 0; k < sweep.segmentCount(); ++k)
        parts.push_back(std::make_unique<SweepSegment>(sweep, k));
    return parts;
}

SmoothBrush smoothDab(const SmoothStroke& stroke, std::size_t k) {
    SmoothBrush b;
    const int n = stroke.radial.count;
    b.center =
        stroke.radial.turn(int(k % std::size_t(n))) * stroke.tool.path.at(k / std::size_t(n)).t;
    b.radius = stroke.tool.size.x();
    b.falloff = stroke.tool.falloff;
    b.time = stroke.strength * kSmoothTimePerRadius2 * b.radius * b.radius;
    return b;
}

std::size_t segmentCount(const Stroke& stroke, double voxelSize) {
    if (const auto* sweep = std::get_if<SweepStroke>(&stroke))
        return toSweep(*sweep).segmentCount();
    if (const auto* pinch = std::get_if<PinchStroke>(&stroke)) return pinchSegmentCount(*pinch);
    if (const auto* strangle = std::get_if<StrangleStroke>(&stroke))
        return planStrangle(*strangle, voxelSize).size();
    if (const auto* slide = std::get_if<SlideStroke>(&stroke))
        return toSweep(slide->local).segmentCount();
    if (const auto* flow = std::get_if<FlowStroke>(&stroke))
        return std::size_t(std::max(1, flow->segments));
    if (const auto* fluid = std::get_if<FluidStroke>(&stroke))
        return fluid->path.size() < 2 ? 0 : fluid->path.size() - 1;
    if (const auto* smooth = std::get_if<SmoothStroke>(&stroke))
        return smooth->tool.path.size() * std::size_t(smooth->radial.count);
    if (const auto* swirl = std::get_if<SwirlStroke>(&stroke))
        return std::size_t(swirl->radial.count);
    if (const auto* inflate = std::get_if<InflateStroke>(&stroke))
        return std::size_t(inflate->radial.count);
    return 1;
}

} // namespace sweepers
