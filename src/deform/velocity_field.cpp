// SPDX-License-Identifier: Apache-2.0
#include "deform/velocity_field.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "core/checks.h"

namespace sweepers {

namespace {

constexpr double kPi = 3.14159265358979323846;

const Box kUnitBox(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());

class Enright : public VelocityField {
  public:
    Eigen::Vector3d at(const Eigen::Vector3d& p, double t) const override {
        if (!kUnitBox.contains(p)) return Eigen::Vector3d::Zero();
        const Eigen::Array3d s = (kPi * p.array()).sin(), c = (kPi * p.array()).cos();
        const Eigen::Array3d s2 = 2.0 * s * c; // sin(2 pi x) ...
        const double m = std::cos(kPi * t / 3.0);
        return m * Eigen::Vector3d(2.0 * s[0] * s[0] * s2[1] * s2[2], -s2[0] * s[1] * s[1] * s2[2],
                                   -s2[0] * s2[1] * s[2] * s[2]);
    }
    // The operator norm of the Jacobian peaks at 4 pi (at (1/2, 0, 1/4), where only du/dy
    // is not zero; no higher on a 60^3 lattice of the box), with a fifth more for safety.
    // The entries' own bounds, (2, 4, 4) pi a row, would give 6 sqrt(3) pi: 2.2 times the
    // steps for nothing.
    double lipschitz() const override { return 1.2 * 4.0 * kPi; }
    Box support() const override { return kUnitBox; }
};

class Vortex : public VelocityField {
  public:
    Eigen::Vector3d at(const Eigen::Vector3d& p, double t) const override {
        if (!kUnitBox.contains(p)) return Eigen::Vector3d::Zero();
        const double sx = std::sin(kPi * p.x()), sy = std::sin(kPi * p.y());
        const double s2x = std::sin(2.0 * kPi * p.x()), s2y = std::sin(2.0 * kPi * p.y());
        const double m = std::cos(kPi * t / 8.0);
        return m * Eigen::Vector3d(-sx * sx * s2y, sy * sy * s2x, 0.0);
    }
    // Rows (pi, 2 pi) in size: sqrt(5) pi each.
    double lipschitz() const override { return kPi * std::sqrt(10.0); }
    Box support() const override { return kUnitBox; }
};

class Rotation : public VelocityField {
  public:
    explicit Rotation(const FieldSpec& s)
        : c_(s.center), w_(s.axis.normalized() * s.degreesPerSecond * kPi / 180.0), r_(s.radius),
          f_(s.falloff) {}
    Eigen::Vector3d at(const Eigen::Vector3d& p, double) const override {
        const Eigen::Vector3d d = p - c_;
        const double r = d.norm();
        if (r >= r_ + f_) return Eigen::Vector3d::Zero();
        double ease = 1.0;
        if (r > r_) {
            const double u = (r - r_) / f_; // C1 smoothstep down to rest
            ease = 1.0 - u * u * (3.0 - 2.0 * u);
        }
        return ease * w_.cross(d);
    }
    // |w| (1 + r |ease'|), with |ease'| at most 1.5 / falloff.
    double lipschitz() const override { return w_.norm() * (1.0 + (r_ + f_) * 1.5 / f_); }
    Box support() const override { return Box(c_.array() - (r_ + f_), c_.array() + (r_ + f_)); }

  private:
    Eigen::Vector3d c_, w_;
    double r_, f_;
};

} // namespace

Eigen::Matrix3d VelocityField::jacobian(const Eigen::Vector3d& p, double t) const {
    const double e = 1e-6;
    Eigen::Matrix3d J;
    for (int a = 0; a < 3; ++a) {
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        d[a] = e;
        J.col(a) = (at(p + d, t) - at(p - d, t)) / (2.0 * e);
    }
    return J;
}

std::shared_ptr<const VelocityField> makeField(const FieldSpec& spec) {
    switch (spec.kind) {
    case FieldSpec::Kind::Enright:
        return std::make_shared<Enright>();
    case FieldSpec::Kind::Vortex:
        return std::make_shared<Vortex>();
    case FieldSpec::Kind::Sampled:
        if (!spec.sampled)
            throw std::invalid_argument("the velocity file " + spec.file + " was not read");
        return spec.sampled;
    case FieldSpec::Kind::Rotation:
        break;
    }
    if (!spec.center.allFinite() || !spec.axis.allFinite() || !std::isfinite(spec.degreesPerSecond))
        throw std::invalid_argument("a rotation field's center, axis and speed must be finite");
    if (!(spec.axis.norm() > 0.0)) throw std::invalid_argument("a rotation field needs an axis");
    if (!finitePositive(spec.radius) || !finitePositive(spec.falloff))
        throw std::invalid_argument("a rotation field's radius and falloff must be positive");
    return std::make_shared<Rotation>(spec);
}

std::string fieldName(FieldSpec::Kind kind) {
    switch (kind) {
    case FieldSpec::Kind::Enright:
        return "enright";
    case FieldSpec::Kind::Vortex:
        return "vortex";
    case FieldSpec::Kind::Rotation:
        return "rotation";
    case FieldSpec::Kind::Sampled:
        return "vdb";
    }
    return "";
}

} // namespace sweepers
