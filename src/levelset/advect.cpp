#include "levelset/advect.h"
#include "levelset/level_set.h"
#include "levelset/monotone_cubic.h"

#include <chrono>
#include <cmath>
#include <mutex>
#include <vector>

#include <Eigen/SVD>
#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace sweepers {

namespace {

using Clock = std::chrono::steady_clock;

// The stretch of the inverse map varies smoothly along the surface: measuring it at one
// interface voxel in four finds its maximum to within the margin the widening adds.
constexpr std::size_t kStretchSampling = 4;
double since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

// Resamples every active voxel of `grid` inside `box` from `source` at map(x), and marks in
// `changed` the voxels whose value changed (where the deformation is the identity, a sample
// at a voxel centre returns its value exactly).
template <typename Map>
std::size_t resample(Grid& grid, const Grid& source, const openvdb::CoordBBox& box, const Map& map,
                     Sampling sampling, openvdb::MaskGrid& changed, Interrupter* interrupter) {
    tbb::enumerable_thread_specific<std::vector<openvdb::Coord>> marks;
    openvdb::tree::LeafManager<Grid::TreeType> leaves(grid.tree());
    std::atomic<std::size_t> count{0};
    const auto& xform = grid.transform();
    tbb::parallel_for(leaves.leafRange(), [&](const auto& range) {
        Grid::ConstAccessor acc = source.getConstAccessor();
        openvdb::tools::GridSampler<Grid::ConstAccessor, openvdb::tools::BoxSampler> trilinear(
            acc, source.transform());
        std::size_t n = 0;
        pollInterrupt(interrupter);
        for (auto leaf = range.begin(); leaf; ++leaf) {
            if (!box.hasOverlap(leaf->getNodeBoundingBox())) continue;
            for (auto it = leaf->beginValueOn(); it; ++it) {
                const openvdb::Coord ijk = it.getCoord();
                if (!box.isInside(ijk)) continue;
                const openvdb::Vec3d p = toVdb(map(toEigen(xform.indexToWorld(ijk))));
                const float v = float(sampling == Sampling::Trilinear
                                          ? trilinear.wsSample(p)
                                          : sampleMonotoneCubic(acc, source.worldToIndex(p)));
                if (v != *it || !acc.isValueOn(ijk)) marks.local().push_back(ijk);
                it.setValue(v);
                ++n;
            }
        }
        count += n;
    });
    auto macc = changed.getAccessor();
    for (const auto& m : marks)
        for (const openvdb::Coord& c : m)
            macc.setValueOn(c);
    return count;
}

} // namespace

openvdb::CoordBBox changedRegion(const Grid& grid, const StepDeformation& seg) {
    // The sampled region, and the band activated around images of the interface (which
    // stay inside the affected box: the deformation maps it onto itself).
    openvdb::CoordBBox box = indexBox(grid, seg.affectedBox(), 1);
    box.expand(int(std::ceil(halfWidthOf(grid))) + 1);
    return box;
}

openvdb::CoordBBox indexBox(const Grid& grid, const Box& world, int pad) {
    if (world.empty()) return {};
    const openvdb::Vec3d lo = grid.worldToIndex(toVdb(world.min));
    const openvdb::Vec3d hi = grid.worldToIndex(toVdb(world.max));
    return openvdb::CoordBBox(openvdb::Coord::floor(lo).offsetBy(-pad),
                              openvdb::Coord::ceil(hi).offsetBy(pad));
}

AdvectStats advectSegment(Grid& grid, const StepDeformation& seg, const AdvectOptions& options) {
    AdvectStats stats;
    stats.subSteps = seg.steps();
    const double h = grid.voxelSize()[0];
    const double halfWidth = halfWidthOf(grid);
    const openvdb::CoordBBox region = indexBox(grid, seg.affectedBox(), 1);
    // The images only pick voxels to activate: a hundredth of a voxel is plenty.
    const double forwardTolerance = 0.01 * h / (1.0 + seg.affectedBox().max.cwiseAbs().maxCoeff());

    // 1. Grow the band: forward-map the interface voxels, one sub-step at a time, and mark
    //    every image; also measure how far apart the images of neighbouring voxels land
    //    (the stretch), which bounds how far a pre-image can sit from the old surface.
    auto t0 = Clock::now();
    std::vector<openvdb::Coord> interface;
    {
        auto acc = grid.getConstAccessor();
        for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
            if (!region.hasOverlap(leaf->getNodeBoundingBox())) continue;
            for (auto it = leaf->cbeginValueOn(); it; ++it) {
                const openvdb::Coord ijk = it.getCoord();
                if (region.isInside(ijk) && nextToCrossing(acc, ijk, *it)) interface.push_back(ijk);
            }
        }
    }
    stats.interfaceVoxels = interface.size();
    using Marks = std::vector<openvdb::Coord>;
    tbb::enumerable_thread_specific<Marks> marks;
    tbb::enumerable_thread_specific<double> stretch(1.0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, interface.size(), 64), [&](const auto& r) {
        pollInterrupt(options.interrupter);
        Marks& m = marks.local();
        double& worst = stretch.local();
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            Eigen::Vector3d p = toEigen(grid.indexToWorld(interface[i]));
            for (int k = 0; k < seg.steps(); ++k) {
                p = seg.forwardStep(k, p, forwardTolerance).p;
                // Intermediate surfaces only need a band when they are stored.
                if (options.resampleEachSubStep || k + 1 == seg.steps())
                    m.push_back(openvdb::Coord::round(grid.worldToIndex(toVdb(p))));
            }
            if (i % kStretchSampling != 0) continue;
            // How far the inverse map can spread a voxel-sized neighbourhood of the new
            // surface: the largest singular value of its Jacobian.
            Eigen::Matrix3d J;
            for (int a = 0; a < 3; ++a) {
                Eigen::Vector3d e = Eigen::Vector3d::Zero();
                e[a] = 0.5 * h;
                J.col(a) = (seg.inverseMap(p + e) - seg.inverseMap(p - e)) / h;
            }
            worst = std::max(worst, Eigen::JacobiSVD<Eigen::Matrix3d>(J).singularValues()[0]);
        }
    });
    openvdb::MaskGrid::Ptr mask = openvdb::MaskGrid::create();
    mask->setTransform(grid.transform().copy());
    {
        auto macc = mask->getAccessor();
        for (const Marks& m : marks)
            for (const openvdb::Coord& c : m)
                macc.setValueOn(c);
    }
    const int dilation = int(std::ceil(halfWidth)) + 1;
    openvdb::tools::dilateActiveValues(mask->tree(), dilation, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::IGNORE_TILES);
    double maxStretch = 1.0;
    for (double s : stretch)
        maxStretch = std::max(maxStretch, s);
    // The voxels the renormalization seeds from lie within 1.5 voxels of the new surface
    // (crossing ends and their central differences); their pre-images lie within
    // 1.5 * stretch voxels of the old one, and trilinear sampling reads one voxel beyond.
    // Make sure the old band reaches that far, so none of them reads a clamped value.
    const double needed = std::ceil(1.5 * std::min(maxStretch, 32.0) + 1.0);
    stats.widenedTo = std::max(halfWidth, needed);
    GridPtr source;
    if (needed > halfWidth) {
        // Only the affected box is sampled, so the band is widened there alone: its active
        // voxels are dilated in a mask and merged into a copy of the grid, whose inactive
        // values (now +-needed voxels) carry the signs; fast marching fills in distances.
        const openvdb::CoordBBox box = indexBox(grid, seg.affectedBox(), int(needed) + 3);
        source = grid.deepCopy();
        openvdb::tools::changeLevelSetBackground(source->tree(), float(needed * h));
        openvdb::MaskGrid::Ptr widen = openvdb::MaskGrid::create();
        for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
            if (!box.hasOverlap(leaf->getNodeBoundingBox())) continue;
            widen->tree().touchLeaf(leaf->origin())->topologyUnion(*leaf);
        }
        openvdb::tools::dilateActiveValues(widen->tree(), int(std::ceil(needed - halfWidth)),
                                           openvdb::tools::NN_FACE, openvdb::tools::IGNORE_TILES);
        source->tree().topologyUnion(widen->tree());
        renormalize(*source, indexBox(grid, seg.affectedBox(), int(needed) + 1), FmmOrder::First,
                    options.interrupter);
    }
    // Voxels the band grows into: renormalized (or dropped again) wherever they are.
    openvdb::MaskGrid::Ptr fresh = mask->deepCopy();
    fresh->tree().topologyDifference(grid.tree());
    grid.tree().topologyUnion(mask->tree());
    stats.growSeconds = since(t0);

    // 2. Sample: composed inverse (default) or one resample per sub-step (5.3.4).
    t0 = Clock::now();
    const openvdb::MaskGrid::Ptr changed = openvdb::MaskGrid::create();
    if (!options.resampleEachSubStep) {
        if (!source) source = grid.deepCopy();
        stats.sampledVoxels = resample(
            grid, *source, region, [&](const Eigen::Vector3d& x) { return seg.inverseMap(x); },
            options.sampling, *changed, options.interrupter);
    } else {
        for (int k = 0; k < seg.steps(); ++k) {
            GridPtr step = (k == 0 && source) ? source : grid.deepCopy();
            stats.sampledVoxels += resample(
                grid, *step, region,
                [&](const Eigen::Vector3d& x) { return seg.inverseStep(k, x); }, options.sampling,
                *changed, options.interrupter);
        }
    }
    // Voxels inside the region that are not in the band kept their old inactive values,
    // whose signs may now be wrong (space pulled out of the shape is inside it now):
    // re-derive every inactive sign from the band.
    openvdb::tools::signedFloodFill(grid.tree());
    stats.sampleSeconds = since(t0);

    // 3. Renormalize the changed region (and the band around it).
    t0 = Clock::now();
    const openvdb::CoordBBox touched = changedRegion(grid, seg);
    if (options.renormalize) {
        // Only where values changed, and as far as the band reaches from there (the nearest
        // surface of a voxel nearby may have moved): where the deformation is the identity
        // (outside the tools' coatings, which fill only part of the box) the distances hold.
        openvdb::tools::dilateActiveValues(changed->tree(), int(std::ceil(halfWidth)) + 1,
                                           openvdb::tools::NN_FACE_EDGE_VERTEX,
                                           openvdb::tools::IGNORE_TILES);
        changed->tree().topologyUnion(fresh->tree());
        renormalize(grid, touched, *changed, options.renormalization, options.interrupter);
    }
    stats.renormalizeSeconds = since(t0);
    stats.touched = touched;
    return stats;
}

} // namespace sweepers
