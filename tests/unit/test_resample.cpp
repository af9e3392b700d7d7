// SPDX-License-Identifier: Apache-2.0
// levelset/resample.h: a sampling pass reads the source at the pre-images the plan's map
// gives, writes the grid or the staged values, and lists what changed and what moved.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "grids.h"
#include "levelset/create.h"
#include "levelset/resample.h"
#include "vdb/local_tree.h"

using namespace sweepers;
using sweepers::test::differingBits;

namespace {

constexpr double kH = 1.0 / 32; // a power of two: voxel centres and one-voxel moves are exact

// Every leaf of the band.
std::vector<LeafNode*> leavesOf(Grid& g) {
    return leavesIn(g.tree(), g.evalActiveVoxelBoundingBox());
}

GridPtr ball() {
    return makeSphere(Eigen::Vector3d::Zero(), 0.4, kH, 3.0);
}

LeafMap shiftedBy(const Eigen::Vector3d& d) {
    return [d](const Eigen::Vector3d* x, std::size_t n, Eigen::Vector3d* y, MapScratch&) {
        for (std::size_t i = 0; i < n; ++i)
            y[i] = x[i] - d;
    };
}

std::size_t voxelsListed(const VoxelList& list) {
    std::size_t n = 0;
    for (const LeafVoxels& leaf : list)
        for (const leafwords::Word w : leaf.words)
            n += std::size_t(__builtin_popcountll(w));
    return n;
}

// A dense block of voxels holding a quadratic field, within the reach of the correction
// everywhere (below 2.5 voxels): f = h (0.005 (u - 8)^2 + 0.008 (v - 8)^2 + 0.01 (v - 8)(w - 8)
// + 0.05 u - 0.5) at index (u, v, w).
double quadratic(const Eigen::Vector3d& index) {
    const Eigen::Vector3d c = index - Eigen::Vector3d(8, 8, 8);
    return kH * (0.005 * c.x() * c.x() + 0.008 * c.y() * c.y() + 0.01 * c.y() * c.z() +
                 0.05 * index.x() - 0.5);
}

GridPtr quadraticBlock() {
    GridPtr g = Grid::create(float(3 * kH));
    g->setTransform(documentTransform(kH));
    auto acc = g->getAccessor();
    for (auto it = openvdb::CoordBBox::createCube({0, 0, 0}, 16).begin(); it; ++it)
        acc.setValueOn(*it, float(quadratic(toEigen((*it).asVec3d()))));
    return g;
}

} // namespace

// The identity read from copies of the leaves (not the grid itself, so every voxel is
// interpolated): each sample lands on a voxel centre and gives its value back, to the bit,
// and nothing is listed as changed.
TEST(Resample, TheIdentityGivesEveryValueBack) {
    for (const Sampling sampling : {Sampling::Trilinear, Sampling::Corrected}) {
        const GridPtr g = ball(), before = g->deepCopy();
        const std::vector<LeafNode*> leaves = leavesOf(*g);
        const auto source = SampleSource::copyOnWrite(*g, leaves);
        ResamplePlan plan;
        plan.box = g->evalActiveVoxelBoundingBox();
        plan.map = shiftedBy(Eigen::Vector3d::Zero());
        plan.sampling = sampling;
        VoxelList changed, moved;
        ResampleOutput out;
        out.changed = &changed;
        out.moved = &moved;
        const std::size_t n = Resampler().run(*g, leaves, *source, plan, out);
        EXPECT_EQ(n, g->activeVoxelCount());
        EXPECT_EQ(differingBits(*g, *before), 0u);
        EXPECT_TRUE(changed.empty());
        EXPECT_TRUE(moved.empty());
    }
}

// A move of one voxel along x: every voxel takes the value of its neighbour at x - 1, to the
// bit; `changed` lists exactly the voxels whose value differs from that neighbour's, `moved`
// those that differ by more than the nudge. Staged, the grid keeps its values until they are
// swapped in, and then holds what writing the grid directly gives.
TEST(Resample, AOneVoxelMoveReadsTheNeighbourAndListsWhatChanged) {
    const GridPtr start = ball();
    const float nudge = float(0.5 * kH);
    GridPtr direct = start->deepCopy();
    std::size_t expectChanged = 0, expectMoved = 0;
    {
        const auto acc = start->getConstAccessor();
        for (auto it = start->cbeginValueOn(); it; ++it) {
            const float from = acc.getValue(it.getCoord().offsetBy(-1, 0, 0));
            expectChanged += from != *it;
            expectMoved += std::abs(from - *it) > nudge;
        }
    }
    ResamplePlan plan;
    plan.box = start->evalActiveVoxelBoundingBox();
    plan.map = shiftedBy(Eigen::Vector3d(kH, 0, 0));
    VoxelList changed, moved;
    ResampleOutput out;
    out.changed = &changed;
    out.moved = &moved;
    out.nudge = nudge;
    {
        const std::vector<LeafNode*> leaves = leavesOf(*direct);
        const auto source = SampleSource::copyOnWrite(*direct, leaves);
        Resampler().run(*direct, leaves, *source, plan, out);
    }
    const auto before = start->getConstAccessor(), after = direct->getConstAccessor();
    std::size_t differ = 0;
    for (auto it = start->cbeginValueOn(); it; ++it)
        differ +=
            after.getValue(it.getCoord()) != before.getValue(it.getCoord().offsetBy(-1, 0, 0));
    EXPECT_EQ(differ, 0u);
    EXPECT_GT(expectMoved, 1000u);
    EXPECT_LT(expectMoved, expectChanged);
    EXPECT_EQ(voxelsListed(changed), expectChanged);
    EXPECT_EQ(voxelsListed(moved), expectMoved);

    GridPtr staged = start->deepCopy();
    const std::vector<LeafNode*> leaves = leavesOf(*staged);
    Staged values;
    std::atomic<std::size_t> growths{0};
    values.reserve(leaves.size(), growths);
    changed.clear();
    moved.clear();
    out.staged = &values;
    Resampler().run(*staged, leaves, *SampleSource::live(*staged), plan, out);
    EXPECT_EQ(differingBits(*staged, *start), 0u);
    values.swapInto(leaves);
    EXPECT_EQ(differingBits(*staged, *direct), 0u);
    EXPECT_EQ(growths, 1u);
}

// Corrected sampling reads a quadratic field exactly between the voxels; trilinear sampling
// reads it high by half its second differences times t (1 - t) along each axis.
TEST(Resample, CorrectedSamplingReadsAQuadraticFieldExactly) {
    const Eigen::Vector3d shift(0.3, 0.6, 0.2); // in voxels
    for (const Sampling sampling : {Sampling::Trilinear, Sampling::Corrected}) {
        const GridPtr g = quadraticBlock();
        const std::vector<LeafNode*> leaves = leavesOf(*g);
        const auto source = SampleSource::copyOnWrite(*g, leaves);
        ResamplePlan plan;
        plan.box = openvdb::CoordBBox({2, 2, 2}, {13, 13, 13}); // a voxel inside the block
        plan.map = shiftedBy(shift * kH);
        plan.sampling = sampling;
        VoxelList changed, moved;
        ResampleOutput out;
        out.changed = &changed;
        out.moved = &moved;
        EXPECT_EQ(Resampler().run(*g, leaves, *source, plan, out), 12u * 12u * 12u);
        double worst = 0.0;
        const auto acc = g->getConstAccessor();
        for (auto it = plan.box.begin(); it; ++it)
            worst = std::max(
                worst,
                std::abs(acc.getValue(*it) - quadratic(toEigen((*it).asVec3d()) - shift)) / kH);
        if (sampling == Sampling::Corrected) {
            EXPECT_LT(worst, 1e-5) << "voxels";
        } else {
            // 0.5 (0.21 * 0.01 + 0.24 * 0.016) voxels where the cross term is bilinear.
            EXPECT_NEAR(worst, 0.00297, 1e-4) << "voxels";
        }
    }
}
