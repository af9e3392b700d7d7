#include "levelset/band.h"

#include <algorithm>
#include <cstdint>

#include <openvdb/tools/Diagnostics.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "levelset/stencils.h"

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

using Word = std::uint64_t;
constexpr Word kZ0 = 0x0101010101010101ull, kZ7 = kZ0 << 7; // the voxels at z = 0, z = 7

// Bit k of the word: whether v[first + k * stride] is inside, for k < count.
Word signs(const float* v, std::size_t first, std::size_t count, std::size_t stride) {
    Word w = 0;
    for (std::size_t k = 0; k < count; ++k)
        w |= Word(v[first + k * stride] < 0.0f) << k;
    return w;
}

} // namespace

LeafNode::NodeMaskType crossingVoxels(const LeafNode& leaf, const Grid::ConstAccessor& acc) {
    // Offsets are x * 64 + y * 8 + z, so word x of a mask holds the slab x, bit y * 8 + z.
    const float* v = leaf.buffer().data();
    Word own[8];
    for (std::size_t x = 0; x < 8; ++x)
        own[x] = signs(v, 64 * x, 64, 1);
    // The face neighbour along an axis: its values, or none where the grid holds a tile there
    // (a tile has one sign: `tileInside`).
    const auto neighbour = [&](int axis, int dir, bool& tileInside) -> const float* {
        openvdb::Coord o = leaf.origin();
        o[axis] += dir * int(LeafNode::DIM);
        if (const LeafNode* n = acc.probeConstLeaf(o)) return n->buffer().data();
        tileInside = acc.getValue(o) < 0.0f;
        return nullptr;
    };
    LeafNode::NodeMaskType out;
    const auto add = [&](std::size_t x, Word w) {
        out.getWord<Word>(openvdb::Index(x)) |= w ^ own[x];
    };
    for (const int dir : {-1, 1}) {
        bool tile = false;
        // Along x: the neighbouring slab, or the neighbour leaf's facing slab.
        const float* n = neighbour(0, dir, tile);
        const Word face = n ? signs(n, dir > 0 ? 0 : 7 * 64, 64, 1) : (tile ? ~Word(0) : 0);
        for (std::size_t x = 0; x < 8; ++x) {
            const std::size_t t = x + std::size_t(dir); // wraps past 7 when dir is -1 at 0
            add(x, t < 8 ? own[t] : face);
        }
        // Along y: rows of eight bits; the facing row of the neighbour at y = 0 or 7.
        n = neighbour(1, dir, tile);
        for (std::size_t x = 0; x < 8; ++x) {
            const Word row =
                n ? signs(n, 64 * x + (dir > 0 ? 0 : 56), 8, 1) : (tile ? Word(0xff) : 0);
            add(x, dir > 0 ? (own[x] >> 8) | (row << 56) : (own[x] << 8) | row);
        }
        // Along z: within each row; the neighbour's voxels at z = 0 or 7, one per row.
        n = neighbour(2, dir, tile);
        for (std::size_t x = 0; x < 8; ++x) {
            Word column = 0; // bit y * 8 at z = 0
            if (n) {
                const Word bits = signs(n, 64 * x + (dir > 0 ? 0 : 7), 8, 8);
                for (std::size_t y = 0; y < 8; ++y)
                    column |= ((bits >> y) & 1) << (8 * y);
            } else if (tile) {
                column = kZ0;
            }
            add(x,
                dir > 0 ? ((own[x] >> 1) & ~kZ7) | (column << 7) : ((own[x] << 1) & ~kZ0) | column);
        }
    }
    return out;
}

BandReport checkBand(const Grid& grid) {
    BandReport r;
    openvdb::tools::CheckLevelSet<Grid> check(grid);
    r.vdbCheck = check.check(/*updateMask=*/false);
    const double h = grid.voxelSize()[0];
    const float limit = float(grid.background() + h);
    openvdb::tree::LeafManager<const Grid::TreeType> leaves(grid.tree());
    struct Counts {
        std::size_t active = 0, near = 0, unit = 0, beyond = 0;
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
                    if (!nextToCrossing(*leaf, it.pos(), acc_)) continue;
                    const openvdb::Coord ijk = it.getCoord();
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
            return a;
        });
    r.activeVoxels = c.active;
    r.nearInterface = c.near;
    r.unitGradient = c.unit;
    r.beyondBand = c.beyond;
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
