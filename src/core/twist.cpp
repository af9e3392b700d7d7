// SPDX-License-Identifier: Apache-2.0
#include "core/twist.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace sweepers {

namespace {

Eigen::Matrix3d hat(const Eigen::Vector3d& w) {
    Eigen::Matrix3d W;
    W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    return W;
}

// Below this theta^2 the closed forms lose digits to cancellation; the truncated series
// are exact to well below double precision there (next terms ~ theta^8 / 4e7).
constexpr double kSeriesTheta2 = 1e-2;

} // namespace

TwistCoefficients twistCoefficients(double t2) {
    if (t2 < kSeriesTheta2) {
        return {0.5 - t2 / 24.0 + t2 * t2 / 720.0 - t2 * t2 * t2 / 40320.0,
                1.0 - t2 / 6.0 + t2 * t2 / 120.0 - t2 * t2 * t2 / 5040.0,
                1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0 - t2 * t2 * t2 / 362880.0};
    }
    const double t = std::sqrt(t2);
    const double s = std::sin(t);
    return {(1.0 - std::cos(t)) / t2, s / t, (t - s) / (t2 * t)};
}

Twist Twist::translation(const Eigen::Vector3d& v) {
    return {Eigen::Vector3d::Zero(), v};
}

Twist Twist::rotation(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& centre) {
    const Eigen::Vector3d w = axis.normalized() * angle;
    return {w, centre.cross(w)};
}

Twist Twist::screw(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& centre,
                   double slide) {
    const Eigen::Vector3d n = axis.normalized();
    Twist t = rotation(n, angle, centre);
    t.m += slide * n;
    return t;
}

Eigen::Matrix4d Twist::logMatrix() const {
    Eigen::Matrix4d L = Eigen::Matrix4d::Zero();
    L.topLeftCorner<3, 3>() = hat(omega);
    L.topRightCorner<3, 1>() = m;
    return L;
}

Eigen::Matrix4d Twist::exp() const {
    // 7.36 written blockwise: R = I + b W + a W^2, translation (I + a W + c W^2) m.
    const TwistCoefficients k = twistCoefficients(omega.squaredNorm());
    const Eigen::Matrix3d W = hat(omega);
    const Eigen::Matrix3d W2 = W * W;
    Eigen::Matrix4d E = Eigen::Matrix4d::Identity();
    E.topLeftCorner<3, 3>() += k.b * W + k.a * W2;
    E.topRightCorner<3, 1>() = (Eigen::Matrix3d::Identity() + k.a * W + k.c * W2) * m;
    return E;
}

Eigen::Vector3d Twist::applyToPoint(const Eigen::Vector3d& p) const {
    const double t2 = omega.squaredNorm();
    if (t2 == 0.0) return p + m; // 7.19
    const TwistCoefficients k = twistCoefficients(t2);
    if (omega.dot(m) == 0.0) {
        // Pure rotation about an axis off the origin (7.23).
        const Eigen::Vector3d xi = omega.cross(p) + m;
        return p + k.a * omega.cross(xi) + k.b * xi;
    }
    // General twist (7.29); (1 - b) / theta^2 is the coefficient c.
    return p + m + omega.cross(omega.cross(k.a * p + k.c * m) + k.a * m + k.b * p);
}

Eigen::Vector3d Twist::applyToVector(const Eigen::Vector3d& v) const {
    const double t2 = omega.squaredNorm();
    if (t2 == 0.0) return v;
    const TwistCoefficients k = twistCoefficients(t2);
    const Eigen::Vector3d wv = omega.cross(v);
    return v + k.a * omega.cross(wv) + k.b * wv; // 7.24 / 7.30
}

Twist logRigid(const Eigen::Matrix4d& M) {
    const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = M.topRightCorner<3, 1>();

    // sin(theta) n and cos(theta) from the skew and trace parts of R.
    const Eigen::Vector3d s_n(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
    const double sinTheta = 0.5 * s_n.norm();
    const double cosTheta = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
    const double theta = std::atan2(sinTheta, cosTheta);

    Eigen::Vector3d omega;
    if (cosTheta > -0.5) {
        // theta < 120 degrees: the skew part is well conditioned (or theta is tiny).
        const double t2 = theta * theta;
        const double scale =
            t2 < 1e-2 ? 0.5 * (1.0 + t2 / 6.0 + 7.0 * t2 * t2 / 360.0) : 0.5 * theta / sinTheta;
        omega = scale * s_n;
    } else {
        // Near pi sin(theta) vanishes; read the axis from the symmetric part
        // (R + R^T)/2 = cos(theta) I + (1 - cos(theta)) n n^T, largest column first.
        const Eigen::Matrix3d B =
            (0.5 * (R + R.transpose()) - cosTheta * Eigen::Matrix3d::Identity()) / (1.0 - cosTheta);
        Eigen::Index i = 0;
        B.diagonal().maxCoeff(&i);
        Eigen::Vector3d n = B.col(i) / std::sqrt(std::max(B(i, i), 1e-300));
        n.normalize();
        if (n.dot(s_n) < 0.0) n = -n;
        omega = theta * n;
    }

    // m = V^-1 t with V = I + a W + c W^2; V^-1 = I - W/2 + e W^2,
    // e = (1 - theta sin(theta) / (2 (1 - cos(theta)))) / theta^2.
    const double t2 = omega.squaredNorm();
    double e;
    if (t2 < 1e-2) {
        e = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
    } else {
        const TwistCoefficients k = twistCoefficients(t2);
        e = (1.0 - k.b / (2.0 * k.a)) / t2;
    }
    const Eigen::Matrix3d W = hat(omega);
    const Eigen::Vector3d m = t - 0.5 * W * t + e * (W * (W * t));
    return {omega, m};
}

} // namespace sweepers
