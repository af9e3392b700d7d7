// SPDX-License-Identifier: Apache-2.0
// MotionLog: the logarithm of an affine motion of space, the quantity that sweepers blend
// (3.5, 3.17). It is a 4x4 matrix with a zero last row, stored as its linear block and
// translation column, together with the narrowest family it belongs to, so that the
// exponential can take a closed form whenever one exists:
//
//   Translation  linear block 0                       exp: p + u              (A.1)
//   Twist        linear block skew (rigid motion)     exp: 7.29
//   Dilation     linear block alpha I (uniform scale) exp: e^a p + (e^a-1)/a u (A.2)
//   AxisScale    linear block a n n^T (scale along    exp: p + (e^a-1) n n.p + u
//                one axis, A.3)                            + ((e^a-1)/a - 1) n n.u
//   General      anything else (blended twist+scale,  exp: Pade matrix exponential
//                scales along several axes, mixed motions)
//
// Sums keep the narrowest family both terms share, so a blend of rigid motions, or of
// scales along one axis, stays on the fast closed form.
#pragma once

#include <Eigen/Core>

#include "core/twist.h"

namespace sweepers {

class MotionLog {
  public:
    enum class Kind { Translation, Twist, Dilation, AxisScale, General };

    MotionLog() = default;
    MotionLog(const Twist& t);

    static MotionLog translation(const Eigen::Vector3d& v) { return Twist::translation(v); }
    // log of a uniform scale by s > 0 about c (A.2.2): linear log(s) I, translation -c log s.
    static MotionLog uniformScale(double s, const Eigen::Vector3d& centre);
    // log of a scale by s > 0 along unit n about c (A.3.2): T_c (log(s) n n^T) T_-c.
    static MotionLog axisScale(double s, const Eigen::Vector3d& n, const Eigen::Vector3d& centre);
    // A general log; the kind is found from the block.
    static MotionLog fromMatrix(const Eigen::Matrix4d& L);

    // Logarithm of an affine 4x4 motion. Rigid motions go through logRigid, symmetric
    // positive definite linear parts (uniform and non-uniform scales about any centre)
    // through their eigen-decomposition; anything else through the matrix logarithm,
    // verified by exponentiating back. Throws std::domain_error when the motion has no
    // real logarithm (reflections, collapses, rotations by pi combined with scales).
    static MotionLog log(const Eigen::Matrix4d& M);

    Kind kind() const { return kind_; }
    const Eigen::Matrix3d& linear() const { return linear_; }
    const Eigen::Vector3d& translationPart() const { return u_; }
    // The twist <omega, m>; only meaningful for kinds Translation and Twist.
    Twist twist() const;

    Eigen::Matrix4d matrix() const;
    Eigen::Matrix4d exp() const;
    // exp(L) . p, closed form where the kind has one.
    Eigen::Vector3d applyExp(const Eigen::Vector3d& p) const;
    // exp(w L) . p: (L * w).applyExp(p), to the bit, without a scaled copy for a translation.
    Eigen::Vector3d applyExp(double w, const Eigen::Vector3d& p) const {
        return kind_ == Kind::Translation ? Eigen::Vector3d(p + u_ * w) : (*this * w).applyExp(p);
    }
    // L . p, the velocity of p; the sub-step bounds 3.14 / 3.19 measure it.
    Eigen::Vector3d velocity(const Eigen::Vector3d& p) const { return linear_ * p + u_; }

    MotionLog operator+(const MotionLog& o) const;
    MotionLog operator*(double w) const;
    MotionLog operator-() const { return *this * -1.0; }
    MotionLog& operator+=(const MotionLog& o) { return *this = *this + o; }
    // Conjugation by an affine map A: log(A M A^-1) = A log(M) A^-1. Mirrors use it.
    MotionLog conjugated(const Eigen::Matrix4d& A) const;

  private:
    Eigen::Matrix3d linear_ = Eigen::Matrix3d::Zero();
    Eigen::Vector3d u_ = Eigen::Vector3d::Zero();
    Eigen::Vector3d axis_ = Eigen::Vector3d::Zero(); // the unit n of a n n^T (AxisScale)
    Kind kind_ = Kind::Translation;
};

inline MotionLog operator*(double w, const MotionLog& l) {
    return l * w;
}

} // namespace sweepers
