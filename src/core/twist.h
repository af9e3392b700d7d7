// SPDX-License-Identifier: Apache-2.0
// Twist (the thesis's "hexanion", chapter 7): the logarithm of a rigid motion as a pair of
// vectors <omega, m>. omega is the rotation axis scaled by the angle, m the translation
// column of the log matrix (7.3). Twists form a real vector space, so fractions and
// weighted blends of rigid motions are plain vector arithmetic (7.5, 7.60).
#pragma once

#include <Eigen/Core>

namespace sweepers {

struct Twist {
    Eigen::Vector3d omega = Eigen::Vector3d::Zero();
    Eigen::Vector3d m = Eigen::Vector3d::Zero();

    Twist() = default;
    Twist(const Eigen::Vector3d& omega_, const Eigen::Vector3d& m_) : omega(omega_), m(m_) {}

    // <0, v> (7.17).
    static Twist translation(const Eigen::Vector3d& v);
    // Rotation by `angle` radians about the line through `centre` along unit `axis`:
    // <theta n, c x theta n> (7.20).
    static Twist rotation(const Eigen::Vector3d& axis, double angle,
                          const Eigen::Vector3d& centre = Eigen::Vector3d::Zero());
    // Screw: rotation as above plus a slide `slide` along the axis (7.25).
    static Twist screw(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& centre,
                       double slide);

    Twist operator+(const Twist& o) const { return {omega + o.omega, m + o.m}; }
    Twist operator-(const Twist& o) const { return {omega - o.omega, m - o.m}; }
    Twist operator-() const { return {-omega, -m}; }
    Twist operator*(double w) const { return {omega * w, m * w}; }
    Twist& operator+=(const Twist& o) {
        omega += o.omega;
        m += o.m;
        return *this;
    }

    bool isTranslation() const { return omega.isZero(0.0); }

    // The 4x4 log matrix (7.3).
    Eigen::Matrix4d logMatrix() const;
    // exp <omega, m> as a 4x4 rigid matrix, closed form (7.28 / 7.36).
    Eigen::Matrix4d exp() const;
    // exp <omega, m> . p without forming the matrix: translation (7.19), rotation (7.23)
    // or general twist (7.29).
    Eigen::Vector3d applyToPoint(const Eigen::Vector3d& p) const;
    // exp <omega, m> . v for a direction: only the rotation acts (7.24 / 7.30).
    Eigen::Vector3d applyToVector(const Eigen::Vector3d& v) const;
    // log M . p: the velocity of p under the motion, omega x p + m.
    Eigen::Vector3d velocity(const Eigen::Vector3d& p) const { return omega.cross(p) + m; }
};

inline Twist operator*(double w, const Twist& t) {
    return t * w;
}

// The twist of a rigid 4x4 matrix (rotation part orthonormal with determinant 1).
// Replaces the case split of 7.46-7.57 with an axis-angle logarithm that stays accurate
// near 0 (series) and near pi (axis from the symmetric part). The angle returned lies in
// [0, pi]: a matrix forgets how many turns produced it.
Twist logRigid(const Eigen::Matrix4d& M);

// Coefficients of the closed-form exponential, with series near theta = 0 where the
// direct formulas lose precision:
//   a = (1 - cos t) / t^2,  b = sin t / t,  c = (t - sin t) / t^3.
struct TwistCoefficients {
    double a, b, c;
};
TwistCoefficients twistCoefficients(double theta2);

} // namespace sweepers
