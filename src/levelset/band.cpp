// SPDX-License-Identifier: Apache-2.0
#include "levelset/band.h"

#include <algorithm>
#include <cstdint>
#include <type_traits>

#include <openvdb/tools/Diagnostics.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "levelset/stencils.h"
#include "vdb/leaf_words.h"

namespace sweepers {

bool nextToCrossing(const LeafNode& leaf, openvdb::Index offset, const Grid::ConstAccessor& acc) {
    const bool inside = leaf.getValue(offset) < 0.0f;
    const openvdb::Coord local = LeafNode::offsetToLocalCoord(offset);
    for (int a = 0; a < 3; ++a) {
        const openvdb::Index stride = openvdb::Index(1) << (3 * (2 - a)); // offset = x*64+y*8+z
        for (int d : {-1, 1}) {
            const int c = local[a] + d;
            float q;
            if (c >= 0 && c < int(LeafNode::DIM)) {
                q = leaf.getValue(d > 0 ? offset + stride : offset - stride);
            } else {
                openvdb::Coord n = leaf.offsetToGlobalCoord(offset);
                n[a] += d;
                q = acc.getValue(n);
            }
            if ((q < 0.0f) != inside) return true;
        }
    }
    return false;
}

namespace {

using leafwords::Word;

// Bit k of the word: whether v[first + k * stride] is inside, for k < count.
Word signs(const float* v, std::size_t first, std::size_t count, std::size_t stride) {
    if (stride == 1) return leafwords::negatives(v + first, int(count));
    Word w = 0;
    for (std::size_t k = 0; k < count; ++k)
        w |= Word(v[first + k * stride] < 0.0f) << k;
    return w;
}

} // namespace

LeafNode::NodeMaskType crossingVoxels(const LeafNode& leaf, const Grid::ConstAccessor& acc) {
    const float* v = leaf.buffer().data();
    Word own[8];
    for (std::size_t x = 0; x < 8; ++x)
        own[x] = signs(v, 64 * x, 64, 1);
    LeafNode::NodeMaskType out;
    leafwords::forEachFace(
        leaf, acc, [&](auto axis, int dir, const openvdb::Coord& o, const LeafNode* next) {
            constexpr int A = decltype(axis)::value;
            // The facing layer of the next leaf, or a tile's one sign where there is none.
            const float* n = next ? next->buffer().data() : nullptr;
            const bool tileInside = !next && acc.getValue(o) < 0.0f;
            // Along x the facing layer is one word, which only the word at the face reads.
            Word facingX = 0;
            if constexpr (A == 0)
                facingX = n ? signs(n, dir > 0 ? 0 : 7 * 64, 64, 1) : tileInside ? ~Word(0) : 0;
            for (int x = 0; x < 8; ++x) {
                const std::size_t sx = std::size_t(x);
                Word facing = 0;
                if constexpr (A == 0) {
                    facing = facingX;
                } else if constexpr (A == 1) {
                    facing = n            ? signs(n, 64 * sx + (dir > 0 ? 0 : 56), 8, 1)
                             : tileInside ? leafwords::kY0
                                          : 0;
                } else if (n) {
                    const Word bits = signs(n, 64 * sx + (dir > 0 ? 0 : 7), 8, 8); // bit y
                    for (std::size_t y = 0; y < 8; ++y)
                        facing |= ((bits >> y) & 1) << (8 * y);
                } else {
                    facing = tileInside ? leafwords::kZ0 : 0;
                }
                out.getWord<Word>(openvdb::Index(x)) |=
                    leafwords::stepped<A>(own, x, dir, facing) ^ own[x];
            }
        });
    return out;
}

BandReport checkBand(const Grid& grid) {
    BandReport r;
    openvdb::tools::CheckLevelSet<Grid> check(grid);
    r.vdbCheck = check.check(/*updateMask=*/false);
    const double h = grid.voxelSize()[0];
    // A voxel exactly a voxel inside the band's edge has its neighbour on the edge, which
    // rounding puts on either side of it: a thousandth of a voxel keeps that from counting.
    const float limit = float(grid.background() + h), inner = float(grid.background() - 1.001 * h);
    openvdb::tree::LeafManager<const Grid::TreeType> leaves(grid.tree());
    struct Counts {
        std::size_t active = 0, near = 0, unit = 0, beyond = 0, holes = 0;
    };
    const Counts c = tbb::parallel_reduce(
        leaves.leafRange(), Counts(),
        [&](const auto& range, Counts acc) {
            auto acc_ = grid.getConstAccessor();
            for (auto leaf = range.begin(); leaf; ++leaf) {
                for (auto it = leaf->cbeginValueOn(); it; ++it) {
                    ++acc.active;
                    const float v = *it;
                    if (std::abs(v) > limit) ++acc.beyond;
                    const openvdb::Coord ijk = it.getCoord();
                    // Distances change by at most a voxel from one voxel to the next: the
                    // neighbours of a voxel this deep lie within the band.
                    const auto offBeside = [&] {
                        for (int a = 0; a < 3; ++a)
                            for (const int d : {-1, 1}) {
                                openvdb::Coord n = ijk;
                                n[a] += d;
                                if (!acc_.isValueOn(n)) return true;
                            }
                        return false;
                    };
                    if (std::abs(v) < inner && offBeside()) ++acc.holes;
                    if (!nextToCrossing(*leaf, it.pos(), acc_)) continue;
                    ++acc.near;
                    const double len = centralGradient(acc_, ijk, h).norm();
                    if (len >= 0.9 && len <= 1.1) ++acc.unit;
                }
            }
            return acc;
        },
        [](Counts a, const Counts& b) {
            a.active += b.active;
            a.near += b.near;
            a.unit += b.unit;
            a.beyond += b.beyond;
            a.holes += b.holes;
            return a;
        });
    r.activeVoxels = c.active;
    r.nearInterface = c.near;
    r.unitGradient = c.unit;
    r.beyondBand = c.beyond;
    r.bandHoles = c.holes;
    return r;
}

std::vector<Eigen::Vector3d> surfacePoints(const Grid& grid, std::size_t most) {
    std::vector<openvdb::Coord> all;
    const auto acc = grid.getConstAccessor();
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf)
        for (auto it = leaf->cbeginValueOn(); it; ++it)
            if (nextToCrossing(*leaf, it.pos(), acc)) all.push_back(it.getCoord());
    const std::size_t stride = most == 0 ? all.size() + 1 : (all.size() + most - 1) / most;
    std::vector<Eigen::Vector3d> points;
    for (std::size_t i = 0; i < all.size(); i += std::max<std::size_t>(1, stride))
        points.push_back(toEigen(grid.indexToWorld(all[i])));
    return points;
}

Box activeWorldBox(const Grid& grid) {
    Box b;
    const openvdb::CoordBBox bb = grid.evalActiveVoxelBoundingBox();
    if (bb.empty()) return b;
    b.add(toEigen(grid.indexToWorld(bb.min())));
    b.add(toEigen(grid.indexToWorld(bb.max())));
    return b;
}

} // namespace sweepers
