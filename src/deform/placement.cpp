// SPDX-License-Identifier: Apache-2.0
#include "deform/placement.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/SVD>

#include "core/motion_log.h"

namespace sweepers {

Eigen::Affine3d Placement::matrix() const {
    Eigen::Affine3d X = Eigen::Affine3d::Identity();
    X.translate(t);
    if (hasRotation()) X.rotate(Eigen::AngleAxisd(angleDegrees * M_PI / 180.0, axis.normalized()));
    X.scale(scale);
    return X;
}

std::optional<Placement> placementOf(const Eigen::Matrix4d& X) {
    // X = T R S: the polar decomposition of the linear part, R P, must have P diagonal.
    const Eigen::Matrix3d L = X.topLeftCorner<3, 3>();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(L, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d U = svd.matrixU();
    const Eigen::Matrix3d& V = svd.matrixV();
    if ((U * V.transpose()).determinant() < 0.0) U.col(2) *= -1.0;
    const Eigen::Matrix3d R = U * V.transpose();
    const Eigen::Matrix3d P = R.transpose() * L;
    const Eigen::Vector3d scale = P.diagonal();
    if ((P - Eigen::Matrix3d(scale.asDiagonal())).norm() > 1e-9 * P.norm() ||
        !(scale.minCoeff() > 0.0))
        return std::nullopt;
    Placement p;
    p.t = X.topRightCorner<3, 1>();
    p.scale = scale;
    const Eigen::AngleAxisd turn(R);
    if (turn.angle() > 1e-12) {
        p.axis = turn.axis();
        p.angleDegrees = turn.angle() * 180.0 / M_PI;
    }
    return p;
}

std::optional<Placement> placementAlong(const Placement& a, const Placement& b, double f) {
    const Eigen::Matrix4d A = a.matrix().matrix();
    Eigen::Matrix4d X;
    try {
        X = (f * MotionLog::log(b.matrix().matrix() * A.inverse())).exp() * A;
    } catch (const std::domain_error&) {
        return std::nullopt;
    }
    return placementOf(X);
}

} // namespace sweepers
