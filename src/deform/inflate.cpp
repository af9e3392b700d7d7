// SPDX-License-Identifier: Apache-2.0
#include "deform/inflate.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sweepers {

namespace {

// How far from the centre, in radii, carriedValue changes values.
constexpr double kCarriedReach = 3.0;

} // namespace

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
    // Outside the shape, within the band, the stroke put the centre on the surface. Inside,
    // down to deepestFill(): deeper, the sphere the new surface encloses holds the whole ball
    // a band deep, which is the thesis's value there.
    return fills_ && fromValue < fill_.band && fromValue > -deepestFill();
}

double Inflation::deepestFill() const {
    const double outer = rho_ + fill_.band;
    return fills_ ? std::cbrt(outer * outer * outer - rho3_) : 0.0;
}

double Inflation::filledValue(const Eigen::Vector3d& x, double value, double fromValue,
                              const SurfaceProbe* probe) const {
    const double band = fill_.band;
    if (!fillsWith(fromValue)) return value;
    const double s = std::max(0.0, -fromValue);
    const Eigen::Vector3d u = x - c_;
    const double r = u.norm();
    // The new surface lies along the ray from c through x at the image of the old surface's
    // first crossing, at distance Q from c: at radius R = (rho^3 + Q^3)^(1/3) (2.30), with
    // the normal the old one carried through the map (carried()). Q is at least s (the sphere
    // of radius R with Q = s is what the new surface encloses), and only a crossing closer
    // than deepestFill() brings the surface within a band of the ball. The distance is the
    // one along the ray times the cosine between the ray and that normal.
    double crossing = s, cosine = 1.0;
    bool found = false;
    if (probe && r > 0.0 && r > rho_ - band && r < rho_ + band) {
        const Eigen::Vector3d n = u / r;
        // (From a hair before s, so that a crossing at s itself is found.)
        const SurfaceExit exit = probe->firstExit(c_, n, std::max(0.0, s - 1e-9), deepestFill());
        crossing = exit.t;
        found = exit.t < deepestFill();
        const Eigen::Vector3d m =
            carried(n, std::cbrt(rho3_ + crossing * crossing * crossing), crossing, exit.gradient);
        // (A tenth at least: where the ray runs almost along the surface, the distance along
        // it says little, and the cosine read from a sampled normal less.)
        if (m.norm() > 0.0) cosine = std::clamp(n.dot(m) / m.norm(), 0.1, 1.0);
    }
    const double out = cosine * (r - std::cbrt(rho3_ + crossing * crossing * crossing));
    if (r < rho_) return std::max(out, -band); // the new ball: clay
    // Beyond the ball, the crossing found along the ray is the one x's pre-image lies before
    // or after (the inverse moves x along that ray): where the sign agrees, its distance.
    if (found && (out < 0.0) == (value < 0.0)) return std::clamp(out, -band, band);
    return value > 0.0 && out > 0.0 && out < band ? std::min(value, out) : value;
}

Eigen::Vector3d Inflation::carried(const Eigen::Vector3d& n, double r, double q,
                                   const Eigen::Vector3d& g) {
    // The inverse (2.31) moves a point at radius r along n to radius q = (r^3 - rho^3)^(1/3):
    // its Jacobian stretches n by r^2 / q^2 and the directions across it by q / r (the volume
    // kept), so J^T g = (r^2 / q^2) (n.g) n + (q / r) (g - (n.g) n).
    const double along = n.dot(g);
    if (!(q > 0.0)) return along * n;
    return (r * r / (q * q)) * along * n + (q / r) * (g - along * n);
}

double Inflation::carriedValue(const Eigen::Vector3d& x, double value,
                               const Eigen::Vector3d& g) const {
    if (!fills_ || !affected_.contains(x)) return value;
    const Eigen::Vector3d u = x - c_;
    const double r = u.norm(), r3 = r * r * r;
    if (r3 <= rho3_ || r >= kCarriedReach * rho_) return value; // the ball, or far enough
    const Eigen::Vector3d n = u / r;
    const Eigen::Vector3d through = carried(n, r, std::cbrt(r3 - rho3_), g);
    const double norm = through.norm(), was = g.norm();
    if (!(norm > 0.0) || !(was > 0.0)) return value;
    // Beyond two radii the map stretches by under a tenth, which renormalization's own
    // estimate of the stretch takes in: the factor gives way to 1 by three.
    const double w = std::clamp(kCarriedReach - r / rho_, 0.0, 1.0);
    return std::clamp(value * (1.0 + w * (was / norm - 1.0)), -fill_.band, fill_.band);
}

Box Inflation::fillReach() const {
    // The sphere the new surface encloses lies within a band of the edge (deepestFill()).
    if (!fills_) return {};
    const double r = rho_ + 2.0 * fill_.band;
    return Box(c_.array() - r, c_.array() + r);
}

Box Inflation::carriedReach() const {
    if (!fills_) return {};
    const double r = kCarriedReach * rho_;
    return Box(c_.array() - r, c_.array() + r);
}

Box Inflation::filledBox(double fromValue) const {
    if (!fillsWith(fromValue)) return {};
    const double s = std::max(0.0, -fromValue);
    const double r = std::cbrt(rho3_ + s * s * s) + fill_.band;
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
