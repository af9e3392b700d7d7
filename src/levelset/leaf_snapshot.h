// SPDX-License-Identifier: Apache-2.0
// A copy of parts of a level set, 8^3 block by block, that can be put back exactly: what
// undo keeps for a stroke (only the blocks its segments could touch, each once).
#pragma once

#include <memory>
#include <unordered_map>

#include "vdb/vdb.h"

namespace sweepers {

class LeafSnapshot {
  public:
    // Copies every block overlapping `box` that is not in the snapshot yet: its leaf if it
    // has one, else the value and state of the tile covering it.
    void capture(const Grid& grid, const openvdb::CoordBBox& box);
    // The same blocks as `other`, as they are in `grid` now (for redo).
    static LeafSnapshot sameBlocks(const Grid& grid, const LeafSnapshot& other);

    // Puts the blocks back, then re-derives the signs of the tiles around them.
    void restore(Grid& grid) const;

    std::size_t blockCount() const { return blocks_.size(); }
    // Index box of the blocks (empty when there are none).
    openvdb::CoordBBox bounds() const;
    std::size_t bytes() const;

  private:
    using Leaf = Grid::TreeType::LeafNodeType;
    struct Block {
        std::unique_ptr<Leaf> leaf; // null: a tile
        float value = 0.0f;
        bool active = false;
    };
    void captureBlock(const Grid& grid, const openvdb::Coord& origin);
    std::unordered_map<openvdb::Coord, Block> blocks_;
};

} // namespace sweepers
