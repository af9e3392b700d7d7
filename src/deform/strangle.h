// SPDX-License-Identifier: Apache-2.0
// The strangle tool (thesis 3.5.2): a circle of radius `size` in the plane through `at`
// normal to `axis` contracts onto its centre, weighting a scale of the plane's directions
// about the axis by a field discontinuous on the disc it spans (3.43-3.45: a cone around
// the outward direction at the circle's nearest point, bounded by a ball of radius size +
// falloff around `at`). What the circle passes is drawn in with it, so a limb through the
// circle is squeezed to a point at `at`; the pull (3.41, tear.h) then parts the two sides
// by `open` across the disc.
//
// The field: a_in = 5 degrees, a_out = 20, r_in = size, r_out = size + falloff. The circle
// cannot reach radius 0 (the scale would be 0); it stops at a quarter of a voxel, below
// what the grid resolves. Its radius shrinks by at most a fraction of a voxel per sub-step
// (the fold-over bound a voxel away from the circle: nothing the grid resolves folds) and
// by at most a fixed ratio (the bound far from it, where the scale moves points by their
// distance to the axis).
#pragma once

#include <memory>
#include <vector>

#include "deform/cone_field.h"
#include "deform/step_deformation.h"

namespace sweepers {

struct StrangleSpec {
    Eigen::Vector3d at = Eigen::Vector3d::Zero();
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ(); // the circle's normal, any length but zero
    double size = 0.5;                               // the circle's radius
    double falloff = 0.3;                            // lambda
    double open = 0.1;                               // the gap between the parts
};

// Throws std::invalid_argument, naming the field, when the spec cannot make a strangle.
void checkStrangle(const StrangleSpec& spec);

class StrangleNoose : public StepDeformation {
  public:
    // radii[k], k = 0..s: the circle's radius at sub-step placement k (decreasing).
    StrangleNoose(const StrangleSpec& spec, std::vector<double> radii);

    double radius(int k) const { return radii_[std::size_t(k)]; }
    const ConeField& field() const { return field_; }

    Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const override;
    ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                              double tolerance = 0.0) const override;
    bool identityOn(const Box& box) const override;
    bool stillAt(const Eigen::Vector3d& p) const override;

  private:
    // phi at p with the circle of radius R (3.43).
    double weight(double R, const Eigen::Vector3d& p) const;
    // p with its distance to the axis scaled by `factor`.
    Eigen::Vector3d scaled(const Eigen::Vector3d& p, double factor) const;

    Eigen::Vector3d at_, axis_;
    std::vector<double> radii_;
    ConeField field_;
    double tanIn_ = 0.0, tanOut_ = 0.0; // tangents of the wedge's angles
};

// The strangle's deformations at the given voxel size: the noose's segments, then the pull.
std::vector<std::unique_ptr<StepDeformation>> planStrangle(const StrangleSpec& spec,
                                                           double voxelSize);

} // namespace sweepers
