// SPDX-License-Identifier: Apache-2.0
// levelset/leaf_snapshot.h: what undo keeps of a stroke puts the grid back to the bit, and
// the same blocks taken after the stroke put it forward again (redo).
#include <gtest/gtest.h>

#include "grids.h"
#include "levelset/create.h"
#include "levelset/leaf_snapshot.h"

using namespace sweepers;
using sweepers::test::differingBits;

namespace {

GridPtr ball() {
    return makeSphere(Eigen::Vector3d::Zero(), 0.5, 1.0 / 32, 3.0);
}

// Changes everything of kind a stroke changes inside `box`: values and states of band voxels,
// a leaf made where a tile of the inside was, a leaf of the band taken out (its block a tile);
// then the signs of inactive values and tiles follow the band, as after a stroke.
void edit(Grid& g, const openvdb::CoordBBox& box) {
    auto acc = g.getAccessor();
    for (auto it = box.begin(); it; ++it) {
        float v;
        if (acc.probeValue(*it, v)) acc.setValue(*it, v - 0.01f);
    }
    acc.setValueOff(box.min(), -0.2f);
    ASSERT_EQ(g.tree().probeConstLeaf({0, 0, 0}), nullptr); // deep inside: a tile
    g.tree().touchLeaf({0, 0, 0})->setValueOn(0, -0.3f);
    const openvdb::Coord band(15, 0, 0); // on the surface, 0.5 / (1/32) = 16 voxels out
    ASSERT_NE(g.tree().probeConstLeaf(band), nullptr);
    delete g.tree().stealNode<LeafNode>(band, 0.0f, false);
    openvdb::tools::signedFloodFill(g.tree());
}

} // namespace

TEST(LeafSnapshot, UndoPutsBackEveryBlockAndRedoPutsTheEditBack) {
    const GridPtr before = ball();
    GridPtr g = before->deepCopy();
    const openvdb::CoordBBox box({-4, -4, -4}, {20, 6, 6});
    LeafSnapshot undo;
    undo.capture(*g, box);
    // Blocks are whole leaves: the box's 8^3 blocks, -8..23 along x, -8..7 along y and z.
    EXPECT_EQ(undo.blockCount(), 4u * 2u * 2u);
    EXPECT_EQ(undo.bounds(), openvdb::CoordBBox({-8, -8, -8}, {23, 7, 7}));
    edit(*g, box);
    const GridPtr after = g->deepCopy();
    ASSERT_GT(differingBits(*g, *before), 100u);

    // A block taken again after the edit keeps what it held first.
    undo.capture(*g, box);
    EXPECT_EQ(undo.blockCount(), 16u);

    const LeafSnapshot redo = LeafSnapshot::sameBlocks(*g, undo);
    EXPECT_EQ(redo.blockCount(), undo.blockCount());
    undo.restore(*g);
    EXPECT_EQ(differingBits(*g, *before), 0u);
    redo.restore(*g);
    EXPECT_EQ(differingBits(*g, *after), 0u);
    undo.restore(*g);
    EXPECT_EQ(differingBits(*g, *before), 0u);
}

// What lies outside the blocks taken is not the snapshot's: undo leaves it as it is.
TEST(LeafSnapshot, UndoLeavesWhatItDidNotTakeAlone) {
    const GridPtr before = ball();
    GridPtr g = before->deepCopy();
    LeafSnapshot undo;
    undo.capture(*g, openvdb::CoordBBox({8, -4, -4}, {20, 4, 4}));
    const openvdb::Coord outside(-15, 0, 0);
    float v;
    ASSERT_TRUE(g->getConstAccessor().probeValue(outside, v));
    g->getAccessor().setValue(outside, v + 0.5f);
    undo.restore(*g);
    EXPECT_EQ(differingBits(*g, *before), 1u);
    EXPECT_EQ(g->getConstAccessor().getValue(outside), v + 0.5f);
}
