// SPDX-License-Identifier: Apache-2.0
// The interface every tool shape implements, and the tool (shape + falloff) built on it.
//
// A shape is defined in its own local frame; a placement (an affine world-from-local map,
// possibly with non-uniform scale or a mirror) puts it in the world. Distances are always
// measured in world units (3.36), so the falloff slope the artist sees does not depend on
// how the tool was scaled. A baked tool (a level set or mesh turned into a tool, 3.4.3)
// implements the same two classes.
#pragma once

#include <limits>
#include <memory>
#include <string>

#include <Eigen/Geometry>

#include "core/box.h"

namespace sweepers {

// A shape at one placement. Evaluated many times per placement, so implementations
// precompute what they can when placed.
class PlacedShape {
  public:
    virtual ~PlacedShape() = default;
    // Euclidean world distance from p to the filled shape; 0 inside.
    virtual double distance(const Eigen::Vector3d& p) const = 0;
    // The same where it is below `cutoff`; elsewhere any value >= cutoff. The falloff needs
    // no more, and shapes use it to skip exact work far away.
    virtual double distanceBelow(const Eigen::Vector3d& p, double /*cutoff*/) const {
        return distance(p);
    }
    // distanceBelow at the n points p, into out: one call for a leaf's voxels, where a call
    // per voxel went through two virtual calls.
    virtual void distancesBelow(const Eigen::Vector3d* p, std::size_t n, double cutoff,
                                double* out) const {
        for (std::size_t i = 0; i < n; ++i)
            out[i] = distanceBelow(p[i], cutoff);
    }
    // World box enclosing the shape.
    virtual Box bounds() const = 0;
    // A bound on |grad distance|. An exact distance has 1; a sampled one (a baked tool)
    // can be steeper between its samples, and the fold-over bound (3.14, 3.19) and the
    // reach tests scale by it.
    virtual double lipschitz() const { return 1.0; }
    // distanceBelow is exact below this world distance (a sampled distance is exact only
    // within the band it was built with); a falloff wider than it is refused.
    virtual double exactBelow() const { return std::numeric_limits<double>::infinity(); }
};

class ToolShape {
  public:
    virtual ~ToolShape() = default;
    virtual std::string name() const = 0;
    virtual std::unique_ptr<PlacedShape> place(const Eigen::Affine3d& worldFromLocal) const = 0;
};

// A shape placed in the world with its falloff width lambda (world units): the influence
// phi = mu_lambda(distance) (3.3) is 1 inside the tool, in (0, 1) on its coating of
// thickness lambda, 0 outside.
class PlacedTool {
  public:
    // Throws std::invalid_argument for a falloff that is not positive or that reaches
    // past where the shape's distance is known.
    PlacedTool(std::unique_ptr<PlacedShape> shape, double falloff);

    double influence(const Eigen::Vector3d& p) const;
    // influence at the n points p, into out (the same values, to the bit).
    void influences(const Eigen::Vector3d* p, std::size_t n, double* out) const;
    double distance(const Eigen::Vector3d& p) const { return shape_->distance(p); }
    // Box enclosing the tool and its coating: outside it the influence is exactly 0.
    const Box& coatingBounds() const { return coating_; }
    double falloff() const { return falloff_; }
    double lipschitz() const { return shape_->lipschitz(); }

  private:
    std::unique_ptr<PlacedShape> shape_;
    double falloff_;
    Box coating_;
};

} // namespace sweepers
