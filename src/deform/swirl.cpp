// SPDX-License-Identifier: Apache-2.0
#include "deform/swirl.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "core/falloff.h"

namespace sweepers {

SwirlSegment::SwirlSegment(const SwirlSpec& spec) : spec_(spec) {
    const double len = spec.move.norm();
    if (!(spec.radius > 0.0) || !std::isfinite(spec.radius))
        throw std::invalid_argument("a swirl needs a positive radius");
    if (!(len > 0.0) || !std::isfinite(len)) throw std::invalid_argument("a swirl needs a move");
    if (spec.swirls < 1) throw std::invalid_argument("a swirl ring needs at least one swirl");
    const double r = spec.radius;
    // 4.3: s = max(1, ceil(4 |t| / r)); refuse what no interactive tool would ask for.
    const double s = std::max(1.0, std::ceil(4.0 * len / r));
    if (s > 4096) throw std::domain_error("the swirl moves too far for its radius; split it");
    steps_ = int(s);

    z_ = spec.move / len;
    u_ = z_.unitOrthogonal();
    v_ = z_.cross(u_); // u x v = z
    if (spec.ring == SwirlRing::Discrete) {
        theta_ = 2.0 * len / (spec.swirls * r * steps_); // 4.2 per sub-step
        reach_ = 3.0 * r; // swirl centres at r from h, falloff support 2r
    } else {
        const double lambda = spec.lambdaOverRadius * r;
        const double l2 = lambda * lambda, r2 = r * r;
        theta_ = len * (l2 + r2) * (l2 + r2) / (2.0 * l2 * l2 * r) / steps_; // 4.13
        reach_ =
            r * std::sqrt(std::max(0.0, std::sqrt(2.0 * M_PI * r / spec.neglect) - 1.0)); // 4.15
        inner_ = 0.5 * reach_;
    }
    for (int k = 0; k <= steps_; ++k) {
        const Eigen::Vector3d c = ringCentre(k);
        affected_.add(Box(c.array() - reach_, c.array() + reach_));
    }
}

std::optional<MotionLog> SwirlSegment::stepLog(int k, const Eigen::Vector3d& p) const {
    const Eigen::Vector3d c = ringCentre(k + 1);
    const Eigen::Vector3d d = p - c;
    const double dist2 = d.squaredNorm();
    if (dist2 >= reach_ * reach_) return std::nullopt;
    const double r = spec_.radius;
    Twist sum;
    if (spec_.ring == SwirlRing::Discrete) {
        // 4.1 with 4.4: sum_i mu_2r(|p - c_i|) <theta v_i, c_i x theta v_i>.
        bool any = false;
        for (int i = 0; i < spec_.swirls; ++i) {
            const double a = 2.0 * M_PI * i / spec_.swirls;
            const Eigen::Vector3d e = std::cos(a) * u_ + std::sin(a) * v_;
            const Eigen::Vector3d tangent = -std::sin(a) * u_ + std::cos(a) * v_;
            const Eigen::Vector3d ci = c + r * e;
            const double w = falloffMu((p - ci).norm(), 2.0 * r);
            if (w == 0.0) continue;
            any = true;
            sum += Twist::rotation(tangent, w * theta_, ci);
        }
        if (!any) return std::nullopt;
    } else {
        // 4.11: theta b <eta, c x eta + z a>, a = |p - c|^2 + lambda^2 + r^2,
        // b = 2 lambda^4 r / (a^2 - r^2 |eta|^2)^(3/2), eta = 2 z x (p - c).
        const double lambda = spec_.lambdaOverRadius * r;
        const double l2 = lambda * lambda;
        const Eigen::Vector3d eta = 2.0 * z_.cross(d);
        const double eta2 = eta.squaredNorm();
        const double a = dist2 + l2 + r * r;
        const double b = 2.0 * l2 * l2 * r / std::pow(a * a - r * r * eta2, 1.5);
        // The field is cut off at the bounding sphere through its stream function, not by
        // itself: cut off by itself, it would pour clay through the sphere, at any voxel size.
        // The field is axisymmetric about z through c with no swirl component, so it is the
        // curl of psi (z x d) / rho^2, with Stokes stream function psi = lambda^4 / (2 r)
        // (a / sqrt(a^2 - 4 r^2 rho^2) - 1) (rho, zeta: distances from and along the axis).
        // The curl of chi times that potential, chi going smoothly from 1 to 0 between half
        // the reach and the reach, is the field times chi plus grad chi x the potential:
        // divergence-free again.
        const double dist = std::sqrt(dist2);
        const double chi = falloffMu(dist - inner_, reach_ - inner_);
        Eigen::Vector3d translation = chi * theta_ * b * (c.cross(eta) + a * z_);
        if (dist > inner_) {
            const double zeta = z_.dot(d);
            // psi / rho^2, written without the cancellation of a / sqrt(...) - 1 near the axis.
            const double root = std::sqrt(std::max(0.0, 1.0 - r * r * eta2 / (a * a)));
            const double psiOverRho2 = 2.0 * l2 * l2 * r / (a * a * root * (1.0 + root));
            const double chiSlope = falloffMuDerivative(dist - inner_, reach_ - inner_);
            translation += theta_ * chiSlope * psiOverRho2 / dist * (dist2 * z_ - zeta * d);
        }
        sum = Twist(chi * theta_ * b * eta, translation);
    }
    return MotionLog(sum);
}

} // namespace sweepers
