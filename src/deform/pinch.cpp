// SPDX-License-Identifier: Apache-2.0
#include "deform/pinch.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/checks.h"
#include "deform/tear.h"

namespace sweepers {

namespace {

// A fixed-point iteration of the forward map that has not converged by then sits on a
// needle's tip, where the map is discontinuous: its last iterate is as good as any.
constexpr int kForwardIterations = 60;

// The needles' segments: each moves the tips by at most a quarter of the falloff.
std::size_t needleSegments(const PinchSpec& spec) {
    return std::size_t(std::max(1.0, std::ceil(spec.size / (spec.falloff / 4.0))));
}

// Distance from p to the segment [a, b].
double distanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b) {
    const Eigen::Vector3d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (p - (a + t * ab)).norm();
}

} // namespace

void checkPinch(const PinchSpec& spec) {
    if (!spec.at.allFinite()) throw std::invalid_argument("at: not finite");
    if (!spec.axis.allFinite() || !(spec.axis.norm() > 0.0))
        throw std::invalid_argument("axis: needs a direction (not zero)");
    if (!finitePositive(spec.size)) throw std::invalid_argument("size: must be positive");
    if (!finitePositive(spec.falloff)) throw std::invalid_argument("falloff: must be positive");
    if (!finitePositive(spec.open)) throw std::invalid_argument("open: must be positive");
    if (needleSegments(spec) > 4096)
        throw std::invalid_argument("size: the needles travel over 1000 falloffs; a larger "
                                    "falloff or a shorter travel");
}

PinchNeedles::PinchNeedles(const PinchSpec& spec, double u0, double u1, int steps)
    : at_(spec.at), axis_(spec.axis.normalized()), size_(spec.size), u0_(u0), u1_(u1) {
    checkPinch(spec);
    if (steps < 1) throw std::invalid_argument("the needles need at least one sub-step");
    steps_ = steps;
    field_ = {kNeedleInDegrees * kDegree, kNeedleOutDegrees * kDegree, spec.falloff / 2.0,
              spec.falloff};
    cosIn2_ = std::pow(std::cos(field_.aIn), 2);
    cosOut2_ = std::pow(std::cos(field_.aOut), 2);
    for (int n = 0; n < 2; ++n) {
        affected_.add(Box(tip(n, u0).array() - field_.rOut, tip(n, u0).array() + field_.rOut));
        affected_.add(Box(tip(n, u1).array() - field_.rOut, tip(n, u1).array() + field_.rOut));
    }
}

Eigen::Vector3d PinchNeedles::tip(int needle, double u) const {
    const double side = needle == 0 ? 1.0 : -1.0;
    return at_ + side * (1.0 - u) * size_ * axis_;
}

double PinchNeedles::weight(int needle, const Eigen::Vector3d& tip,
                            const Eigen::Vector3d& p) const {
    const Eigen::Vector3d v = p - tip;
    const double r2 = v.squaredNorm();
    if (r2 >= field_.rOut * field_.rOut || r2 == 0.0) return 0.0;
    // The body of needle 0 points along +axis (it moves down the axis), that of needle 1
    // along -axis. Most points lie wholly inside or outside the cone: compared by cosines,
    // they need no arc cosine.
    const double along = (needle == 0 ? 1.0 : -1.0) * v.dot(axis_);
    if (along <= 0.0 || along * along <= cosOut2_ * r2) return 0.0;
    const double r = std::sqrt(r2);
    const double alpha =
        along * along >= cosIn2_ * r2 ? 1.0 : field_.alpha(std::acos(std::min(along / r, 1.0)));
    return alpha * (r <= field_.rIn ? 1.0 : field_.rho(r)); // 3.39
}

Eigen::Vector3d PinchNeedles::displacement(int k, const Eigen::Vector3d& p) const {
    const double u = u0_ + (u1_ - u0_) * double(k + 1) / steps_;
    const double w0 = weight(0, tip(0, u), p), w1 = weight(1, tip(1, u), p);
    if (w0 == 0.0 && w1 == 0.0) return Eigen::Vector3d::Zero();
    // Each tip moves by size (u1 - u0) / s towards `at` per sub-step; the two translations are
    // blended with the normalized weights of 3.17, so where both fields are full the motions
    // cancel instead of adding up.
    const double blend = (1.0 - (1.0 - w0) * (1.0 - w1)) / (w0 + w1);
    const double step = size_ * (u1_ - u0_) / steps_;
    return blend * step * (w1 - w0) * axis_;
}

Eigen::Vector3d PinchNeedles::inverseStep(int k, const Eigen::Vector3d& p) const {
    if (!affected_.contains(p)) return p;
    return p - displacement(k, p);
}

ForwardResult PinchNeedles::forwardStep(int k, const Eigen::Vector3d& q, double tolerance) const {
    if (!affected_.contains(q)) return {q, true, 0};
    // p - displacement(p) = q: a contraction away from the tips (the sub-step count keeps it
    // one from a voxel away from them on).
    return iterateForward(
        q, tolerance, kForwardIterations,
        [&](const Eigen::Vector3d& p) -> Eigen::Vector3d { return q + displacement(k, p); });
}

bool PinchNeedles::beyondReach(const Eigen::Vector3d& c, double margin) const {
    // Nothing moves farther than r_out from the tips' paths.
    for (int n = 0; n < 2; ++n)
        if (distanceToSegment(c, tip(n, u0_), tip(n, u1_)) < field_.rOut + margin) return false;
    return true;
}

bool PinchNeedles::stillAt(const Eigen::Vector3d& p) const {
    return beyondReach(p, 0.0);
}

bool PinchNeedles::identityOn(const Box& box) const {
    return !affected_.overlaps(box) ||
           beyondReach(0.5 * (box.min + box.max), 0.5 * box.extent().norm());
}

std::size_t pinchSegmentCount(const PinchSpec& spec) {
    return needleSegments(spec) + 1;
}

std::vector<std::unique_ptr<StepDeformation>> planPinch(const PinchSpec& spec, double voxelSize) {
    checkPinch(spec);
    if (!finitePositive(voxelSize)) throw std::invalid_argument("a pinch needs a voxel size");
    std::vector<std::unique_ptr<StepDeformation>> parts;
    const std::size_t n = needleSegments(spec);
    const ConeField field{kNeedleInDegrees * kDegree, kNeedleOutDegrees * kDegree,
                          spec.falloff / 2.0, spec.falloff};
    // Fold-over free farther than a voxel from the tips (what the grid resolves): a
    // translation by t weighted by phi folds nowhere while |t| |grad phi| < 1, twice over for
    // two needles.
    const double travel = spec.size / double(n);
    const double steps = std::ceil(travel * 2.0 * field.slopeBound(voxelSize));
    if (steps > 1e6) throw std::invalid_argument("the pinch would need over a million sub-steps");
    for (std::size_t j = 0; j < n; ++j)
        parts.push_back(std::make_unique<PinchNeedles>(spec, double(j) / n, double(j + 1) / n,
                                                       int(std::max(1.0, steps))));
    // The pull around the segment the tips travelled (3.41, 3.42: "before pinching").
    const Eigen::Vector3d axis = spec.axis.normalized();
    parts.push_back(std::make_unique<Tear>(
        Tear::alongSegment(spec.at - spec.size * axis, spec.at + spec.size * axis, spec.open,
                           std::max(spec.falloff, 2.0 * spec.open))));
    return parts;
}

} // namespace sweepers
