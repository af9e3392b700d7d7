// SPDX-License-Identifier: Apache-2.0
// The exact shape a stroke history defines, known without any grid (the idea of thesis
// 5.4): every sub-step is given by the closed form of its inverse (5.18, 5.19), so a point x
// lies inside the sculpted shape exactly when the start shape contains
// D_1^-1(D_2^-1(... D_n^-1(x))), D_1 ... D_n the deformations applied, in order. The
// reference implicit function is phi_ref(x) = phi_start(history^-1(x)): not a distance,
// but its zero set is the true surface, which a grid result can be measured against.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/box.h"
#include "deform/step_deformation.h"
#include "vdb/vdb.h"

namespace sweepers {

class ExactReference {
  public:
    // The start shape's implicit function, negative inside.
    using StartFunction = std::function<double(const Eigen::Vector3d&)>;

    // A sphere's signed distance: exact.
    static StartFunction sphere(const Eigen::Vector3d& center, double radius);
    // A start grid sampled trilinearly (a start read from a file or a mesh): exact only up to
    // the start grid's own sampling, which a study has to say.
    static StartFunction sampled(const GridPtr& start);

    explicit ExactReference(StartFunction start);

    // The next deformation of the history (as applied: a segment's plan is kept, not
    // re-planned, so that strokes planned on the grid they met are taken as they were).
    void append(std::shared_ptr<const StepDeformation> deformation);
    std::size_t size() const { return history_.size(); }

    // history^-1(x): the point of the start shape that ends at x.
    Eigen::Vector3d pullBack(const Eigen::Vector3d& x) const;
    // phi_ref(x): negative inside the sculpted shape.
    double value(const Eigen::Vector3d& x) const;
    // The point of the segment [a, b] where phi_ref changes sign, to `tolerance` (world
    // units) along it; nullopt when phi_ref has the same sign at both ends.
    std::optional<Eigen::Vector3d> crossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                            double tolerance) const;

    // The history as the points of `box` see it (a leaf of a grid, a bracket around a mesh
    // vertex): the deformations that are the identity on every point on the way back from
    // the box (identityOn) are skipped, exactly; value and crossing give what the whole
    // history gives, to the bit, and cost what the rest costs. A point that leaves the box's
    // bound on its way back is taken through the whole history.
    class Near {
      public:
        double value(const Eigen::Vector3d& x) const;
        std::optional<Eigen::Vector3d> crossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                double tolerance) const;
        // The deformations kept, of the history's.
        std::size_t size() const { return steps_.size(); }

      private:
        friend class ExactReference;
        const ExactReference* reference_ = nullptr;
        Box box_;
        // The deformations kept, latest first, and after each the box every point of `box_`
        // lies in on its way back (the box grown by what the deformation reaches).
        std::vector<std::size_t> steps_;
        std::vector<Box> after_;
    };
    Near near(const Box& box) const;

  private:
    // phi_ref(x) through the deformations `steps` (latest first); nullopt when the point
    // leaves the box its step allows (`after`, when given).
    std::optional<double> valueAlong(const std::vector<std::size_t>& steps,
                                     const std::vector<Box>* after, const Eigen::Vector3d& x) const;

    StartFunction start_;
    std::vector<std::shared_ptr<const StepDeformation>> history_;
    std::vector<std::size_t> latestFirst_; // the history's indices, the last applied first
    std::vector<double> fromValues_;       // per deformation: the value a fill is made from, or 0
    bool fills_ = false;                   // whether a deformation of the history fills a region
};

} // namespace sweepers
