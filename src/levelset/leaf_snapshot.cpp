// SPDX-License-Identifier: Apache-2.0
#include "levelset/leaf_snapshot.h"

#include <openvdb/tools/SignedFloodFill.h>

#include "levelset/stencils.h"

namespace sweepers {

namespace {
constexpr int kDim = int(Grid::TreeType::LeafNodeType::DIM);
} // namespace

void LeafSnapshot::captureBlock(const Grid& grid, const openvdb::Coord& origin) {
    if (blocks_.count(origin)) return;
    Block b;
    if (const Leaf* leaf = grid.tree().probeConstLeaf(origin)) {
        b.leaf = std::make_unique<Leaf>(*leaf);
    } else {
        b.value = grid.tree().getValue(origin);
        b.active = grid.tree().isValueOn(origin);
    }
    blocks_.emplace(origin, std::move(b));
}

void LeafSnapshot::capture(const Grid& grid, const openvdb::CoordBBox& box) {
    if (box.empty()) return;
    const openvdb::Coord first = floorToMultiple(box.min(), kDim);
    for (int x = first.x(); x <= box.max().x(); x += kDim)
        for (int y = first.y(); y <= box.max().y(); y += kDim)
            for (int z = first.z(); z <= box.max().z(); z += kDim)
                captureBlock(grid, openvdb::Coord(x, y, z));
}

LeafSnapshot LeafSnapshot::sameBlocks(const Grid& grid, const LeafSnapshot& other) {
    LeafSnapshot s;
    for (const auto& [origin, block] : other.blocks_)
        s.captureBlock(grid, origin);
    return s;
}

void LeafSnapshot::restore(Grid& grid) const {
    auto& tree = grid.tree();
    for (const auto& [origin, b] : blocks_) {
        if (b.leaf)
            tree.addLeaf(new Leaf(*b.leaf));
        else
            tree.addTile(1, origin, b.value, b.active); // level 1: one 8^3 tile
    }
    // Tiles farther away took their signs from the band when the stroke ended; with the
    // band back, flood filling gives them back too.
    openvdb::tools::signedFloodFill(tree);
}

openvdb::CoordBBox LeafSnapshot::bounds() const {
    openvdb::CoordBBox box;
    for (const auto& [origin, b] : blocks_)
        box.expand(openvdb::CoordBBox::createCube(origin, kDim));
    return box;
}

std::size_t LeafSnapshot::bytes() const {
    std::size_t n = blocks_.size() * (sizeof(Block) + sizeof(openvdb::Coord) + 16);
    for (const auto& [origin, b] : blocks_)
        if (b.leaf) n += b.leaf->memUsage();
    return n;
}

} // namespace sweepers
