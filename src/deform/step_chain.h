// SPDX-License-Identifier: Apache-2.0
// Deformations applied one after another as one: their sub-steps in order, composed before a
// single resample of the grid. A swept-fluid segment (swept_fluid.h) chains the flow steps
// of the tool's successive positions this way.
#pragma once

#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "deform/step_deformation.h"

namespace sweepers {

class StepChain : public StepDeformation {
  public:
    explicit StepChain(std::vector<std::unique_ptr<StepDeformation>> parts)
        : parts_(std::move(parts)) {
        if (parts_.empty()) throw std::invalid_argument("a chain of deformations needs one");
        steps_ = 0;
        for (std::size_t i = 0; i < parts_.size(); ++i) {
            for (int k = 0; k < parts_[i]->steps(); ++k)
                at_.emplace_back(i, k);
            steps_ += parts_[i]->steps();
            affected_.add(parts_[i]->affectedBox());
            forwardTolerance_ = parts_[i]->forwardTolerance();
        }
    }

    bool identityOn(const Box& box) const override {
        for (const auto& p : parts_)
            if (!p->identityOn(box)) return false;
        return true;
    }
    bool stillAt(const Eigen::Vector3d& x) const override {
        for (const auto& p : parts_)
            if (!p->stillAt(x)) return false;
        return true;
    }
    Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const override {
        const auto [part, local] = at_[std::size_t(k)];
        return parts_[part]->inverseStep(local, p);
    }
    ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                              double tolerance = 0.0) const override {
        const auto [part, local] = at_[std::size_t(k)];
        return parts_[part]->forwardStep(local, q, tolerance);
    }
    std::size_t parts() const { return parts_.size(); }

  private:
    std::vector<std::unique_ptr<StepDeformation>> parts_;
    std::vector<std::pair<std::size_t, int>> at_; // by sub-step: its part, its index there
};

} // namespace sweepers
