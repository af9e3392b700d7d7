// SPDX-License-Identifier: Apache-2.0
#include "levelset/level_set_tool.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "levelset/create.h"
#include "levelset/renormalize.h"

namespace sweepers {

namespace {

// Unregistered accessors: one per query costs a few stores, and queries come from many
// threads at once.
using ConstAccessor = openvdb::tree::ValueAccessor<const Grid::TreeType, false>;

double boxDistance(const Box& box, const Eigen::Vector3d& q) {
    const Eigen::Vector3d out =
        (box.min - q).cwiseMax(q - box.max).cwiseMax(Eigen::Vector3d::Zero());
    return out.norm();
}

// Voxels outside the band the tool's grid needs: two past the reach (so the trilinear
// samples just inside the reach are band values), three inside for a mesh (so the cells
// across the surface hold no inside background).
constexpr double kMarginVoxels = 2.0, kInsideVoxels = 3.0;

// The largest slope of the trilinear interpolant, clamped at 0, over the cells that have
// an active corner: in a cell, d/dx is a blend of the four x edges' differences, so
// |grad| <= |(max x-edge, max y-edge, max z-edge)| / h. Cells with no corner above 0 are
// flat after the clamp.
double measureLipschitz(const Grid& grid) {
    openvdb::tree::LeafManager<const Grid::TreeType> leaves(grid.tree());
    const double h = grid.voxelSize()[0];
    return tbb::parallel_reduce(
        leaves.leafRange(), 0.0,
        [&](const openvdb::tree::LeafManager<const Grid::TreeType>::LeafRange& range,
            double worst) {
            ConstAccessor acc(grid.tree());
            for (auto leaf = range.begin(); leaf; ++leaf) {
                for (auto v = leaf->cbeginValueOn(); v; ++v) {
                    const openvdb::Coord ijk = v.getCoord();
                    for (int c = 0; c < 8; ++c) {
                        const openvdb::Coord lo =
                            ijk - openvdb::Coord(c & 1 ? 1 : 0, c & 2 ? 1 : 0, c & 4 ? 1 : 0);
                        float f[8];
                        bool outside = false;
                        for (int k = 0; k < 8; ++k) {
                            f[k] = acc.getValue(lo +
                                                openvdb::Coord(k & 1, (k >> 1) & 1, (k >> 2) & 1));
                            outside = outside || f[k] > 0.0f;
                        }
                        if (!outside) continue;
                        double g[3] = {0.0, 0.0, 0.0};
                        for (int k = 0; k < 8; ++k)
                            for (int axis = 0; axis < 3; ++axis)
                                if (!(k & (1 << axis)))
                                    g[axis] = std::max(g[axis],
                                                       double(std::abs(f[k | (1 << axis)] - f[k])));
                        worst =
                            std::max(worst, std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) / h);
                    }
                }
            }
            return worst;
        },
        [](double a, double b) { return std::max(a, b); });
}

// Box of the inside voxels grown by one voxel (the surface lies within a voxel of one),
// in the grid's world coordinates (the tool's own units).
Box insideBounds(const Grid& grid) {
    openvdb::CoordBBox inside;
    for (auto v = grid.cbeginValueOn(); v; ++v)
        if (*v <= 0.0f) {
            openvdb::CoordBBox b;
            v.getBoundingBox(b);
            inside.expand(b);
        }
    Box box;
    if (inside.empty()) return box;
    inside.expand(1);
    for (int c = 0; c < 8; ++c) {
        const openvdb::Vec3d ijk(c & 1 ? inside.max().x() : inside.min().x(),
                                 c & 2 ? inside.max().y() : inside.min().y(),
                                 c & 4 ? inside.max().z() : inside.min().z());
        box.add(toEigen(grid.transform().indexToWorld(ijk)));
    }
    return box;
}

class PlacedLevelSet : public PlacedShape {
  public:
    PlacedLevelSet(const LevelSetTool& tool, const Eigen::Affine3d& worldFromLocal, double scale)
        : tool_(tool), localFromWorld_(worldFromLocal.inverse()), scale_(scale) {
        for (const Eigen::Vector3d& c : tool.localBounds().corners())
            bounds_.add(worldFromLocal * c);
    }
    double distance(const Eigen::Vector3d& p) const override {
        return scale_ * tool_.localDistance(localFromWorld_ * p);
    }
    double distanceBelow(const Eigen::Vector3d& p, double cutoff) const override {
        const Eigen::Vector3d q = localFromWorld_ * p;
        const double lower = scale_ * boxDistance(tool_.localBounds(), q);
        return lower >= cutoff ? lower : scale_ * tool_.localDistance(q);
    }
    Box bounds() const override { return bounds_; }
    double lipschitz() const override { return tool_.lipschitz(); }
    double exactBelow() const override { return scale_ * tool_.reach(); }

  private:
    LevelSetTool tool_; // a copy: it shares the grid, and placed shapes outlive sweeps
    Eigen::Affine3d localFromWorld_;
    double scale_;
    Box bounds_;
};

} // namespace

LevelSetTool::LevelSetTool(GridPtr grid, std::string name) {
    auto data = std::make_shared<Data>();
    data->bounds = insideBounds(*grid);
    if (data->bounds.empty()) throw std::invalid_argument("the shape has no inside");
    data->reach = double(grid->background()) - kMarginVoxels * grid->voxelSize()[0];
    data->lipschitz = std::max(1.0, measureLipschitz(*grid));
    data->grid = std::move(grid);
    data->name = std::move(name);
    data_ = std::move(data);
}

std::shared_ptr<const LevelSetTool> LevelSetTool::scaled(double factor) const {
    if (!(factor > 0.0) || !std::isfinite(factor))
        throw std::invalid_argument("a tool's scale must be positive and finite");
    return std::shared_ptr<const LevelSetTool>(new LevelSetTool(data_, scale_ * factor));
}

double LevelSetTool::localDistance(const Eigen::Vector3d& q) const {
    const Grid& grid = *data_->grid;
    ConstAccessor acc(grid.tree());
    const double sampled =
        openvdb::tools::BoxSampler::sample(acc, grid.transform().worldToIndex(toVdb(q)));
    return std::max({0.0, sampled, boxDistance(data_->bounds, q)});
}

std::unique_ptr<PlacedShape> LevelSetTool::place(const Eigen::Affine3d& worldFromLocal) const {
    const Eigen::Affine3d X = worldFromLocal * Eigen::Scaling(scale_);
    const Eigen::Matrix3d L = X.linear();
    const double s = std::cbrt(std::abs(L.determinant()));
    if (!(s > 0.0) || !std::isfinite(s))
        throw std::invalid_argument("a tool placement collapses the tool");
    // Distances scale with s only when L / s is a rotation or a mirror.
    if (((L.transpose() * L) / (s * s) - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-9)
        throw std::invalid_argument("a baked tool can only be moved, turned and scaled uniformly");
    return std::make_unique<PlacedLevelSet>(*this, X, s);
}

GridPtr bakeToolGrid(const Grid& levelSet, double reach, Interrupter* interrupter) {
    initVdb();
    // The band is widened by fast marching from the level set's own values near the
    // surface. (OpenVDB's rebuild and mesh conversion fill a wide band by expanding the
    // exact one, and were found up to half a voxel off a sphere's distance two voxels
    // out, which made the sampled distance 1.6 times steeper than a distance.)
    const double h = levelSet.voxelSize()[0], halfWidth = halfWidthOf(levelSet);
    const double width = std::ceil(reach / h) + kMarginVoxels;
    GridPtr g = levelSet.deepCopy();
    if (width > halfWidth) {
        openvdb::tools::changeLevelSetBackground(g->tree(), float(width * h));
        openvdb::MaskGrid::Ptr grown = openvdb::MaskGrid::create();
        grown->tree().topologyUnion(g->tree());
        openvdb::tools::dilateActiveValues(grown->tree(), int(std::ceil(width - halfWidth)),
                                           openvdb::tools::NN_FACE_EDGE_VERTEX,
                                           openvdb::tools::IGNORE_TILES);
        // Only outside: inside, the distance is 0 whatever the depth.
        grown->tree().topologyDifference(g->tree());
        auto acc = g->getAccessor();
        for (auto v = grown->cbeginValueOn(); v; ++v)
            if (acc.getValue(v.getCoord()) > 0.0f) acc.setValueOn(v.getCoord());
        pollInterrupt(interrupter);
        RenormalizeOptions whole;
        whole.interrupter = interrupter;
        renormalize(*g, whole);
    }
    return g;
}

GridPtr bakeToolGrid(const std::vector<Eigen::Vector3f>& vertices,
                     const std::vector<Eigen::Vector3i>& triangles, double voxelSize, double reach,
                     Interrupter* interrupter) {
    return bakeToolGrid(
        *levelSetFromMesh(vertices, triangles, voxelSize, kInsideVoxels, interrupter), reach,
        interrupter);
}

} // namespace sweepers
