// SPDX-License-Identifier: Apache-2.0
#include "deform/tear.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "core/checks.h"
#include "core/falloff.h"

namespace sweepers {

Tear::Tear(Set set, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius, double open,
           double reach)
    : set_(set), a_(a), b_(b), radius_(radius), open_(open), reach_(reach) {
    if (!finitePositive(open)) throw std::invalid_argument("a tear needs a positive opening");
    if (!finitePositive(reach)) throw std::invalid_argument("a tear needs a positive reach");
    // d' + r beta((d_out - d') / d_out) increases in d' when r * 15/8 < d_out.
    if (reach < 2.0 * open)
        throw std::invalid_argument("a tear's reach must be at least twice its opening");
    steps_ = 1;
    tears_ = true;
    Box set_box;
    if (set == Set::Segment) {
        set_box.add(a);
        set_box.add(b);
    } else {
        // The disc's box: its centre plus radius times how far the disc spreads along each axis.
        const Eigen::Vector3d spread =
            (Eigen::Vector3d::Ones() - b.cwiseProduct(b)).cwiseMax(0.0).cwiseSqrt() * radius;
        set_box = Box(a - spread, a + spread);
    }
    affected_ = set_box.expanded(reach);
}

Tear Tear::alongSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double open,
                        double reach) {
    if (!((b - a).norm() > 0.0)) throw std::invalid_argument("a tear needs a segment, not a point");
    return Tear(Set::Segment, a, b, 0.0, open, reach);
}

Tear Tear::acrossDisc(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double radius,
                      double open, double reach) {
    if (!finitePositive(radius)) throw std::invalid_argument("a tear's disc needs a radius");
    if (!(normal.norm() > 0.0)) throw std::invalid_argument("a tear's disc needs a normal");
    return Tear(Set::Disc, centre, normal.normalized(), radius, open, reach);
}

Eigen::Vector3d Tear::nearest(const Eigen::Vector3d& p) const {
    if (set_ == Set::Segment) {
        const Eigen::Vector3d ab = b_ - a_;
        const double t = std::clamp((p - a_).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
        return a_ + t * ab;
    }
    const Eigen::Vector3d v = p - a_;
    const Eigen::Vector3d inPlane = v - v.dot(b_) * b_;
    const double len = inPlane.norm();
    return len <= radius_ ? Eigen::Vector3d(a_ + inPlane)
                          : Eigen::Vector3d(a_ + inPlane * (radius_ / len));
}

Eigen::Vector3d Tear::alongTorn(const Eigen::Vector3d& x) const {
    if (set_ == Set::Segment) return (b_ - a_).normalized();
    // In the disc's plane, towards x's projection (any direction of the plane at its centre).
    const Eigen::Vector3d v = x - a_;
    const Eigen::Vector3d inPlane = v - v.dot(b_) * b_;
    const double len = inPlane.norm();
    return len > 0.0 ? Eigen::Vector3d(inPlane / len) : Eigen::Vector3d(b_.unitOrthogonal());
}

double Tear::push(double d) const {
    return open_ * falloffBeta((reach_ - d) / reach_); // r phi(d), 3.42
}

double Tear::openedDepth(const Eigen::Vector3d& x) const {
    return open_ - (x - nearest(x)).norm();
}

double Tear::leastValue(const Eigen::Vector3d& p) const {
    return -(p - nearest(p)).norm();
}

Eigen::Vector3d Tear::inverseStep(int, const Eigen::Vector3d& x) const {
    if (!affected_.contains(x)) return x;
    Eigen::Vector3d q = nearest(x); // not const: returned as is below
    const double d = (x - q).norm();
    if (d >= reach_) return x;
    if (d <= open_) return q; // torn open: no pre-image but S itself
    // d' + push(d') = d has one root in [0, d] (the left side is increasing, open at 0 and at
    // least d at d): bisection, to far below a voxel.
    double lo = 0.0, hi = d;
    for (int i = 0; i < 60 && hi - lo > 1e-13 * (1.0 + d); ++i) {
        const double mid = 0.5 * (lo + hi);
        (mid + push(mid) < d ? lo : hi) = mid;
    }
    return q + (x - q) * (0.5 * (lo + hi) / d);
}

ForwardResult Tear::forwardStep(int, const Eigen::Vector3d& p, double) const {
    if (!affected_.contains(p)) return {p, true, 0};
    const Eigen::Vector3d q = nearest(p);
    const double d = (p - q).norm();
    if (d == 0.0 || d >= reach_) return {p, true, 1}; // on S: torn, it stays (3.41 is undefined)
    return {p + (p - q) * (push(d) / d), true, 1};
}

} // namespace sweepers
