// SPDX-License-Identifier: Apache-2.0
// A tool placement along a path: translation t, optional rotation (axis, angle in degrees)
// and scale (uniform or per local axis). As a world-from-local matrix it is T(t) R S.
#pragma once

#include <optional>

#include <Eigen/Geometry>

namespace sweepers {

struct Placement {
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
    double angleDegrees = 0.0;
    Eigen::Vector3d scale = Eigen::Vector3d::Ones();

    bool hasRotation() const { return angleDegrees != 0.0; }
    bool uniformScale() const { return scale.x() == scale.y() && scale.y() == scale.z(); }
    Eigen::Affine3d matrix() const;
    bool operator==(const Placement& o) const {
        return t == o.t && axis == o.axis && angleDegrees == o.angleDegrees && scale == o.scale;
    }
};

// The placement whose matrix is X, when X is of the form T R S (nullopt otherwise).
std::optional<Placement> placementOf(const Eigen::Matrix4d& X);

// The placement a fraction f of the way along the motion from a to b, exp(f log(B A^-1)) A
// (as the sub-step placements of 3.12 are), or nullopt where that is not of the form T R S:
// a scale along axes other than the tool's own, or a motion without a logarithm.
std::optional<Placement> placementAlong(const Placement& a, const Placement& b, double f);

} // namespace sweepers
