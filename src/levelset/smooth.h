// Smoothing under a brush: the level sets relax by mean-curvature flow,
//     d phi / dt = w(x) kappa |grad phi|,   kappa = div(grad phi / |grad phi|),
// weighted by the brush's falloff w (1 inside the ball, mu of 3.2 across the falloff, 0
// beyond), then the touched box is renormalized. Bumps of wavelength l fade like
// exp(-(2 pi / l)^2 t): fine noise goes first, the form under the brush last.
//
// Unlike every other stroke this is not a deformation of space: the velocity is the
// surface's own curvature, so it keeps no feature and no exact shape stands behind it.
//
// Written here rather than taken from OpenVDB's LevelSetFilter::meanCurvature because
// that filter visits every leaf of the grid at each step (its mask only weights the
// update) and renormalizes the whole band after it: a dab's cost would follow the model.
// This one visits only the band inside the brush's reach, and renormalizes the ball it
// reaches.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "levelset/interrupt.h"
#include "levelset/vdb.h"
#include "levelset/voxel_list.h"

namespace sweepers {

struct SmoothBrush {
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    double radius = 0.25, falloff = 0.25; // world units
    double time = 0.0;                    // flow time (world units squared)
};

struct SmoothStats {
    openvdb::CoordBBox changed;    // index box of every voxel the dab may have changed
    int steps = 0;                 // explicit flow steps
    std::size_t updates = 0;       // voxel updates, all steps together
    std::size_t leaves = 0;        // leaves under the brush
    std::size_t leavesVisited = 0; // leaf places probed (or leaves walked) to find them
};

class CurvatureSmoother {
  public:
    CurvatureSmoother(Grid& grid, const SmoothBrush& brush, Interrupter* interrupter = nullptr);

    // How far from the brush's centre a dab may change a voxel: its ball and falloff, the
    // band around them and a voxel (which renormalization rebuilds), and the voxel next to
    // those that the rebuilt band may take in.
    double reachRadius() const {
        return brush_.radius + brush_.falloff + double(grid_.background()) +
               2.0 * grid_.voxelSize()[0];
    }
    // An index box holding that ball and the voxels the differences read: what undo records
    // before a dab and the mesher updates after it.
    openvdb::CoordBBox reach() const { return reach_; }

    SmoothStats run();

  private:
    // The ball renormalization recomputes: the reach less the voxel the band may take in
    // next to it (in voxels, about the brush's centre).
    double renormalizedRadius() const;
    double stepCount() const; // explicit steps of the flow, at least 1
    void collectLeaves();     // the leaves of the band inside the reach
    void weigh();             // the brush's weight at each band voxel, and the leaves that flow
    void requireAffordable() const; // throws LimitExceeded beyond the work limit
    void widenBand();               // two more voxels of band around the voxels that flow
    void flow();                    // the explicit steps of the flow
    void renormalizeReach();

    using Leaf = Grid::TreeType::LeafNodeType;
    Grid& grid_;
    SmoothBrush brush_;
    Interrupter* interrupter_;
    openvdb::CoordBBox reach_;
    std::vector<Leaf*> leaves_;
    // Of the leaves that flow (index into leaves_): the weights, and the voxels with one.
    std::vector<std::size_t> flowing_;
    std::vector<std::array<float, Leaf::SIZE>> weight_;
    VoxelList weighted_;
    SmoothStats stats_;
};

// One dab: CurvatureSmoother(grid, brush, interrupter).run().
SmoothStats smoothLevelSet(Grid& grid, const SmoothBrush& brush,
                           Interrupter* interrupter = nullptr);

// The flow time of a dab of strength s with a brush of this radius: s times
// kSmoothTimePerRadius2 times the radius squared, so that a dab smooths the same shape alike
// at every voxel size and brush size (bumps a fifth of the radius long fade by e^-5).
inline constexpr double kSmoothTimePerRadius2 = 0.005;

} // namespace sweepers
