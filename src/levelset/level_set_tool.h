// SPDX-License-Identifier: Apache-2.0
// Baked tools (thesis 3.4.3): any closed shape, given as a level set, used as a sculpting
// tool with the same falloff, sub-step bound and blending as a ball.
//
// The tool's distance is its level set sampled trilinearly and clamped at 0 inside. The
// falloff needs it exactly up to the falloff width, so the tool's grid carries an outside
// band at least that wide (bakeToolGrid). Past the band the distance is extended, not
// clamped: it is the larger of the band's edge value and the distance to the shape's box,
// both below the true distance, so the influence (3.3) still reaches 0 and stays there.
//
// Trilinear sampling makes the distance only piecewise smooth, and it can be steeper than
// 1 between samples. Its Lipschitz bound is measured over the grid's cells when the tool
// is made (lipschitz()); the fold-over bound (3.14, 3.19) multiplies the sub-steps by it,
// so a baked tool keeps the deformation fold-free.
//
// The level set's own coordinates are the tool's local frame: its origin is the point the
// tool's path moves and turns about. Placements may move, turn, mirror and scale it
// uniformly; a non-uniform scale would stop the sampled values being world distances.
#pragma once

#include <memory>
#include <string>

#include "levelset/interrupt.h"
#include "tools/tool_shape.h"
#include "vdb/vdb.h"

namespace sweepers {

class LevelSetTool : public ToolShape {
  public:
    // Takes the grid as it is (it is not copied and must not change afterwards). Throws
    // std::invalid_argument when the level set has no inside.
    LevelSetTool(GridPtr grid, std::string name);

    // The same tool scaled uniformly by `factor` (> 0) about its origin; shares the grid.
    std::shared_ptr<const LevelSetTool> scaled(double factor) const;

    std::string name() const override { return data_->name; }
    // Throws std::invalid_argument for a placement that does not scale uniformly.
    std::unique_ptr<PlacedShape> place(const Eigen::Affine3d& worldFromLocal) const override;

    // In the tool's own units (before `scaled`): the distance is exact below reach().
    double reach() const { return data_->reach; }
    double lipschitz() const { return data_->lipschitz; }
    double scale() const { return scale_; }
    // Box of the shape itself (where the distance is 0), in the tool's own units.
    const Box& localBounds() const { return data_->bounds; }
    const Grid& grid() const { return *data_->grid; }

    // Distance from a point in the tool's own units, before scaling.
    double localDistance(const Eigen::Vector3d& q) const;

  private:
    struct Data {
        GridPtr grid;
        std::string name;
        double reach = 0.0;
        double lipschitz = 1.0;
        Box bounds;
    };
    LevelSetTool(std::shared_ptr<const Data> data, double scale)
        : data_(std::move(data)), scale_(scale) {}
    std::shared_ptr<const Data> data_;
    double scale_ = 1.0;
};

// The grid a baked tool needs: `levelSet` with its band widened outside to cover `reach`
// (in the level set's own units) plus two voxels. Throws Cancelled when `interrupter`
// stops it.
GridPtr bakeToolGrid(const Grid& levelSet, double reach, Interrupter* interrupter = nullptr);

// The same from a closed triangle mesh, sampled at `voxelSize` (three voxels inside).
GridPtr bakeToolGrid(const std::vector<Eigen::Vector3f>& vertices,
                     const std::vector<Eigen::Vector3i>& triangles, double voxelSize, double reach,
                     Interrupter* interrupter = nullptr);

} // namespace sweepers
