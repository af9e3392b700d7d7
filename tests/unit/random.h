// SPDX-License-Identifier: Apache-2.0
// Seeded random geometry for property tests: every run sees the same cases.
#pragma once

#include <random>

#include <Eigen/Geometry>

namespace sweepers::test {

class Rng {
  public:
    explicit Rng(unsigned seed) : gen_(seed) {}
    double uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(gen_); }
    Eigen::Vector3d vec(double lo, double hi) {
        return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)};
    }
    Eigen::Vector3d unit() {
        Eigen::Vector3d v;
        do
            v = vec(-1, 1);
        while (v.norm() < 0.1 || v.norm() > 1.0);
        return v.normalized();
    }
    Eigen::Vector3d inBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
        return {uniform(lo.x(), hi.x()), uniform(lo.y(), hi.y()), uniform(lo.z(), hi.z())};
    }
    // Rigid 4x4 with rotation angle in [0, maxAngle].
    Eigen::Matrix4d rigid(double maxAngle, double maxShift) {
        Eigen::Affine3d A = Eigen::Affine3d::Identity();
        A.translate(vec(-maxShift, maxShift));
        // Drawn one per statement: the order in which a call's arguments are evaluated is
        // the compiler's choice (GCC and clang choose differently).
        const Eigen::Vector3d axis = unit();
        A.rotate(Eigen::AngleAxisd(uniform(0, maxAngle), axis));
        return A.matrix();
    }

  private:
    std::mt19937 gen_;
};

// exp of a 4x4 matrix by its truncated power series (3.6), scaled and squared so the
// series converges fast: an independent reference for the closed forms.
inline Eigen::Matrix4d seriesExp(const Eigen::Matrix4d& L) {
    int squarings = 0;
    double n = L.cwiseAbs().maxCoeff();
    while (n > 0.25) {
        n *= 0.5;
        ++squarings;
    }
    const Eigen::Matrix4d A = L / double(1 << squarings);
    Eigen::Matrix4d sum = Eigen::Matrix4d::Identity(), term = Eigen::Matrix4d::Identity();
    for (int k = 1; k < 30; ++k) {
        term = term * A / double(k);
        sum += term;
    }
    for (int i = 0; i < squarings; ++i)
        sum = sum * sum;
    return sum;
}

inline double maxDiff(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
    return (a - b).cwiseAbs().maxCoeff();
}

inline Eigen::Vector3d apply(const Eigen::Matrix4d& M, const Eigen::Vector3d& p) {
    return M.topLeftCorner<3, 3>() * p + M.topRightCorner<3, 1>();
}

} // namespace sweepers::test
