// SPDX-License-Identifier: Apache-2.0
// Sweeps: one or several tools moved together along a path of placements, optionally
// mirrored about a coordinate plane (thesis chapter 3, 5.3.3).
//
// A segment (one pair of consecutive placements) is split into s sub-steps by the
// fold-over bound (3.14 for one tool, 3.19 for several). Sub-step k moves tool j by
// M_j^(1/s), from placement tau_k = (k/s (.) M_j) X_j,A to tau_{k+1} (3.12, 3.13).
//
// The deformation is *defined* by its closed-form inverse (5.18, 5.19): the inverse of
// sub-step k at p is exp(-c(p) sum_j phi_j(p) log(M_j)/s) . p with the influences phi_j of
// the tools at tau_{k+1} and c = (1 - prod(1 - phi_j)) / sum(phi_j), the normalized blend
// of 3.17 (c phi = phi for one tool). A segment's inverse applies the inverse sub-steps
// last first; its forward map solves each sub-step by fixed-point iteration (INVERTFASTER,
// 5.4.1 generalized to several tools).
#pragma once

#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "core/box.h"
#include "core/motion_log.h"
#include "deform/placement.h"
#include "deform/step_deformation.h"
#include "tools/tool_shape.h"

namespace sweepers {

enum class MirrorAxis { None, X, Y, Z };

struct SweptTool {
    std::shared_ptr<const ToolShape> shape;
    double falloff = 0.0; // lambda, world units
    std::vector<Placement> path;
};

struct Sweep {
    std::vector<SweptTool> tools;
    MirrorAxis mirror = MirrorAxis::None;

    // Number of segments; every tool must have the same number of placements (>= 2).
    // Throws std::invalid_argument otherwise.
    std::size_t segmentCount() const;
};

struct SegmentOptions {
    int forceSteps = 0;              // > 0: use this many sub-steps instead of the bound
    double forwardTolerance = 1e-12; // fixed-point convergence, relative to 1 + |p|
    int forwardMaxIterations = 500;
};

class SweepSegment : public StepDeformation {
  public:
    // Plans segment `index` of the sweep. Throws std::invalid_argument for a malformed
    // sweep and std::domain_error for a motion without a logarithm.
    SweepSegment(const Sweep& sweep, std::size_t index, const SegmentOptions& options = {});

    // The fold-over bound the step count was taken from (left side of 3.19).
    double stepBound() const { return stepBound_; }
    // Tools after mirroring (a mirrored sweep has twice as many).
    std::size_t toolCount() const { return tools_.size(); }
    const MotionLog& motionLog(std::size_t tool) const { return tools_[tool].log; }

    // Tool j at sub-step placement tau_k, k in [0, s].
    const PlacedTool& placedTool(std::size_t j, int k) const { return *tools_[j].placed[k]; }

    // Also true where the box lies in the affected box but beyond every tool's coating.
    bool identityOn(const Box& box) const override;

    // Known for one tool moved without turning or scaling (a drag); +infinity otherwise.
    double stretchBound() const override { return stretchBound_; }

    // For one tool, the blend is its influence times its log (3.17 with c phi = phi): the
    // sub-steps apply that directly. Several tools take the blend of stepLog.
    Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const override;
    using StepDeformation::forwardSteps;
    using StepDeformation::inverseMaps;
    void inverseMaps(const Eigen::Vector3d* p, std::size_t n, Eigen::Vector3d* out,
                     MapScratch& scratch) const override;
    void forwardSteps(int k, const Eigen::Vector3d* q, std::size_t n, double tolerance,
                      Eigen::Vector3d* out, MapScratch& scratch) const override;
    ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                              double tolerance = 0.0) const override;

  protected:
    // The normalized blend of sub-step k at p (tools at tau_{k+1}).
    std::optional<MotionLog> stepLog(int k, const Eigen::Vector3d& p) const override;

  private:
    // The influence phi of the one tool at sub-step k (tools at tau_{k+1}) at p.
    double oneToolInfluence(int k, const Eigen::Vector3d& p) const {
        return stepBoxes_[std::size_t(k)].contains(p)
                   ? tools_[0].placed[std::size_t(k) + 1]->influence(p)
                   : 0.0;
    }

    // exp(w L) p for the one tool's sub-step log L (5.18: w = -phi inverts a sub-step, w = phi
    // iterates it forward), and p itself where w is 0, to the bit.
    Eigen::Vector3d oneToolStep(double w, const Eigen::Vector3d& p) const {
        return w == 0.0 ? p : tools_[0].stepLog.applyExp(w, p);
    }

    // The points at[i], i in `which` (in order), that lie in sub-step k's box, and the one
    // tool's influence there (influence, to the bit), into the scratch's index, points and
    // phi: what the batched maps gather.
    void influencesInBox(int k, const std::vector<std::size_t>& which, const Eigen::Vector3d* at,
                         MapScratch& into) const;

    struct ToolPlan {
        MotionLog log;                                   // log M_j for the whole segment
        MotionLog stepLog;                               // log M_j / s
        std::vector<std::unique_ptr<PlacedTool>> placed; // k = 0..s
    };
    std::vector<ToolPlan> tools_;
    std::vector<Box> stepBoxes_; // union of coatings at tau_{k+1}
    double stepBound_ = 0.0;
    double stretchBound_ = std::numeric_limits<double>::infinity();
};

// The reflection matrix of a mirror plane through the origin.
Eigen::Matrix4d mirrorMatrix(MirrorAxis axis);

} // namespace sweepers
