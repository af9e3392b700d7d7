// SPDX-License-Identifier: Apache-2.0
// Velocity fields v(x, t): deformations given by a flow (thesis chapter 4), whose
// characteristics the flow steps of flow.h integrate. Each field is zero outside a box and
// Lipschitz in x with a known bound, which bounds the integration steps.
#pragma once

#include <memory>
#include <string>

#include "core/box.h"

namespace sweepers {

class VelocityField {
  public:
    virtual ~VelocityField() = default;
    virtual Eigen::Vector3d at(const Eigen::Vector3d& p, double t) const = 0;
    // A bound on the operator norm of dv/dx over all space and time (for Enright's field,
    // its measured peak with a margin).
    virtual double lipschitz() const = 0;
    // v is zero outside this box (and on its faces), so nothing crosses them.
    virtual Box support() const = 0;
    // The field's spatial derivative at p, by central differences.
    Eigen::Matrix3d jacobian(const Eigen::Vector3d& p, double t) const;
};

// What a script names (the "field" of a flow stroke).
struct FieldSpec {
    enum class Kind { Enright, Vortex, Rotation, Sampled };
    Kind kind = Kind::Enright;
    // Rotation: about the axis through `center`, `degreesPerSecond` (right-handed), rigid
    // within `radius` of the center and easing to rest over `falloff` beyond it (C1).
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
    double degreesPerSecond = 90.0, radius = 1.0, falloff = 0.5;
    // Sampled: a velocity grid in a VDB file (as written in the script, relative to it; the
    // grid's name, empty for the first), read by io/ when the script is (sampled_field.h).
    std::string file, gridName;
    std::shared_ptr<const VelocityField> sampled;
};

// Enright et al.'s 3D deformation test (2002, after LeVeque): in the unit box,
//   u =  2 sin^2(pi x) sin(2 pi y) sin(2 pi z) cos(pi t / T),
//   v = -sin(2 pi x) sin^2(pi y) sin(2 pi z) cos(pi t / T),
//   w = -sin(2 pi x) sin(2 pi y) sin^2(pi z) cos(pi t / T),
// with period T = 3: the flow stretches a sphere into a thin sheet until T / 2 and brings it
// back by T. Divergence-free; zero on the box's faces.
// Vortex: LeVeque's single vortex in the unit square, the same in every slice of the unit
// box along z (w = 0), period T = 8:
//   u = -sin^2(pi x) sin(2 pi y) cos(pi t / T),  v = sin^2(pi y) sin(2 pi x) cos(pi t / T).
// Sampled: the field io/ read. Throws std::invalid_argument for a rotation that is not
// finite, or whose axis, radius or falloff is not positive, or a sampled field not read.
std::shared_ptr<const VelocityField> makeField(const FieldSpec& spec);

// The name a script gives the field ("enright", "vortex", "rotation", "vdb").
std::string fieldName(FieldSpec::Kind kind);

} // namespace sweepers
