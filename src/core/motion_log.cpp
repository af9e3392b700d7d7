// SPDX-License-Identifier: Apache-2.0
#include "core/motion_log.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

namespace sweepers {

namespace {

// Tolerance for recognising a family from matrix entries computed in floating point.
constexpr double kFamilyTol = 1e-12;

// (e^x - 1) / x and its reciprocal without cancellation near 0.
double expm1OverX(double x) {
    return x == 0.0 ? 1.0 : std::expm1(x) / x;
}

MotionLog::Kind join(MotionLog::Kind a, MotionLog::Kind b) {
    using K = MotionLog::Kind;
    if (a == b) return a;
    if (a == K::General || b == K::General) return K::General;
    if (a == K::Translation) return b;
    if (b == K::Translation) return a;
    return K::General; // twist + dilation, a scale along an axis + a twist or a dilation
}

} // namespace

MotionLog::MotionLog(const Twist& t) : u_(t.m) {
    linear_ << 0, -t.omega.z(), t.omega.y(), t.omega.z(), 0, -t.omega.x(), -t.omega.y(),
        t.omega.x(), 0;
    kind_ = t.omega.isZero(0.0) ? Kind::Translation : Kind::Twist;
}

MotionLog MotionLog::uniformScale(double s, const Eigen::Vector3d& centre) {
    if (!(s > 0.0)) throw std::domain_error("a scale factor must be positive");
    MotionLog l;
    const double a = std::log(s);
    l.linear_ = a * Eigen::Matrix3d::Identity();
    l.u_ = -a * centre;
    l.kind_ = a == 0.0 ? Kind::Translation : Kind::Dilation;
    return l;
}

MotionLog MotionLog::axisScale(double s, const Eigen::Vector3d& n, const Eigen::Vector3d& centre) {
    if (!(s > 0.0)) throw std::domain_error("a scale factor must be positive");
    const Eigen::Vector3d un = n.normalized();
    Eigen::Matrix4d L = Eigen::Matrix4d::Zero();
    L.topLeftCorner<3, 3>() = std::log(s) * un * un.transpose();
    L.topRightCorner<3, 1>() = -L.topLeftCorner<3, 3>() * centre; // T_c L T_-c
    return fromMatrix(L);
}

MotionLog MotionLog::fromMatrix(const Eigen::Matrix4d& L) {
    MotionLog l;
    l.linear_ = L.topLeftCorner<3, 3>();
    l.u_ = L.topRightCorner<3, 1>();
    const double scale = std::max(1.0, l.linear_.cwiseAbs().maxCoeff());
    const double tol = kFamilyTol * scale;
    const Eigen::Matrix3d sym = 0.5 * (l.linear_ + l.linear_.transpose());
    if (l.linear_.cwiseAbs().maxCoeff() <= tol) {
        l.linear_.setZero();
        l.kind_ = Kind::Translation;
    } else if (sym.cwiseAbs().maxCoeff() <= tol) {
        l.linear_ = 0.5 * (l.linear_ - l.linear_.transpose());
        l.kind_ = Kind::Twist;
    } else {
        const double alpha = l.linear_.trace() / 3.0;
        const bool dilation =
            (l.linear_ - alpha * Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= tol;
        if (dilation) {
            l.linear_ = alpha * Eigen::Matrix3d::Identity();
            l.kind_ = Kind::Dilation;
            return l;
        }
        // a n n^T (A.3)? Its column through the largest diagonal entry a n_i^2 is a n_i n,
        // the longest multiple of n among its columns, so the least spoilt by rounding.
        int i = 0;
        l.linear_.diagonal().cwiseAbs().maxCoeff(&i);
        const Eigen::Vector3d n = l.linear_.col(i).normalized();
        const double a = n.dot(l.linear_ * n);
        l.kind_ = Kind::General;
        if ((l.linear_ - a * n * n.transpose()).cwiseAbs().maxCoeff() <= tol) {
            l.linear_ = a * n * n.transpose();
            l.axis_ = n;
            l.kind_ = Kind::AxisScale;
        }
    }
    return l;
}

MotionLog MotionLog::log(const Eigen::Matrix4d& M) {
    if (!M.allFinite()) throw std::domain_error("the motion has non-finite entries");
    if (!M.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1), 1e-12))
        throw std::domain_error("the motion is not affine (last row must be 0 0 0 1)");
    const Eigen::Matrix3d A = M.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = M.topRightCorner<3, 1>();
    const double det = A.determinant();
    if (!(det > 0.0))
        throw std::domain_error("the motion mirrors or collapses space, it has no logarithm");

    // Rigid: orthonormal linear part.
    if ((A.transpose() * A - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-10)
        return logRigid(M);

    // Symmetric positive definite: scales along orthogonal axes about a centre (A.2, A.3).
    // log A = V log(S) V^T, and the translation solves ((e^L - I) L^-1) u = t, i.e.
    // u = V diag(log s_i / (s_i - 1)) V^T t.
    if ((A - A.transpose()).cwiseAbs().maxCoeff() < 1e-12 * A.cwiseAbs().maxCoeff()) {
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (A + A.transpose()));
        const Eigen::Vector3d& s = eig.eigenvalues();
        if (s.minCoeff() > 0.0) {
            const Eigen::Matrix3d& V = eig.eigenvectors();
            Eigen::Vector3d logS, inv;
            for (int i = 0; i < 3; ++i) {
                logS[i] = std::log(s[i]);
                inv[i] = 1.0 / expm1OverX(logS[i]);
            }
            Eigen::Matrix4d L = Eigen::Matrix4d::Zero();
            L.topLeftCorner<3, 3>() = V * logS.asDiagonal() * V.transpose();
            L.topRightCorner<3, 1>() = V * inv.asDiagonal() * V.transpose() * t;
            return fromMatrix(L);
        }
    }

    // Anything else (a rotation with a scale): principal matrix logarithm, checked.
    const Eigen::Matrix4d L = M.log();
    if (!L.allFinite() || L.row(3).cwiseAbs().maxCoeff() > 1e-9 ||
        !((L.exp() - M).cwiseAbs().maxCoeff() <= 1e-9 * std::max(1.0, M.cwiseAbs().maxCoeff())))
        throw std::domain_error("the motion has no real logarithm; split it into smaller steps");
    Eigen::Matrix4d clean = L;
    clean.row(3).setZero();
    return fromMatrix(clean);
}

Twist MotionLog::twist() const {
    return {Eigen::Vector3d(linear_(2, 1), linear_(0, 2), linear_(1, 0)), u_};
}

Eigen::Matrix4d MotionLog::matrix() const {
    Eigen::Matrix4d L = Eigen::Matrix4d::Zero();
    L.topLeftCorner<3, 3>() = linear_;
    L.topRightCorner<3, 1>() = u_;
    return L;
}

Eigen::Matrix4d MotionLog::exp() const {
    switch (kind_) {
    case Kind::Translation:
    case Kind::Twist:
        return twist().exp();
    case Kind::Dilation: {
        const double a = linear_(0, 0);
        Eigen::Matrix4d E = Eigen::Matrix4d::Identity();
        E.topLeftCorner<3, 3>() *= std::exp(a);
        E.topRightCorner<3, 1>() = expm1OverX(a) * u_;
        return E;
    }
    case Kind::AxisScale: { // as applyExp below
        const double a = axis_.dot(linear_ * axis_);
        Eigen::Matrix4d E = Eigen::Matrix4d::Identity();
        E.topLeftCorner<3, 3>() += std::expm1(a) * axis_ * axis_.transpose();
        E.topRightCorner<3, 1>() = u_ + (expm1OverX(a) - 1.0) * axis_.dot(u_) * axis_;
        return E;
    }
    case Kind::General:
        break;
    }
    Eigen::Matrix4d E = matrix().exp();
    E.row(3) = Eigen::RowVector4d(0, 0, 0, 1);
    return E;
}

Eigen::Vector3d MotionLog::applyExp(const Eigen::Vector3d& p) const {
    switch (kind_) {
    case Kind::Translation:
        return p + u_;
    case Kind::Twist:
        return twist().applyToPoint(p);
    case Kind::Dilation: {
        const double a = linear_(0, 0);
        return std::exp(a) * p + expm1OverX(a) * u_;
    }
    case Kind::AxisScale: {
        // L = a n n^T with (n n^T)^2 = n n^T, so exp(t L) = I + (e^{ta} - 1) n n^T, and the
        // translation is the integral of that over t in [0, 1] applied to u. For u = -a
        // (c.n) n this is 3.27's sub-step p + (e^a - 1) ((p - c).n) n; u is any vector
        // here, since a blend adds translations.
        const double a = axis_.dot(linear_ * axis_);
        return p + u_ +
               (std::expm1(a) * axis_.dot(p) + (expm1OverX(a) - 1.0) * axis_.dot(u_)) * axis_;
    }
    case Kind::General:
        break;
    }
    const Eigen::Matrix4d E = exp();
    return E.topLeftCorner<3, 3>() * p + E.topRightCorner<3, 1>();
}

MotionLog MotionLog::operator+(const MotionLog& o) const {
    MotionLog r;
    r.linear_ = linear_ + o.linear_;
    r.u_ = u_ + o.u_;
    r.kind_ = join(kind_, o.kind_);
    // Scales along one axis add up to a scale along it (one tool's log blended with itself);
    // along two axes they do not.
    if (kind_ == Kind::AxisScale && o.kind_ == Kind::AxisScale && axis_ != o.axis_ &&
        axis_ != -o.axis_)
        r.kind_ = Kind::General;
    r.axis_ = kind_ == Kind::AxisScale ? axis_ : o.axis_;
    return r;
}

MotionLog MotionLog::operator*(double w) const {
    MotionLog r = *this;
    r.linear_ *= w;
    r.u_ *= w;
    return r;
}

MotionLog MotionLog::conjugated(const Eigen::Matrix4d& A) const {
    const Eigen::Matrix4d C = A * matrix() * A.inverse();
    return fromMatrix(C);
}

} // namespace sweepers
