// SPDX-License-Identifier: Apache-2.0
#include "deform/strangle.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/checks.h"
#include "deform/tear.h"

namespace sweepers {

namespace {

constexpr int kForwardIterations = 60; // as for the needles: a non-converged point is on the circle
constexpr double kNooseSegmentRatio = 2.0;

ConeField nooseField(const StrangleSpec& spec) {
    return {kNooseInDegrees * kDegree, kNooseOutDegrees * kDegree, spec.size,
            spec.size + spec.falloff};
}

} // namespace

void checkStrangle(const StrangleSpec& spec) {
    if (!spec.at.allFinite()) throw std::invalid_argument("at: not finite");
    if (!spec.axis.allFinite() || !(spec.axis.norm() > 0.0))
        throw std::invalid_argument("axis: needs a direction (not zero)");
    if (!finitePositive(spec.size)) throw std::invalid_argument("size: must be positive");
    if (!finitePositive(spec.falloff)) throw std::invalid_argument("falloff: must be positive");
    if (!finitePositive(spec.open)) throw std::invalid_argument("open: must be positive");
}

StrangleNoose::StrangleNoose(const StrangleSpec& spec, std::vector<double> radii)
    : at_(spec.at), axis_(spec.axis.normalized()), radii_(std::move(radii)),
      field_(nooseField(spec)) {
    checkStrangle(spec);
    if (radii_.size() < 2) throw std::invalid_argument("the noose needs at least one sub-step");
    for (std::size_t k = 1; k < radii_.size(); ++k)
        if (!(radii_[k] > 0.0 && radii_[k] <= radii_[k - 1]))
            throw std::invalid_argument("the noose's radii must be positive and decreasing");
    steps_ = int(radii_.size()) - 1;
    tanIn_ = std::tan(field_.aIn);
    tanOut_ = std::tan(field_.aOut);
    affected_ = Box(at_.array() - field_.rOut, at_.array() + field_.rOut);
}

double StrangleNoose::weight(double R, const Eigen::Vector3d& p) const {
    const Eigen::Vector3d v = p - at_;
    const double r2 = v.squaredNorm();
    if (r2 >= field_.rOut * field_.rOut) return 0.0;
    const double z = std::abs(v.dot(axis_));
    const double beyond = std::sqrt(std::max(0.0, r2 - z * z)) - R; // past the circle
    // The angle at the circle's nearest point between p and the outward direction (3.45),
    // compared by its tangent first: most points lie wholly inside or outside the wedge.
    if (beyond <= 0.0 || z >= tanOut_ * beyond) return 0.0;
    const double alpha = z <= tanIn_ * beyond ? 1.0 : field_.alpha(std::atan2(z, beyond));
    return alpha * field_.rho(std::sqrt(r2));
}

Eigen::Vector3d StrangleNoose::scaled(const Eigen::Vector3d& p, double factor) const {
    const Eigen::Vector3d v = p - at_;
    const double z = v.dot(axis_);
    return at_ + z * axis_ + factor * (v - z * axis_);
}

Eigen::Vector3d StrangleNoose::inverseStep(int k, const Eigen::Vector3d& p) const {
    if (!affected_.contains(p)) return p;
    const double w = weight(radius(k + 1), p);
    if (w == 0.0) return p;
    // Sub-step k scales by R_{k+1} / R_k where the field is full: its inverse by the power -w.
    return scaled(p, std::pow(radius(k + 1) / radius(k), -w));
}

ForwardResult StrangleNoose::forwardStep(int k, const Eigen::Vector3d& q, double tolerance) const {
    if (!affected_.contains(q)) return {q, true, 0};
    const double ratio = radius(k + 1) / radius(k);
    return iterateForward(q, tolerance, kForwardIterations, [&](const Eigen::Vector3d& p) {
        return scaled(q, std::pow(ratio, weight(radius(k + 1), p)));
    });
}

bool StrangleNoose::stillAt(const Eigen::Vector3d& p) const {
    // Outside the wedge for the smallest circle of the segment: outside it for every larger
    // one, so no sub-step moves p (see identityOn).
    const Eigen::Vector3d v = p - at_;
    if (v.squaredNorm() >= field_.rOut * field_.rOut) return true;
    const double z = v.dot(axis_);
    return std::abs(z) >= tanOut_ * ((v - z * axis_).norm() - radii_.back());
}

bool StrangleNoose::identityOn(const Box& box) const {
    if (!affected_.overlaps(box)) return true;
    const Eigen::Vector3d centre = 0.5 * (box.min + box.max);
    if ((centre - at_).norm() >= field_.rOut + 0.5 * box.extent().norm()) return true;
    // Nothing moves outside the wedge a_out around the plane seen from the circle, nor inside
    // the circle: a point at height z and distance rho from the axis is still when
    // |z| >= tan(a_out) (rho - R), for the smallest R of the segment (the wedge only grows as
    // the circle shrinks). Over a box, the distance to a line is largest at a corner.
    double lowest = std::numeric_limits<double>::infinity(), farthest = 0.0;
    bool above = false, below = false;
    for (const Eigen::Vector3d& c : box.corners()) {
        const Eigen::Vector3d v = c - at_;
        const double z = v.dot(axis_);
        above = above || z >= 0.0;
        below = below || z <= 0.0;
        lowest = std::min(lowest, std::abs(z));
        farthest = std::max(farthest, (v - z * axis_).norm());
    }
    if (above && below) lowest = 0.0; // the box crosses the plane
    return lowest >= tanOut_ * (farthest - radii_.back());
}

std::vector<std::unique_ptr<StepDeformation>> planStrangle(const StrangleSpec& spec,
                                                           double voxelSize) {
    checkStrangle(spec);
    if (!finitePositive(voxelSize)) throw std::invalid_argument("a strangle needs a voxel size");
    const ConeField field = nooseField(spec);
    const double slope = 15.0 / 8.0;
    const double angles = field.aOut - field.aIn;
    // Near the circle a sub-step moves points by about the radius change, against a field
    // whose slope is slopeBound(h) a voxel away: no fold farther than a voxel from the
    // circle. Far from it, by up to log(ratio) times their distance to the axis, against a
    // slope of at most 15/8 (2 / angles + 1 / falloff) times that distance; half that bound.
    const double nearStep = 1.0 / field.slopeBound(voxelSize);
    const double farLog = 0.5 / (slope * (2.0 / angles + field.rOut / spec.falloff));
    const double end = 0.25 * voxelSize;
    std::vector<double> radii{spec.size};
    while (radii.back() > end) {
        const double R = radii.back();
        radii.push_back(std::max({R - nearStep, R * std::exp(-farLog), end}));
        if (radii.size() > 4'000'000)
            throw std::invalid_argument("the strangle would need millions of sub-steps");
    }
    // Segments of at most a quarter of the falloff of contraction each, and of at most a
    // halving of the radius. A segment's inverse map stretches the wedge's faces by more
    // than its ratio q (the field's angular slope adds about 7 ln q times r / d at distance
    // d from the circle), and the advection widens the source band only up to a stretch of
    // 32: past it the sampled values are clamped and the face comes out terraced to the
    // grid. One last segment from a tenth of the size down to a quarter voxel goes past it;
    // halvings keep every segment's stretch below it.
    std::vector<std::unique_ptr<StepDeformation>> parts;
    std::size_t first = 0;
    for (std::size_t k = 1; k < radii.size(); ++k) {
        const bool last = k + 1 == radii.size();
        if (last || radii[first] - radii[k + 1] > spec.falloff / 4.0 ||
            radii[first] > kNooseSegmentRatio * radii[k + 1]) {
            parts.push_back(std::make_unique<StrangleNoose>(
                spec, std::vector<double>(radii.begin() + std::ptrdiff_t(first),
                                          radii.begin() + std::ptrdiff_t(k) + 1)));
            first = k;
        }
    }
    parts.push_back(std::make_unique<Tear>(Tear::acrossDisc(
        spec.at, spec.axis, spec.size, 0.5 * spec.open, std::max(spec.falloff, spec.open))));
    return parts;
}

} // namespace sweepers
