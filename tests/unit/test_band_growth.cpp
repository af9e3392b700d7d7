// SPDX-License-Identifier: Apache-2.0
// levelset/band_growth.h: the leaves the band's outer voxels need, and whether sampling reached
// every voxel renormalization reads.
#include <algorithm>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>
#include <openvdb/tools/Morphology.h>

#include "levelset/band_growth.h"
#include "levelset/create.h"
#include "levelset/dilate.h"
#include "vdb/local_tree.h"

using namespace sweepers;

namespace {

std::set<openvdb::Coord> leafOrigins(const Grid& g) {
    std::set<openvdb::Coord> origins;
    for (auto leaf = g.tree().cbeginLeaf(); leaf; ++leaf)
        origins.insert(leaf->origin());
    return origins;
}

} // namespace

// The leaves made are those a dilation of the mask by the cube makes, where they overlap the
// box: random voxel sets, reaches from 1 to 3 voxels, a box that cuts some leaves off.
TEST(BandGrowth, TheLeavesMadeAreThoseTheCubeDilationReaches) {
    std::mt19937 random(7);
    std::uniform_int_distribution<int> at(-40, 40), count(1, 30);
    const openvdb::CoordBBox box({-32, -48, -40}, {40, 24, 48});
    for (int trial = 0; trial < 60; ++trial) {
        openvdb::MaskTree marked;
        for (int n = count(random); n > 0; --n)
            marked.setValueOn(openvdb::Coord(at(random), at(random), at(random)));
        const VoxelList mask = listLeaves(marked);
        const int beyond = 1 + trial % 3;
        GridPtr g = Grid::create(0.1f);
        makeLeavesWithin(*g, mask, beyond, box);

        openvdb::MaskTree dilated(marked);
        openvdb::tools::dilateActiveValues(dilated, beyond, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                           openvdb::tools::IGNORE_TILES);
        std::set<openvdb::Coord> expected;
        for (auto leaf = dilated.cbeginLeaf(); leaf; ++leaf)
            if (box.hasOverlap(leaf->getNodeBoundingBox())) expected.insert(leaf->origin());
        ASSERT_EQ(leafOrigins(*g), expected) << "trial " << trial << ", reach " << beyond;
    }
}

// On a sphere's band, sampling reached everything; with one voxel next to the crossing
// switched off (or one of its face neighbours), it did not, and the voxels missing are listed:
// that voxel, and its inactive face neighbours within the box.
TEST(BandGrowth, AVoxelNextToTheCrossingLeftOffIsFoundMissing) {
    const GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 0.4, 1.0 / 32, 3.0);
    const openvdb::CoordBBox box = g->evalActiveVoxelBoundingBox();
    const auto leaves = [&] { return leavesIn(g->tree(), box); };
    EXPECT_TRUE(seedsSampled(*g, leaves(), box));
    EXPECT_TRUE(unsampledSeeds(*g, leaves(), box).empty());

    // The voxel on the +x axis just inside the surface (0.4 = 12.8 voxels: index 12 at 12.5).
    const openvdb::Coord seed(12, 0, 0);
    auto acc = g->getAccessor();
    ASSERT_LT(acc.getValue(seed), 0.0f);
    ASSERT_GT(acc.getValue(seed.offsetBy(1, 0, 0)), 0.0f);
    acc.setValueOff(seed);
    EXPECT_FALSE(seedsSampled(*g, leaves(), box));
    const VoxelList missing = unsampledSeeds(*g, leaves(), box);
    std::set<openvdb::Coord> listed;
    for (const LeafVoxels& leaf : missing)
        for (int pos = 0; pos < 512; ++pos)
            if (leaf.words[std::size_t(pos >> 6)] >> (pos & 63) & 1)
                listed.insert(leaf.origin + LeafNode::offsetToLocalCoord(openvdb::Index(pos)));
    EXPECT_EQ(listed, std::set<openvdb::Coord>{seed});

    // Outside the box, the same voxel is not looked at.
    const openvdb::CoordBBox without({-20, -20, -20}, {11, 20, 20});
    EXPECT_TRUE(unsampledSeeds(*g, leaves(), without).empty());
}
