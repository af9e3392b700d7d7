// SPDX-License-Identifier: Apache-2.0
// Ball and filled-ellipsoid tools.
//
// Both are the unit ball scaled by semi-axes in the local frame. Under a placement the
// result is an ellipsoid in the world; when its three semi-axes are equal the closed-form
// ball distance applies (3.37), otherwise the true Euclidean distance to the filled
// ellipsoid is computed (3.38), not the scaled distance of 3.35, whose slope would vary
// over space.
#pragma once

#include "tools/tool_shape.h"

namespace sweepers {

class EllipsoidShape : public ToolShape {
  public:
    // A ball of the given radius.
    explicit EllipsoidShape(double radius);
    // An ellipsoid with semi-axes along the local x, y, z axes.
    explicit EllipsoidShape(const Eigen::Vector3d& semiAxes);

    std::string name() const override { return isBall_ ? "ball" : "ellipsoid"; }
    std::unique_ptr<PlacedShape> place(const Eigen::Affine3d& worldFromLocal) const override;
    const Eigen::Vector3d& semiAxes() const { return semiAxes_; }

  private:
    Eigen::Vector3d semiAxes_;
    bool isBall_;
};

// Distance from a point to the filled axis-aligned ellipsoid with the given semi-axes,
// centred at the origin. Exposed for tests.
double distanceToFilledEllipsoid(const Eigen::Vector3d& semiAxes, const Eigen::Vector3d& p);

} // namespace sweepers
