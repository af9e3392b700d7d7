// SPDX-License-Identifier: Apache-2.0
// Work on the part of a tree inside an index box, at a cost that follows the box, not the
// tree: a sculpting segment touches a brush-sized box of a model that only grows.
//
// The leaves overlapping a box are found by descending the tree through the internal
// nodes that overlap it; signs of inactive values are re-derived (signed flood fill) in the
// leaves and internal nodes overlapping the box, bottom up; the values of a box are copied
// into a dense array.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "vdb/leaf_words.h"
#include "vdb/parallel.h"
#include "vdb/vdb.h"

namespace sweepers {

// The leaves of `tree` (a Grid::TreeType, const or not) overlapping `box`. A leaf's place is
// read from its parent (the iterator's coordinate), so the leaves left out are not touched:
// reading each one's origin would cost a cache miss a leaf.
template <typename TreeT> auto leavesIn(TreeT& tree, const openvdb::CoordBBox& box) {
    using Leaf = std::conditional_t<std::is_const_v<TreeT>, const LeafNode, LeafNode>;
    std::vector<Leaf*> out;
    if (box.empty()) return out;
    constexpr int kLast = int(LeafNode::DIM) - 1;
    for (auto upper = tree.root().beginChildOn(); upper; ++upper) {
        if (!box.hasOverlap(upper->getNodeBoundingBox())) continue;
        for (auto lower = upper->beginChildOn(); lower; ++lower) {
            if (!box.hasOverlap(lower->getNodeBoundingBox())) continue;
            for (auto leaf = lower->beginChildOn(); leaf; ++leaf) {
                const openvdb::Coord origin = leaf.getCoord();
                if (box.hasOverlap(openvdb::CoordBBox(origin, origin.offsetBy(kLast))))
                    out.push_back(&*leaf);
            }
        }
    }
    return out;
}

// Frees the nodes of `tree` on the calling thread, leaving it empty. OpenVDB's Tree::clear,
// which a tree's destructor calls, frees the leaves in a parallel loop, and threads freeing
// small blocks of one heap at once contend for it, so that freeing a few thousand leaves in
// parallel is slower than freeing them on one thread. A segment frees its copies and its
// threads' marks so.
template <typename TreeT> void freeOnThisThread(TreeT& tree) {
    std::vector<typename TreeT::LeafNodeType*> leaves;
    tree.stealNodes(leaves);
    for (auto* leaf : leaves)
        delete leaf;
    tree.clear();
}

// Copies the values of `box` into `out`, a dense array indexed ((x * ny) + y) * nz + z
// from box.min(), a leaf's row at a time: `leafAt(origin)` gives the leaf at that origin (or
// null), `valueAt(ijk)` the value of a tile or the background where there is none. What
// reads every voxel around a leaf (meshing, sampling) reads its neighbours this way instead
// of one tree lookup per voxel.
template <typename LeafAt, typename ValueAt>
void copyBox(const openvdb::CoordBBox& box, float* out, const LeafAt& leafAt,
             const ValueAt& valueAt) {
    constexpr int kDim = int(LeafNode::DIM);
    const openvdb::Coord size = box.dim();
    const auto at = [&](int x, int y, int z) {
        return (std::size_t(x - box.min().x()) * std::size_t(size.y()) +
                std::size_t(y - box.min().y())) *
                   std::size_t(size.z()) +
               std::size_t(z - box.min().z());
    };
    const openvdb::Coord first(box.min().x() & ~(kDim - 1), box.min().y() & ~(kDim - 1),
                               box.min().z() & ~(kDim - 1));
    for (int ox = first.x(); ox <= box.max().x(); ox += kDim)
        for (int oy = first.y(); oy <= box.max().y(); oy += kDim)
            for (int oz = first.z(); oz <= box.max().z(); oz += kDim) {
                const openvdb::Coord o(ox, oy, oz);
                openvdb::CoordBBox part(o, o.offsetBy(kDim - 1));
                part.intersect(box);
                const LeafNode* leaf = leafAt(o);
                const openvdb::Coord lo = part.min(), n = part.dim();
                // The part's rows, stepped through by strides (an index computed per row was
                // most of a block's cost).
                float* const to = out + at(lo.x(), lo.y(), lo.z());
                const std::size_t toY = std::size_t(size.z()), toX = std::size_t(size.y()) * toY;
                const auto forEachRow = [&](const auto& body) {
                    for (int x = 0; x < n.x(); ++x)
                        for (int y = 0; y < n.y(); ++y)
                            body(to + std::size_t(x) * toX + std::size_t(y) * toY,
                                 (std::size_t(x) * kDim + std::size_t(y)) * kDim);
                };
                if (!leaf) {
                    const float tile = float(valueAt(o));
                    forEachRow([&](float* row, std::size_t) { std::fill(row, row + n.z(), tile); });
                    continue;
                }
                const float* const from = leaf->buffer().data() + LeafNode::coordToOffset(lo);
                const auto rows = [&](auto length) {
                    forEachRow([&](float* row, std::size_t offset) {
                        std::memcpy(row, from + offset, sizeof(float) * std::size_t(int(length)));
                    });
                };
                // The rows a block around a leaf reads are a whole leaf row or one or two
                // voxels of its neighbours': copied by fixed sizes, where a copy of any length
                // is a library call per row.
                switch (n.z()) {
                case kDim:
                    rows(std::integral_constant<int, kDim>{});
                    break;
                case 2:
                    rows(std::integral_constant<int, 2>{});
                    break;
                case 1:
                    rows(std::integral_constant<int, 1>{});
                    break;
                default:
                    rows(n.z());
                }
            }
}

// Re-derives the signs of a leaf's inactive values from its active ones, to the bit as
// tools::SignedFloodFillOp does: each inactive voxel takes the side of the active voxel
// before it along its row (z); a row starts from the side of the last active voxel that
// began a row before it in its slab (y), and a slab from the last active voxel that began a
// slab before it (x), the leaf from its first active voxel. OpenVDB's takes a branch on every
// voxel's state; here the rows' states and signs are bytes of the masks' words, and a row's
// values are chosen without branches (a drag segment at 1/128 floods about 560 leaves).
inline void floodLeafSigns(LeafNode& leaf, float inside, float outside) {
    const auto& mask = leaf.getValueMask();
    float* const values = leaf.buffer().data();
    const openvdb::Index first = mask.findFirstOn();
    if (first >= LeafNode::SIZE) { // no active voxel: the side of the first value
        leaf.fill(values[0] < 0.0f ? inside : outside);
        return;
    }
    bool xInside = values[first] < 0.0f;
    for (int x = 0; x < 8; ++x) {
        float* const slab = values + std::size_t(64) * std::size_t(x);
        const std::uint64_t on = mask.getWord<std::uint64_t>(x);
        const std::uint64_t negative = leafwords::negatives(slab, 64);
        if (on & 1u) xInside = negative & 1u;
        bool yInside = xInside;
        for (int y = 0; y < 8; ++y) {
            const unsigned active = unsigned(on >> (8 * y)) & 0xffu;
            const unsigned sign = unsigned(negative >> (8 * y)) & 0xffu;
            if (active & 1u) yInside = sign & 1u;
            if (active == 0xffu) continue;
            float* const row = slab + std::size_t(8) * std::size_t(y);
            bool zInside = yInside;
            for (int z = 0; z < 8; ++z) {
                const bool isOn = (active >> z) & 1u;
                zInside = isOn ? bool((sign >> z) & 1u) : zInside;
                row[z] = isOn ? row[z] : zInside ? inside : outside;
            }
        }
    }
}

// Re-derives the signs of the inactive values of `leaves` and of the internal nodes that
// overlap `box` (what tools::signedFloodFill does to a whole tree), from their active values;
// everything else keeps its values (a leaf whose values did not change keeps its signs).
// Returns the number of leaves filled.
inline std::size_t floodSignsIn(Grid::TreeType& tree, const std::vector<LeafNode*>& leaves,
                                const openvdb::CoordBBox& box) {
    if (box.empty()) return 0;
    const openvdb::tools::SignedFloodFillOp<Grid::TreeType> fill(tree);
    // Leaves only read their own values, so they are filled in parallel; a node's tiles take
    // their signs from its children, so nodes are filled after them, bottom up.
    const float outside = std::abs(tree.background()), inside = -outside;
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& r) {
        for (std::size_t l = r.begin(); l != r.end(); ++l)
            floodLeafSigns(*leaves[l], inside, outside);
    });
    // Each node reads only its own children, so the nodes of a level are filled in parallel
    // too: an upper node holds 32768 tiles, and a stroke near the origin crosses four of
    // them, too much work to leave to one thread.
    using Upper = Grid::TreeType::RootNodeType::ChildNodeType;
    using Lower = Upper::ChildNodeType;
    std::vector<Upper*> uppers;
    std::vector<Lower*> lowers;
    for (auto upper = tree.root().beginChildOn(); upper; ++upper) {
        if (!box.hasOverlap(upper->getNodeBoundingBox())) continue;
        uppers.push_back(&*upper);
        for (auto lower = upper->beginChildOn(); lower; ++lower)
            if (box.hasOverlap(lower->getNodeBoundingBox())) lowers.push_back(&*lower);
    }
    const auto fillAll = [&](const auto& nodes) {
        parallelFor(tbb::blocked_range<std::size_t>(0, nodes.size(), 1), [&](const auto& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i)
                fill(*nodes[i]);
        });
    };
    fillAll(lowers);
    fillAll(uppers);
    fill(tree.root()); // the root's tiles between its (few) children
    return leaves.size();
}

} // namespace sweepers
