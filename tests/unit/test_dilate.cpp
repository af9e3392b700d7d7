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

} // namespace

TEST(DilateByCube, EqualsRepeatedTwentySixNeighbourDilation) {
    for (unsigned seed = 1; seed <= 3; ++seed)
        for (int radius : {0, 1, 2, 3, 4, 5, 7, 8, 9, 13}) {
            const auto mask = randomMask(seed);
            auto expected = std::make_shared<openvdb::MaskTree>(*mask);
            if (radius > 0)
                openvdb::tools::dilateActiveValues(*expected, radius,
                                                   openvdb::tools::NN_FACE_EDGE_VERTEX,
                                                   openvdb::tools::IGNORE_TILES);
            dilateByCube(*mask, radius);
            EXPECT_EQ(mask->activeVoxelCount(), expected->activeVoxelCount())
                << "seed " << seed << " radius " << radius;
            EXPECT_TRUE(mask->hasSameTopology(*expected))
                << "seed " << seed << " radius " << radius;
        }
}

// Clusters far apart: one box of leaves around all of them would hold some 10^12 slots, so
// the mask is split until each part's box is dense enough; the cube distributes over the
// union.
TEST(DilateByCube, FarApartClustersAreDilatedEachInItsOwnBox) {
    const auto mask = randomMask(4);
    for (const openvdb::Coord shift :
         {openvdb::Coord(100000, 0, 0), openvdb::Coord(0, -90000, 40000), openvdb::Coord(3000)}) {
        const auto far = randomMask(5 + unsigned(shift.x() & 7));
        for (auto it = far->cbeginValueOn(); it; ++it)
            mask->setValueOn(it.getCoord() + shift);
    }
    for (int radius : {3, 11}) {
        auto dilated = std::make_shared<openvdb::MaskTree>(*mask);
        auto expected = std::make_shared<openvdb::MaskTree>(*mask);
        openvdb::tools::dilateActiveValues(*expected, radius, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                           openvdb::tools::IGNORE_TILES);
        dilateByCube(*dilated, radius);
        EXPECT_EQ(dilated->activeVoxelCount(), expected->activeVoxelCount()) << radius;
        EXPECT_TRUE(dilated->hasSameTopology(*expected)) << radius;
    }
}

TEST(DilateByCube, RefusesANegativeRadius) {
    openvdb::MaskTree tree;
    tree.setValueOn(openvdb::Coord(0));
    EXPECT_THROW(dilateByCube(tree, -1), std::invalid_argument);
}

// The union a leaf at a time gives OpenVDB's union: masks overlapping in some leaves and not
// in others, an empty leaf in the added mask (which adds no voxel), and a mask holding an
// active tile (which takes OpenVDB's union).
TEST(UniteMasks, EqualsOpenVdbTopologyUnion) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
        const auto into = randomMask(seed), from = randomMask(seed + 10);
        from->touchLeaf(openvdb::Coord(200, 200, 200)); // a leaf with no voxel on
        auto expected = std::make_shared<openvdb::MaskTree>(*into);
        expected->topologyUnion(*from);
        uniteMasks(*into, *from);
        EXPECT_EQ(into->activeVoxelCount(), expected->activeVoxelCount()) << seed;
        for (auto it = expected->cbeginValueOn(); it; ++it)
            ASSERT_TRUE(into->isValueOn(it.getCoord())) << seed << " " << it.getCoord();
    }
    const auto into = randomMask(7);
    openvdb::MaskTree tiled;
    tiled.addTile(1, openvdb::Coord(-64, 0, 0), true, true); // a tile of 8^3 voxels
    auto expected = std::make_shared<openvdb::MaskTree>(*into);
    expected->topologyUnion(tiled);
    uniteMasks(*into, tiled);
    EXPECT_TRUE(into->isValueOn(openvdb::Coord(-60, 3, 5)));
    EXPECT_EQ(into->activeVoxelCount(), expected->activeVoxelCount());
}

namespace {

// The mask as a list of its leaves' words.
VoxelList listOf(const openvdb::MaskTree& tree) {
    VoxelList out;
    for (auto it = tree.cbeginLeaf(); it; ++it) {
        LeafVoxels leaf{it->origin(), {}};
        for (int x = 0; x < 8; ++x)
            leaf.words[std::size_t(x)] = it->getValueMask().getWord<leafwords::Word>(x);
        out.push_back(leaf);
    }
    return out;
}

} // namespace

// A list dilates as its tree does, whether each leaf is listed once, or some twice (their
// voxels split between the two entries).
TEST(DilateByCube, AListDilatesAsItsTreeDoes) {
    for (int radius : {0, 1, 4, 9}) {
        const auto mask = randomMask(21);
        auto expected = std::make_shared<openvdb::MaskTree>(*mask);
        dilateByCube(*expected, radius);
        VoxelList once = listOf(*mask), twice;
        for (std::size_t i = 0; i < once.size(); ++i) {
            twice.push_back(once[i]);
            if (i % 3 != 0) continue;
            LeafVoxels half = once[i]; // the first entry keeps the even words, this the odd
            for (std::size_t x = 0; x < 8; x += 2) {
                twice.back().words[x + 1] = 0;
                half.words[x] = 0;
            }
            twice.push_back(half);
        }
        for (const VoxelList* list : {&once, &twice}) {
            openvdb::MaskTree tree;
            uniteMasks(tree, dilatedByCube(*list, radius));
            EXPECT_EQ(tree.activeVoxelCount(), expected->activeVoxelCount()) << radius;
            EXPECT_TRUE(tree.hasSameTopology(*expected)) << radius;
        }
    }
}

TEST(UniteMasks, AListAddsItsVoxels) {
    const auto into = randomMask(31), from = randomMask(32);
    auto expected = std::make_shared<openvdb::MaskTree>(*into);
    expected->topologyUnion(*from);
    uniteMasks(*into, listOf(*from));
    EXPECT_EQ(into->activeVoxelCount(), expected->activeVoxelCount());
    EXPECT_TRUE(into->hasSameTopology(*expected));
}
