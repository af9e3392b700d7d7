// SPDX-License-Identifier: Apache-2.0
// The pinch tool (thesis 3.5.1): two needles on a line through `at` along `axis` whose tips
// start at at +- size axis and meet at `at`, each weighting a translation along the line by
// its discontinuous field (3.39, 3.40: a cone around the needle's body, bounded by a ball
// around the tip). The field is discontinuous at the tip, so the number of sub-steps is
// taken from the fold-over bound a voxel away from it (the grid sees nothing finer), and
// the travel is split into segments of a quarter of the falloff. When the tips meet, the
// surface touches itself at `at`; the pull (3.41, tear.h) then opens the hole to radius
// `open` around the segment the needles travelled.
//
// The needles' fields: a_in = 10 degrees, a_out = 30, r_in = falloff / 2, r_out = falloff.
// Sub-step k of a segment is defined by its inverse with the tips at tau_{k+1} (5.18), and
// the two translations are blended as tools are (3.17).
#pragma once

#include <memory>
#include <vector>

#include "deform/cone_field.h"
#include "deform/step_deformation.h"

namespace sweepers {

struct PinchSpec {
    Eigen::Vector3d at = Eigen::Vector3d::Zero();
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ(); // any length but zero
    double size = 1.0;                               // tips start at at +- size axis
    double falloff = 0.3;                            // lambda: a needle's reach
    double open = 0.1;                               // the hole's radius
};

// Throws std::invalid_argument, naming the field, when the spec cannot make a pinch.
void checkPinch(const PinchSpec& spec);

class PinchNeedles : public StepDeformation {
  public:
    // The tips moving from u0 to u1 (0: at +- size axis; 1: at `at`) in `steps` sub-steps.
    PinchNeedles(const PinchSpec& spec, double u0, double u1, int steps);

    // The tip of needle 0 (above `at` along the axis) or 1 (below) at u.
    Eigen::Vector3d tip(int needle, double u) const;
    const ConeField& field() const { return field_; }

    Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const override;
    ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                              double tolerance = 0.0) const override;
    bool identityOn(const Box& box) const override;
    bool stillAt(const Eigen::Vector3d& p) const override;

  private:
    // How far sub-step k moves p (the tips at tau_{k+1}).
    Eigen::Vector3d displacement(int k, const Eigen::Vector3d& p) const;
    double weight(int needle, const Eigen::Vector3d& tip, const Eigen::Vector3d& p) const;
    // Whether every point within `margin` of c lies beyond the needles' reach.
    bool beyondReach(const Eigen::Vector3d& c, double margin) const;

    Eigen::Vector3d at_, axis_;
    double size_, u0_, u1_;
    ConeField field_;
    double cosIn2_ = 0.0, cosOut2_ = 0.0; // squared cosines of the cone's angles
};

// The pinch's deformations at the given voxel size: the needles' segments, then the pull.
std::vector<std::unique_ptr<StepDeformation>> planPinch(const PinchSpec& spec, double voxelSize);
// How many deformations planPinch makes (it does not depend on the voxel size).
std::size_t pinchSegmentCount(const PinchSpec& spec);

} // namespace sweepers
