// SPDX-License-Identifier: Apache-2.0
// Deformations given by a velocity field (velocity_field.h): a flow from time t0 to t1 is
// applied in segments, each one resample of the grid, and each segment composes the inverse
// of its sub-steps before that one sample, as every deformation of the engine does. A
// sub-step's inverse follows the characteristic through the point backward in time (RK4);
// since the flow is smooth, the whole segment's inverse is one characteristic, traced back
// from t1 to t0 however far it goes. Steps are bounded by the field's Lipschitz constant L:
// sub-steps last at most 1 / (2 L) (the forward map, found by fixed-point iteration on the
// inverse, then contracts) and RK4 steps at most 1 / (4 L), so no two characteristics cross.
#pragma once

#include <memory>
#include <vector>

#include "deform/step_deformation.h"
#include "deform/velocity_field.h"

namespace sweepers {

class FlowStep : public StepDeformation {
  public:
    // From time t0 to t1 (t1 > t0).
    FlowStep(std::shared_ptr<const VelocityField> field, double t0, double t1);

    Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const override;
    // Integrates forward, then corrects by fixed-point iteration on the inverse, so that
    // inverseStep(k, forwardStep(k, q)) = q to the tolerance.
    ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                              double tolerance = 0.0) const override;
    double from() const { return t0_; }
    double to() const { return t1_; }

  private:
    // The characteristic through p at time a, at time b (RK4, `steps` equal steps).
    Eigen::Vector3d trace(const Eigen::Vector3d& p, double a, double b, int steps) const;

    std::shared_ptr<const VelocityField> field_;
    double t0_, t1_, dt_;
    int rk_ = 1; // RK4 steps per sub-step
};

// The flow from t0 to t1 in `segments` segments of equal time.
std::vector<std::unique_ptr<StepDeformation>>
planFlow(const std::shared_ptr<const VelocityField>& field, double t0, double t1, int segments);

// The fewest segments (a power of two, at most `most`) in which the flow from t0 to t1 can
// be applied to a surface through `points` with the inverse map of every segment stretching
// no neighbourhood of the moved points by more than `maxStretch` (the largest singular
// value of its Jacobian): beyond the stretch the advection can widen the band for, a
// segment would sample values the old band does not hold. The points are followed with
// their Jacobians (the variational equation dJ/dt = dv/dx J) through 64 checkpoints.
int flowSegments(const VelocityField& field, double t0, double t1,
                 const std::vector<Eigen::Vector3d>& points, double maxStretch = 16.0,
                 int most = 64);

} // namespace sweepers
