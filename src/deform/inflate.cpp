// SPDX-License-Identifier: Apache-2.0
#include "deform/inflate.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sweepers {

Inflation::Inflation(const Eigen::Vector3d& centre, double radius, const Box& reach, bool remove,
                     InflationFill fill)
    : c_(centre), rho_(radius), rho3_(radius * radius * radius), remove_(remove), fill_(fill) {
    if (!(radius > 0.0) || !std::isfinite(radius))
        throw std::invalid_argument("an inflation needs a positive radius");
    if (!(fill.band >= 0.0) || !std::isfinite(fill.band))
        throw std::invalid_argument("an inflation's fill needs a band of at least 0");
    steps_ = 1;
    fills_ = !remove && fill.band > 0.0;
    affected_ = reach;
    affected_.add(Box(centre.array() - 2 * radius, centre.array() + 2 * radius));
}

Eigen::Vector3d Inflation::blowUp(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d u = p - c_;
    const double r = u.norm();
    if (r == 0.0) return p; // the discontinuous point
    return c_ + std::cbrt(r * r * r + rho3_) / r * u;
}

Eigen::Vector3d Inflation::suckIn(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d u = p - c_;
    const double r = u.norm();
    const double r3 = r * r * r;
    if (r3 <= rho3_) return c_; // inside the ball: no pre-image but the centre
    return c_ + std::cbrt(r3 - rho3_) / r * u;
}

Eigen::Vector3d Inflation::inverseStep(int, const Eigen::Vector3d& p) const {
    if (!affected_.contains(p)) return p;
    return remove_ ? blowUp(p) : suckIn(p);
}

ForwardResult Inflation::forwardStep(int, const Eigen::Vector3d& q, double) const {
    if (!affected_.contains(q)) return {q, true, 0};
    return {remove_ ? suckIn(q) : blowUp(q), true, 1};
}

bool Inflation::fillsWith(double fromValue) const {
    // Within the band the new surface lies less than a voxel beyond the ball's edge (s^3 /
    // (3 rho^2) for a ball of three voxels or more), closer than any sampled value says.
    // Deeper, the value at c is the band's and the surface lies farther out, where the
    // inverse samples distances again.
    return fills_ && fromValue > -fill_.band && fromValue < fill_.band;
}

double Inflation::filledValue(const Eigen::Vector3d& x, double value, double fromValue) const {
    const double band = fill_.band;
    if (!fillsWith(fromValue)) return value;
    const double s = std::max(0.0, -fromValue);
    const double r = (x - c_).norm(), out = r - std::cbrt(rho3_ + s * s * s);
    if (r < rho_) return std::max(out, -band); // the new ball: clay
    return value > 0.0 && out > 0.0 && out < band ? std::min(value, out) : value;
}

Box Inflation::filledBox() const {
    if (!fills_) return {};
    const double band = fill_.band, r = std::cbrt(rho3_ + band * band * band) + band;
    return Box(c_.array() - r, c_.array() + r);
}

Sequence::Sequence(std::vector<std::unique_ptr<StepDeformation>> parts) : parts_(std::move(parts)) {
    steps_ = 0;
    for (const auto& p : parts_) {
        steps_ += p->steps();
        affected_.add(p->affectedBox());
    }
}

std::pair<const StepDeformation*, int> Sequence::locate(int k) const {
    for (const auto& p : parts_) {
        if (k < p->steps()) return {p.get(), k};
        k -= p->steps();
    }
    throw std::out_of_range("sub-step out of range");
}

Eigen::Vector3d Sequence::inverseStep(int k, const Eigen::Vector3d& p) const {
    const auto [part, local] = locate(k);
    return part->inverseStep(local, p);
}

ForwardResult Sequence::forwardStep(int k, const Eigen::Vector3d& q, double tolerance) const {
    const auto [part, local] = locate(k);
    return part->forwardStep(local, q, tolerance);
}

std::unique_ptr<StepDeformation> starShapedSwirl(const SwirlSpec& swirl, double rho,
                                                 const Box& reach) {
    std::vector<std::unique_ptr<StepDeformation>> parts;
    parts.push_back(std::make_unique<Inflation>(swirl.at, rho, reach, /*remove=*/true));
    parts.push_back(std::make_unique<SwirlSegment>(swirl));
    parts.push_back(std::make_unique<Inflation>(swirl.at + swirl.move, rho, reach));
    return std::make_unique<Sequence>(std::move(parts));
}

} // namespace sweepers
