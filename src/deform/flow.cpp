// SPDX-License-Identifier: Apache-2.0
#include "deform/flow.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/LU>
#include <Eigen/SVD>

namespace sweepers {

FlowStep::FlowStep(std::shared_ptr<const VelocityField> field, double t0, double t1)
    : field_(std::move(field)), t0_(t0), t1_(t1) {
    if (!(t1 > t0) || !std::isfinite(t1 - t0))
        throw std::invalid_argument("a flow runs forward in time");
    const double L = field_->lipschitz();
    steps_ = std::max(1, int(std::ceil(2.0 * L * (t1 - t0))));
    dt_ = (t1 - t0) / steps_;
    affected_ = field_->support();
}

Eigen::Vector3d FlowStep::trace(const Eigen::Vector3d& p, double a, double b, int steps) const {
    const double h = (b - a) / steps;
    Eigen::Vector3d x = p;
    for (int i = 0; i < steps; ++i) {
        const double t = a + i * h;
        const VelocityField& v = *field_;
        const Eigen::Vector3d k1 = v.at(x, t), k2 = v.at(x + 0.5 * h * k1, t + 0.5 * h),
                              k3 = v.at(x + 0.5 * h * k2, t + 0.5 * h),
                              k4 = v.at(x + h * k3, t + h);
        x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    return x;
}

Eigen::Vector3d FlowStep::inverseStep(int k, const Eigen::Vector3d& p) const {
    if (!affected_.contains(p)) return p;
    const double a = t0_ + k * dt_;
    return trace(p, a + dt_, a, rk_);
}

ForwardResult FlowStep::forwardStep(int k, const Eigen::Vector3d& q, double tolerance) const {
    if (!affected_.contains(q)) return {q, true, 0};
    const double a = t0_ + k * dt_;
    // From a start within RK4's error of the answer, x -= inverse(x) - q, which contracts
    // by about dt L <= 1/2 per iteration, until the inverse comes back to q.
    ForwardResult r{trace(q, a, a + dt_, rk_), false, 0};
    const double tol = (tolerance > 0.0 ? tolerance : forwardTolerance_) * (1.0 + q.norm());
    for (int it = 1; it <= forwardMaxIterations_; ++it) {
        const Eigen::Vector3d miss = inverseStep(k, r.p) - q;
        r.iterations = it;
        if (miss.norm() <= tol) {
            r.converged = true;
            break;
        }
        r.p -= miss;
    }
    return r;
}

std::vector<std::unique_ptr<StepDeformation>>
planFlow(const std::shared_ptr<const VelocityField>& field, double t0, double t1, int segments) {
    if (segments < 1) throw std::invalid_argument("a flow needs at least one segment");
    std::vector<std::unique_ptr<StepDeformation>> parts;
    parts.reserve(std::size_t(segments));
    for (int i = 0; i < segments; ++i)
        parts.push_back(std::make_unique<FlowStep>(field, t0 + (t1 - t0) * i / segments,
                                                   t0 + (t1 - t0) * (i + 1) / segments));
    return parts;
}

int flowSegments(const VelocityField& field, double t0, double t1,
                 const std::vector<Eigen::Vector3d>& points, double maxStretch, int most) {
    constexpr int kCheckpoints = 64;
    const double span = (t1 - t0) / kCheckpoints;
    const int steps = std::max(1, int(std::ceil(4.0 * field.lipschitz() * span)));
    const double h = span / steps;
    // J[c]: the Jacobian of the flow map from t0 to checkpoint c, for every point.
    std::vector<std::vector<Eigen::Matrix3d>> J(points.size());
    // RK4 on a point and, beside it, the variational equation of its Jacobian.
    auto rate = [&](const Eigen::Vector3d& y, const Eigen::Matrix3d& N, double at) {
        return std::make_pair(field.at(y, at), Eigen::Matrix3d(field.jacobian(y, at) * N));
    };
    for (std::size_t i = 0; i < points.size(); ++i) {
        Eigen::Vector3d x = points[i];
        Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
        J[i].push_back(M);
        for (int c = 0; c < kCheckpoints; ++c)
            for (int s = 0; s < steps; ++s) {
                const double t = t0 + c * span + s * h;
                const auto k1 = rate(x, M, t);
                const auto k2 = rate(x + 0.5 * h * k1.first, M + 0.5 * h * k1.second, t + 0.5 * h);
                const auto k3 = rate(x + 0.5 * h * k2.first, M + 0.5 * h * k2.second, t + 0.5 * h);
                const auto k4 = rate(x + h * k3.first, M + h * k3.second, t + h);
                x += h / 6.0 * (k1.first + 2.0 * k2.first + 2.0 * k3.first + k4.first);
                M += h / 6.0 * (k1.second + 2.0 * k2.second + 2.0 * k3.second + k4.second);
                if (s + 1 == steps) J[i].push_back(M);
            }
    }
    for (int n = 1;; n *= 2) {
        if (n >= most || n >= kCheckpoints) return std::min(n, most);
        const std::size_t per = std::size_t(kCheckpoints / n);
        double worst = 1.0;
        for (const auto& Ji : J)
            for (std::size_t piece = 0; piece < std::size_t(n); ++piece) {
                // The piece's inverse map: from checkpoint b back to a, J_a J_b^-1.
                const Eigen::Matrix3d inverse = Ji[piece * per] * Ji[(piece + 1) * per].inverse();
                worst =
                    std::max(worst, Eigen::JacobiSVD<Eigen::Matrix3d>(inverse).singularValues()[0]);
            }
        if (worst <= maxStretch) return n;
    }
}

} // namespace sweepers
