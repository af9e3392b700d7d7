// SPDX-License-Identifier: Apache-2.0
#include <random>

#include <gtest/gtest.h>
#include <openvdb/tools/Morphology.h>

#include "levelset/dilate.h"

using namespace sweepers;

namespace {

// Scattered voxels and a few solid blocks, across leaf and internal-node boundaries and on
// both sides of the origin.
openvdb::MaskTree::Ptr randomMask(unsigned seed) {
    std::mt19937 gen(seed);
    std::uniform_int_distribution<int> coord(-70, 70), size(1, 12);
    auto tree = std::make_shared<openvdb::MaskTree>();
    for (int i = 0; i < 300; ++i)
        tree->setValueOn(openvdb::Coord(coord(gen), coord(gen), coord(gen)));
    for (int i = 0; i < 5; ++i) {
        const openvdb::Coord lo(coord(gen), coord(gen), coord(gen));
        for (int x = 0, s = size(gen); x < s; ++x)
            for (int y = 0; y < s; ++y)
                for (int z = 0; z < s; ++z)
                    tree->setValueOn(lo.offsetBy(x, y, z));
    }
    return tree;
}

// The list dilated, as a tree.
openvdb::MaskTree::Ptr dilated(const VoxelList& list, int radius) {
    auto tree = std::make_shared<openvdb::MaskTree>();
    uniteMasks(*tree, dilatedByCube(list, radius));
    return tree;
}

// OpenVDB's dilation of the mask by `radius` rounds over all 26 neighbours.
openvdb::MaskTree::Ptr expectedDilation(const openvdb::MaskTree& mask, int radius) {
    auto expected = std::make_shared<openvdb::MaskTree>(mask);
    if (radius > 0)
        openvdb::tools::dilateActiveValues(*expected, radius, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                           openvdb::tools::IGNORE_TILES);
    return expected;
}

} // namespace

TEST(DilateByCube, EqualsRepeatedTwentySixNeighbourDilation) {
    for (unsigned seed = 1; seed <= 3; ++seed)
        for (int radius : {0, 1, 2, 3, 4, 5, 7, 8, 9, 13}) {
            const auto mask = randomMask(seed);
            const auto expected = expectedDilation(*mask, radius);
            const auto got = dilated(listLeaves(*mask), radius);
            EXPECT_EQ(got->activeVoxelCount(), expected->activeVoxelCount())
                << "seed " << seed << " radius " << radius;
            EXPECT_TRUE(got->hasSameTopology(*expected)) << "seed " << seed << " radius " << radius;
        }
}

// Clusters far apart: one box of leaves around all of them would hold some 10^12 slots, so
// the set is split until each part's box is dense enough; the cube distributes over the
// union, and the list holds each leaf once though the parts dilated apart reach some leaves
// both.
TEST(DilateByCube, FarApartClustersAreDilatedEachInItsOwnBox) {
    const auto mask = randomMask(4);
    for (const openvdb::Coord shift :
         {openvdb::Coord(100000, 0, 0), openvdb::Coord(0, -90000, 40000), openvdb::Coord(3000)}) {
        const auto far = randomMask(5 + unsigned(shift.x() & 7));
        for (auto it = far->cbeginValueOn(); it; ++it)
            mask->setValueOn(it.getCoord() + shift);
    }
    for (int radius : {3, 11}) {
        const auto expected = expectedDilation(*mask, radius);
        const VoxelList list = dilatedByCube(listLeaves(*mask), radius);
        openvdb::MaskTree got;
        uniteMasks(got, list);
        EXPECT_EQ(got.activeVoxelCount(), expected->activeVoxelCount()) << radius;
        EXPECT_TRUE(got.hasSameTopology(*expected)) << radius;
        EXPECT_EQ(list.size(), expected->leafCount()) << radius;
    }
}

TEST(DilateByCube, RefusesANegativeRadius) {
    openvdb::MaskTree tree;
    tree.setValueOn(openvdb::Coord(0));
    EXPECT_THROW(dilatedByCube(listLeaves(tree), -1), std::invalid_argument);
}

// A leaf listed twice, its voxels split between the entries, dilates as when listed once,
// and comes out once.
TEST(DilateByCube, ALeafListedTwiceIsDilatedOnce) {
    for (int radius : {0, 1, 4, 9}) {
        const auto mask = randomMask(21);
        const auto expected = expectedDilation(*mask, radius);
        VoxelList twice;
        for (const LeafVoxels& leaf : listLeaves(*mask)) {
            twice.push_back(leaf);
            if (twice.size() % 3 != 0) continue;
            LeafVoxels half = leaf; // the first entry keeps the even words, this the odd
            for (std::size_t x = 0; x < 8; x += 2) {
                twice.back().words[x + 1] = 0;
                half.words[x] = 0;
            }
            twice.push_back(half);
        }
        const VoxelList list = dilatedByCube(twice, radius);
        openvdb::MaskTree got;
        uniteMasks(got, list);
        EXPECT_EQ(got.activeVoxelCount(), expected->activeVoxelCount()) << radius;
        EXPECT_TRUE(got.hasSameTopology(*expected)) << radius;
        EXPECT_EQ(list.size(), got.leafCount()) << radius;
    }
}

// A list's voxels join those of a tree; a leaf without voxels adds none.
TEST(UniteMasks, AListAddsItsVoxels) {
    const auto into = randomMask(31), from = randomMask(32);
    from->touchLeaf(openvdb::Coord(200, 200, 200)); // a leaf with no voxel on
    auto expected = std::make_shared<openvdb::MaskTree>(*into);
    expected->topologyUnion(*from);
    uniteMasks(*into, listLeaves(*from));
    EXPECT_EQ(into->activeVoxelCount(), expected->activeVoxelCount());
    for (auto it = expected->cbeginValueOn(); it; ++it)
        ASSERT_TRUE(into->isValueOn(it.getCoord())) << it.getCoord();
    EXPECT_FALSE(into->probeConstLeaf(openvdb::Coord(200, 200, 200))); // nothing to add
}

// Two lists sharing some leaves, put end to end: each leaf once holds every voxel of both.
TEST(UniteMasks, EachLeafOnceKeepsEveryVoxel) {
    const auto a = randomMask(41), b = randomMask(42);
    VoxelList both = listLeaves(*a);
    const VoxelList more = listLeaves(*b);
    both.insert(both.end(), more.begin(), more.end());
    const VoxelList once = eachLeafOnce(both);
    auto expected = std::make_shared<openvdb::MaskTree>(*a);
    expected->topologyUnion(*b);
    EXPECT_EQ(once.size(), expected->leafCount());
    openvdb::MaskTree tree;
    uniteMasks(tree, once);
    EXPECT_TRUE(tree.hasSameTopology(*expected));
    EXPECT_EQ(tree.activeVoxelCount(), expected->activeVoxelCount());
}
