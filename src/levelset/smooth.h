// SPDX-License-Identifier: Apache-2.0
// Smoothing under a brush: the level sets relax by mean-curvature flow,
//     d phi / dt = w(x) kappa |grad phi|,   kappa = div(grad phi / |grad phi|),
// for a flow time t, weighted by the brush's falloff w (1 inside the ball, mu of 3.2 across
// the falloff, 0 beyond). Bumps of wavelength l fade like exp(-(2 pi / l)^2 t): fine noise
// goes first, the form under the brush last.
//
// Two schemes give it, a dab running the one that counts less work:
// - the filter: the distance blurred by a Gaussian of standard deviation sqrt(2 t)
//   (levelset/distance_filter.h: a step of Esedoglu, Ruuth and Tsai's diffusion
//   generated motion), each voxel under the brush taking w times the way from its value to
//   the blurred one, then renormalized where values changed, as after a segment. Its work
//   follows the band under the brush, (r/h)^2, whatever t;
// - the explicit flow: steps of the equation above by central differences, stable for
//   dt <= h^2 / 4, so t / dt of them, (r/h)^2 steps of (r/h)^2 voxels. It is the reference
//   the filter is tested against, and what a dab runs where it takes less work than the
//   filter: a short dab of a few steps, whose Gaussian would be about a voxel wide. The
//   ball it reaches is renormalized.
// No value moves more than two voxels in a dab.
//
// Unlike every other stroke this is not a deformation of space: the velocity is the
// surface's own curvature, so it keeps no feature and no exact shape stands behind it.
//
// Written here rather than taken from OpenVDB's LevelSetFilter because that filter visits
// every leaf of the grid at each step (its mask only weights the update) and renormalizes
// the whole band after it: a dab's cost would follow the model. This one visits only the
// band inside the brush's reach (and, for the filter, the band its Gaussian reads around
// it), and renormalizes the ball it reaches.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "levelset/distance_filter.h"
#include "levelset/interrupt.h"
#include "vdb/vdb.h"
#include "vdb/voxel_list.h"

namespace sweepers {

struct SmoothBrush {
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    double radius = 0.25, falloff = 0.25; // world units
    double time = 0.0;                    // flow time (world units squared)
};

// Automatic: the filter where it takes less work than the flow, the flow otherwise; Filter:
// the filter wherever its Gaussian is wide enough (the flow otherwise); ExplicitFlow: the
// flow always. SmoothStats::scheme says which ran.
enum class SmoothScheme { Automatic, Filter, ExplicitFlow };

struct SmoothOptions {
    SmoothScheme scheme = SmoothScheme::Automatic;
};

struct SmoothStats {
    openvdb::CoordBBox changed; // index box of every voxel the dab may have changed
    SmoothScheme scheme = SmoothScheme::ExplicitFlow; // the one that ran
    int steps = 0;                                    // explicit flow steps (0 for the filter)
    int latticeSpacing = 0;                           // the filter's lattice spacing, in voxels
    std::size_t updates = 0;                          // voxel updates, all steps together
    std::size_t weighted = 0; // band voxels under the brush (a weight above 0)
    double mostChange = 0.0;  // of the filter: the largest change of a value (world units)
    // The work checked against the limit, in voxel updates of the explicit flow: the
    // scheme's that ran, and each scheme's (the filter's 0 where its Gaussian would be
    // narrower than DistanceFilter::kSmallestSigma, or the flow was asked for).
    double work = 0.0, flowWork = 0.0, filterWork = 0.0;
    // Wall time of the phases: planning (leaves, weights, the filter's lattice), the update
    // (the filter or the flow, and the band's growth), the renormalization.
    double planSeconds = 0.0, updateSeconds = 0.0, renormalizeSeconds = 0.0;
    std::size_t leaves = 0;        // leaves under the brush
    std::size_t leavesVisited = 0; // leaf places probed (or leaves walked) to find them
};

class CurvatureSmoother {
  public:
    CurvatureSmoother(Grid& grid, const SmoothBrush& brush, Interrupter* interrupter = nullptr,
                      const SmoothOptions& options = {});

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

    // The phases up to the work check: the leaves under the brush, their weights, the
    // filter's lattice, and the work (SmoothStats::work, scheme, weighted). The grid does not
    // change; run() plans first if this was not called.
    const SmoothStats& plan();
    // The dab. Throws LimitExceeded beyond the work limit, before the grid changes; Cancelled
    // when the interrupter stops it (the grid half-changed: the caller restores it).
    SmoothStats run();

  private:
    using Leaf = Grid::TreeType::LeafNodeType;
    // The ball renormalization recomputes: the reach less the voxel the band may take in
    // next to it (in voxels, about the brush's centre).
    double renormalizedRadius() const;
    double stepCount() const; // explicit steps of the flow, at least 1
    // The filter's standard deviation, in voxels: sqrt(2 t) / h.
    double sigmaVoxels() const;
    // The leaves of the grid with a voxel within `radius` voxels of the brush's centre.
    std::vector<Leaf*> leavesIn(double radius);
    bool leafNear(const openvdb::Coord& origin, double radius) const;
    // The brush's weight at a voxel: 1 inside the ball, mu of 3.2 across the falloff.
    float weightAt(const openvdb::Coord& ijk) const;
    void weigh(); // the band voxels with a weight, and the leaves that flow
    // SmoothStats' work (and the filter's plan, reading the band of `around`).
    void estimateWork(const std::vector<Leaf*>& around);
    std::string workDescription() const;
    void widenBand(int layers); // more voxels of band around the voxels that flow
    void flow();                // the explicit steps of the flow
    void filter();              // the filter's splat, blur and update
    void renormalizeReach();

    Grid& grid_;
    SmoothBrush brush_;
    Interrupter* interrupter_;
    SmoothOptions options_;
    openvdb::CoordBBox reach_;
    openvdb::Vec3d centre_; // the brush's centre, in index space
    std::vector<Leaf*> leaves_;
    // The leaves that flow (index into leaves_), and the voxels with a weight of each.
    std::vector<std::size_t> flowing_;
    VoxelList weighted_;
    VoxelList changed_, fresh_; // what the filter changed, and the voxels the band grew by
    std::unique_ptr<DistanceFilter> filter_;
    SmoothStats stats_;
    bool planned_ = false;
};

// One dab: CurvatureSmoother(grid, brush, interrupter).run().
SmoothStats smoothLevelSet(Grid& grid, const SmoothBrush& brush, Interrupter* interrupter = nullptr,
                           const SmoothOptions& options = {});

// The flow time of a dab of strength s with a brush of this radius: s times
// kSmoothTimePerRadius2 times the radius squared, so that a dab smooths the same shape alike
// at every voxel size and brush size (bumps a fifth of the radius long fade by e^-5).
inline constexpr double kSmoothTimePerRadius2 = 0.005;

} // namespace sweepers
