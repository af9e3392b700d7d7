// SPDX-License-Identifier: Apache-2.0
// The first m sub-steps of a deformation: the part of its motion done by a fraction m / s
// of the way (animated modeling, thesis 3.6.2: the partial motion stands in for the
// segment's end placement, 3.48). A sweep segment's sub-steps follow its motion, so the
// prefix moves the tools part of the way along it; a pinch's or a strangle's sub-steps
// advance its needles or its circle. A deformation of one sub-step has no prefix between
// nothing and all of it.
#pragma once

#include <stdexcept>

#include "deform/step_deformation.h"

namespace sweepers {

class StepPrefix : public StepDeformation {
  public:
    // 0 < m < whole.steps(); `whole` must outlive the prefix.
    StepPrefix(const StepDeformation& whole, int m) : whole_(whole) {
        if (!(m > 0 && m < whole.steps()))
            throw std::invalid_argument("a prefix holds some of the sub-steps, not none or all");
        steps_ = m;
        affected_ = whole.affectedBox();
        forwardTolerance_ = whole.forwardTolerance();
    }

    // What holds for every sub-step of the whole holds for the first m.
    bool identityOn(const Box& box) const override { return whole_.identityOn(box); }
    bool stillAt(const Eigen::Vector3d& p) const override { return whole_.stillAt(p); }
    Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const override {
        return whole_.inverseStep(k, p);
    }
    ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                              double tolerance = 0.0) const override {
        return whole_.forwardStep(k, q, tolerance);
    }
    // The whole's bound holds for its first sub-steps (StepDeformation::stretchBound).
    double stretchBound() const override { return whole_.stretchBound(); }

  private:
    const StepDeformation& whole_;
};

} // namespace sweepers
