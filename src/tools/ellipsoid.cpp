// SPDX-License-Identifier: Apache-2.0
#include "tools/ellipsoid.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/SVD>

namespace sweepers {

namespace {

class PlacedBall final : public PlacedShape {
  public:
    PlacedBall(const Eigen::Vector3d& c, double r) : c_(c), r_(r) {}
    double distance(const Eigen::Vector3d& p) const override {
        return std::max(0.0, (p - c_).norm() - r_);
    }
    void distancesBelow(const Eigen::Vector3d* p, std::size_t n, double /*cutoff*/,
                        double* out) const override {
        for (std::size_t i = 0; i < n; ++i)
            out[i] = distance(p[i]);
    }
    Box bounds() const override { return {c_.array() - r_, c_.array() + r_}; }

  private:
    Eigen::Vector3d c_;
    double r_;
};

class PlacedEllipsoid : public PlacedShape {
  public:
    // World ellipsoid {c + U diag(a) y : |y| <= 1}; G = U diag(a) V^T is the linear part.
    PlacedEllipsoid(const Eigen::Vector3d& c, const Eigen::Matrix3d& U, const Eigen::Vector3d& a,
                    const Eigen::Matrix3d& G)
        : c_(c), Ut_(U.transpose()), a_(a) {
        for (int k = 0; k < 3; ++k)
            halfExtent_[k] = G.row(k).norm();
    }
    double distance(const Eigen::Vector3d& p) const override {
        return distanceToFilledEllipsoid(a_, Ut_ * (p - c_));
    }
    double distanceBelow(const Eigen::Vector3d& p, double cutoff) const override {
        // |p - c| - (largest semi-axis) is a lower bound of the distance.
        const double bound = (p - c_).norm() - a_.maxCoeff();
        return bound >= cutoff ? bound : distance(p);
    }
    Box bounds() const override { return {c_ - halfExtent_, c_ + halfExtent_}; }

  private:
    Eigen::Vector3d c_;
    Eigen::Matrix3d Ut_;
    Eigen::Vector3d a_;
    Eigen::Vector3d halfExtent_;
};

void requirePositive(const Eigen::Vector3d& a) {
    if (!(a.minCoeff() > 0.0) || !a.allFinite())
        throw std::invalid_argument("tool sizes must be positive and finite");
}

} // namespace

EllipsoidShape::EllipsoidShape(double radius)
    : semiAxes_(Eigen::Vector3d::Constant(radius)), isBall_(true) {
    requirePositive(semiAxes_);
}

EllipsoidShape::EllipsoidShape(const Eigen::Vector3d& semiAxes)
    : semiAxes_(semiAxes), isBall_(false) {
    requirePositive(semiAxes_);
}

std::unique_ptr<PlacedShape> EllipsoidShape::place(const Eigen::Affine3d& X) const {
    const Eigen::Matrix3d G = X.linear() * semiAxes_.asDiagonal();
    const Eigen::Vector3d c = X.translation();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(G, Eigen::ComputeFullU);
    // A copy: through a reference into the solver GCC 12 warns of uninitialized values.
    const Eigen::Vector3d a = svd.singularValues(); // NOLINT(performance-*)
    if (!(a.minCoeff() > 0.0)) throw std::invalid_argument("a tool placement collapses the tool");
    if (a.maxCoeff() - a.minCoeff() <= 1e-12 * a.maxCoeff())
        return std::make_unique<PlacedBall>(c, a.mean());
    return std::make_unique<PlacedEllipsoid>(c, svd.matrixU(), a, G);
}

double distanceToFilledEllipsoid(const Eigen::Vector3d& e, const Eigen::Vector3d& p) {
    const Eigen::Vector3d y = p.cwiseAbs();
    if (y.cwiseQuotient(e).squaredNorm() <= 1.0) return 0.0;
    // The closest point is x_i = e_i^2 y_i / (t + e_i^2) where t > 0 is the root of
    //   F(t) = sum (e_i y_i / (t + e_i^2))^2 - 1.
    // F is convex and decreasing on t >= 0 with F(0) > 0 (p is outside), so Newton's method
    // started at 0 climbs monotonically to the root without overshooting.
    const Eigen::Vector3d e2 = e.cwiseProduct(e);
    // At the root 1 >= e_min^2 |y|^2 / (t + e_max^2)^2, so t >= e_min |y| - e_max^2: starting
    // there keeps Newton on the left of the root and saves most iterations far away.
    double t = std::max(0.0, e.minCoeff() * y.norm() - e2.maxCoeff());
    for (int it = 0; it < 100; ++it) {
        double F = -1.0, dF = 0.0;
        for (int i = 0; i < 3; ++i) {
            const double r = e[i] * y[i] / (t + e2[i]);
            F += r * r;
            dF -= 2.0 * r * r / (t + e2[i]);
        }
        if (F <= 0.0 || dF == 0.0) break;
        const double step = F / dF;
        t -= step;
        if (-step <= 1e-15 * (t + e2.maxCoeff())) break;
    }
    Eigen::Vector3d x;
    for (int i = 0; i < 3; ++i)
        x[i] = e2[i] * y[i] / (t + e2[i]);
    return (y - x).norm();
}

} // namespace sweepers
