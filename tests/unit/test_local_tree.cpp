// SPDX-License-Identifier: Apache-2.0
// vdb/local_tree.h: a leaf's signs flooded as OpenVDB floods them, and trees freed on
// the calling thread.
#include <cstring>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <openvdb/tools/SignedFloodFill.h>

#include "vdb/local_tree.h"

using namespace sweepers;

// A leaf's inactive values take the signs OpenVDB's signed flood fill gives them, to the bit:
// leaves with no active voxel, a few, half, nearly all and all of them, values of both signs
// with zeros of either sign, infinities and NaN among them.
TEST(LocalTree, LeafSignsAreFloodedAsOpenVdbFloodsThem) {
    std::mt19937 random(29);
    const float specials[] = {0.0f, -0.0f, std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(),
                              std::numeric_limits<float>::quiet_NaN()};
    std::uniform_real_distribution<float> value(-1.0f, 1.0f), unit(0.0f, 1.0f);
    std::uniform_int_distribution<int> kind(0, 31);
    const double densities[] = {0.0, 0.002, 0.02, 0.3, 0.5, 0.9, 0.998, 1.0};
    Grid::TreeType tree(0.25f);
    const openvdb::tools::SignedFloodFillOp<Grid::TreeType> openvdbFill(tree);
    int changed = 0;
    for (int trial = 0; trial < 400; ++trial) {
        LeafNode leaf(openvdb::Coord(8, -16, 0), 0.0f);
        const double density = densities[trial % 8];
        for (openvdb::Index i = 0; i < LeafNode::SIZE; ++i) {
            const int k = kind(random);
            leaf.setValueOnly(i, k < 5 ? specials[k] : value(random));
            leaf.setActiveState(i, unit(random) < density);
        }
        LeafNode expected(leaf), ours(leaf);
        openvdbFill(expected);
        floodLeafSigns(ours, -0.25f, 0.25f);
        ASSERT_EQ(0, std::memcmp(expected.buffer().data(), ours.buffer().data(),
                                 sizeof(float) * LeafNode::SIZE))
            << "trial " << trial << ", density " << density;
        changed += std::memcmp(leaf.buffer().data(), ours.buffer().data(),
                               sizeof(float) * LeafNode::SIZE) != 0;
    }
    EXPECT_GT(changed, 300); // leaves the fill changed: the case tested
}

// A tree freed on the calling thread is empty and can be used again, and every node it held
// is freed (the sanitizers' run finds any that is not).
TEST(LocalTree, ATreeFreedOnThisThreadIsEmpty) {
    openvdb::MaskTree tree;
    for (int i = 0; i < 40; ++i)
        tree.touchLeaf(openvdb::Coord(8 * i, -300 * i, 5000 - 64 * i))->setValueOn(i);
    tree.addTile(1, openvdb::Coord(4096, 0, 0), true, true); // an active tile, a leaf in size
    ASSERT_EQ(tree.leafCount(), 40u);
    freeOnThisThread(tree);
    EXPECT_EQ(tree.leafCount(), 0u);
    EXPECT_EQ(tree.activeVoxelCount(), 0u);
    EXPECT_TRUE(tree.empty());
    tree.touchLeaf(openvdb::Coord(1, 2, 3))->setValueOn(0);
    EXPECT_EQ(tree.activeVoxelCount(), 1u);
}
