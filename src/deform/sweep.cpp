// SPDX-License-Identifier: Apache-2.0
#include "deform/sweep.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/falloff.h"

namespace sweepers {

namespace {

// A segment needing more sub-steps than this is refused rather than planned: it would
// take minutes per voxel block, and it is almost always a typing error in a script.
constexpr int kMaxSteps = 4096;
constexpr double kMaxTurnDegrees = 179.0;

Eigen::Affine3d affine(const Eigen::Matrix4d& M) {
    Eigen::Affine3d A;
    A.matrix() = M;
    return A;
}

} // namespace

Eigen::Matrix4d mirrorMatrix(MirrorAxis axis) {
    Eigen::Matrix4d R = Eigen::Matrix4d::Identity();
    switch (axis) {
    case MirrorAxis::X:
        R(0, 0) = -1;
        break;
    case MirrorAxis::Y:
        R(1, 1) = -1;
        break;
    case MirrorAxis::Z:
        R(2, 2) = -1;
        break;
    case MirrorAxis::None:
        break;
    }
    return R;
}

std::size_t Sweep::segmentCount() const {
    if (tools.empty()) throw std::invalid_argument("a sweep needs at least one tool");
    const std::size_t n = tools.front().path.size();
    for (const SweptTool& t : tools) {
        if (!t.shape) throw std::invalid_argument("a swept tool has no shape");
        if (t.path.size() < 2) throw std::invalid_argument("a tool path needs two placements");
        if (t.path.size() != n)
            throw std::invalid_argument("tools swept together need the same number of placements");
    }
    return n - 1;
}

SweepSegment::SweepSegment(const Sweep& sweep, std::size_t index, const SegmentOptions& options) {
    forwardTolerance_ = options.forwardTolerance;
    forwardMaxIterations_ = options.forwardMaxIterations;
    if (index >= sweep.segmentCount()) throw std::invalid_argument("segment index out of range");

    // Each tool's start placement and motion log; a mirror adds the reflected tool, placed
    // by R X (its mirror image) and moved by R M R (R^-1 = R).
    struct Source {
        const SweptTool* tool;
        Eigen::Matrix4d XA, XB;
        MotionLog log;
    };
    std::vector<Source> sources;
    const Eigen::Matrix4d R = mirrorMatrix(sweep.mirror);
    for (const SweptTool& t : sweep.tools) {
        const Eigen::Matrix4d XA = t.path[index].matrix().matrix();
        const Eigen::Matrix4d XB = t.path[index + 1].matrix().matrix();
        const MotionLog log = MotionLog::log(XB * XA.inverse());
        // The log of a rigid motion takes the shorter way round; near a half turn that way
        // is ambiguous, and a tiny edit would flip the direction of the sculpted twist.
        if (log.kind() == MotionLog::Kind::Twist &&
            log.twist().omega.norm() > kMaxTurnDegrees * M_PI / 180.0)
            throw std::domain_error("the tool turns by more than " +
                                    std::to_string(int(kMaxTurnDegrees)) +
                                    " degrees between two placements; add one in between");
        sources.push_back({&t, XA, XB, log});
        if (sweep.mirror != MirrorAxis::None)
            sources.push_back({&t, R * XA, R * XB, log.conjugated(R)});
    }

    // Sub-step count, 3.19: s > -sum_j min(mu_j') max_l |log M_j . p_l| over the corners of
    // the coating boxes. The thesis takes the box at the start only; a scale grows the
    // coating, so the end box is measured too. The slope of phi is mu' times the slope of
    // the distance: 1 for an exact distance, the shape's bound for a sampled one.
    double bound = 0.0;
    for (const Source& s : sources) {
        double vmax = 0.0, lipschitz = 1.0;
        for (const Eigen::Matrix4d& X : {s.XA, s.XB}) {
            const PlacedTool placed(s.tool->shape->place(affine(X)), s.tool->falloff);
            for (const Eigen::Vector3d& c : placed.coatingBounds().corners())
                vmax = std::max(vmax, s.log.velocity(c).norm());
            lipschitz = std::max(lipschitz, placed.lipschitz());
        }
        bound += -falloffMuMinSlope(s.tool->falloff) * lipschitz * vmax;
    }
    stepBound_ = bound;
    if (!std::isfinite(bound) || bound >= kMaxSteps)
        throw std::domain_error("the motion needs more than " + std::to_string(kMaxSteps) +
                                " sub-steps; split it into more placements");
    steps_ = options.forceSteps > 0 ? options.forceSteps
                                    : std::max(1, static_cast<int>(std::floor(bound)) + 1);
    // One tool translated by t: inverse sub-step k is p - phi_k(p) t / s (5.18), whose
    // displacement is |t| / s times the slope of phi_k, so B / s Lipschitz (B the bound above,
    // |t| the velocity everywhere). The displacement of s of them composed is
    // (1 + B / s)^s - 1 Lipschitz, and so is each column of its central differences: their
    // matrix spreads points apart by at most 1 + sqrt(3) ((1 + B / s)^s - 1).
    if (sources.size() == 1 && sources[0].log.kind() == MotionLog::Kind::Translation)
        stretchBound_ =
            1.0 + std::sqrt(3.0) * std::expm1(double(steps_) * std::log1p(bound / steps_));

    // Sub-step placements tau_k = (k/s (.) M) X_A (3.12); tau_s is X_B exactly.
    stepBoxes_.assign(steps_, Box());
    for (const Source& s : sources) {
        ToolPlan plan;
        plan.log = s.log;
        plan.stepLog = s.log * (1.0 / steps_);
        for (int k = 0; k <= steps_; ++k) {
            const Eigen::Matrix4d X =
                k == steps_ ? s.XB : (s.log * (double(k) / steps_)).exp() * s.XA;
            plan.placed.push_back(
                std::make_unique<PlacedTool>(s.tool->shape->place(affine(X)), s.tool->falloff));
            affected_.add(plan.placed.back()->coatingBounds());
            if (k > 0) stepBoxes_[k - 1].add(plan.placed.back()->coatingBounds());
        }
        tools_.push_back(std::move(plan));
    }
}

bool SweepSegment::identityOn(const Box& box) const {
    if (box.empty()) return true;
    const Eigen::Vector3d centre = 0.5 * (box.min + box.max);
    const double radius = 0.5 * box.extent().norm();
    for (int k = 0; k < steps_; ++k) {
        if (!stepBoxes_[k].overlaps(box)) continue;
        for (const ToolPlan& t : tools_) {
            const PlacedTool& tool = *t.placed[k + 1];
            // The distance is L-Lipschitz (L = 1 unless sampled), so no point of the box is
            // nearer the tool than distance(centre) - L radius; the influence is 0 from the
            // falloff width on (3.3). The margin covers the rounding of shapes whose
            // distance is solved for.
            if (tool.distance(centre) - tool.lipschitz() * radius <
                tool.falloff() * (1.0 + 1e-9) + 1e-12)
                return false;
        }
    }
    return true;
}

Eigen::Vector3d SweepSegment::inverseStep(int k, const Eigen::Vector3d& p) const {
    if (tools_.size() != 1) return StepDeformation::inverseStep(k, p);
    return oneToolStep(-oneToolInfluence(k, p), p);
}

void SweepSegment::inverseMaps(const Eigen::Vector3d* p, std::size_t n, Eigen::Vector3d* out,
                               MapScratch& scratch) const {
    if (tools_.size() != 1) return StepDeformation::inverseMaps(p, n, out, scratch);
    // inverseMap a sub-step at a time over all the points: those in the sub-step's box are
    // gathered and their influences found in one call (a call per point went through
    // inverseStep, influence and the shape's distance, two of them virtual).
    std::vector<std::size_t>& moved = scratch.which;
    moved.clear();
    for (std::size_t i = 0; i < n; ++i) {
        out[i] = p[i];
        if (!stillAt(p[i])) moved.push_back(i);
    }
    for (int k = steps_ - 1; k >= 0; --k) {
        influencesInBox(k, moved, out, scratch);
        for (std::size_t j = 0; j < scratch.index.size(); ++j)
            out[scratch.index[j]] = oneToolStep(-scratch.phi[j], scratch.points[j]);
    }
}

void SweepSegment::influencesInBox(int k, const std::vector<std::size_t>& which,
                                   const Eigen::Vector3d* at, MapScratch& into) const {
    into.index.clear();
    into.points.clear();
    for (const std::size_t i : which)
        if (stepBoxes_[std::size_t(k)].contains(at[i])) {
            into.index.push_back(i);
            into.points.push_back(at[i]);
        }
    into.phi.resize(into.points.size());
    tools_[0].placed[std::size_t(k) + 1]->influences(into.points.data(), into.points.size(),
                                                     into.phi.data());
}

ForwardResult SweepSegment::forwardStep(int k, const Eigen::Vector3d& q, double tolerance) const {
    if (tools_.size() != 1) return StepDeformation::forwardStep(k, q, tolerance);
    // p = exp(phi(p) L) q, iterated (INVERTFASTER, 5.4.1).
    return iterateForward(q, tolerance, forwardMaxIterations_, [&](const Eigen::Vector3d& p) {
        return oneToolStep(oneToolInfluence(k, p), q);
    });
}

void SweepSegment::forwardSteps(int k, const Eigen::Vector3d* q, std::size_t n, double tolerance,
                                Eigen::Vector3d* out, MapScratch& scratch) const {
    if (tools_.size() != 1) return StepDeformation::forwardSteps(k, q, n, tolerance, out, scratch);
    // forwardStep's iteration run on all the points at once, each until it converges (to the
    // bit what it gives one point at a time): the influences of the points still iterating
    // in the sub-step's box are found in one call per iteration.
    std::vector<std::size_t>& iterating = scratch.which;
    std::vector<double>& tol = scratch.tolerance;
    iterating.resize(n);
    tol.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        out[i] = q[i];
        iterating[i] = i;
        tol[i] = forwardToleranceAt(q[i], tolerance);
    }
    for (int it = 1; it <= forwardMaxIterations_ && !iterating.empty(); ++it) {
        influencesInBox(k, iterating, out, scratch);
        // Each point's next iterate: q where its influence is 0 (outside the box too).
        std::size_t j = 0, kept = 0;
        for (const std::size_t i : iterating) {
            double w = 0.0;
            if (j < scratch.index.size() && scratch.index[j] == i) w = scratch.phi[j++];
            const Eigen::Vector3d next = oneToolStep(w, q[i]);
            const double change = (next - out[i]).norm();
            out[i] = next;
            if (change > tol[i]) iterating[kept++] = i;
        }
        iterating.resize(kept);
    }
}

std::optional<MotionLog> SweepSegment::stepLog(int k, const Eigen::Vector3d& p) const {
    if (!stepBoxes_[k].contains(p)) return std::nullopt;
    // Normalized blend 3.17 / 5.19: c = (1 - prod(1 - phi_j)) / sum(phi_j).
    double sum = 0.0, prod = 1.0;
    MotionLog blend;
    int active = 0;
    for (const ToolPlan& t : tools_) {
        const double phi = t.placed[k + 1]->influence(p);
        if (phi == 0.0) continue;
        sum += phi;
        prod *= 1.0 - phi;
        blend += t.stepLog * phi;
        ++active;
    }
    if (active == 0) return std::nullopt;
    if (active == 1) return blend; // c phi = phi
    return blend * ((1.0 - prod) / sum);
}

} // namespace sweepers
