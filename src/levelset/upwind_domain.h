// SPDX-License-Identifier: Apache-2.0
// The data renormalization (renormalize.h) solves on: the leaves of a region, each with its six
// face neighbours found once (Domain); a leaf's voxel sets as bits, in the leaf's order or in
// that of a block whose rows run along another axis; and a leaf with a rim of its neighbours'
// values in a dense block (Block), which the upwind stencils read by fixed strides.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "levelset/leaf_box.h"
#include "vdb/leaf_words.h"
#include "vdb/local_tree.h"
#include "vdb/vdb.h"
#include "vdb/voxel_list.h"

namespace sweepers::upwind {

using Leaf = Grid::TreeType::LeafNodeType;
constexpr int kLeafVoxels = Leaf::SIZE; // 512, offset = x * 64 + y * 8 + z

template <int A> using Axis = std::integral_constant<int, A>;
// Calls body(Axis<0>{}), body(Axis<1>{}), body(Axis<2>{}): the axis is a constant in each
// call, so neighbour steps compile to shifts and adds.
template <typename Body> void forEachAxis(Body&& body) {
    body(Axis<0>{});
    body(Axis<1>{});
    body(Axis<2>{});
}

// The voxels of every leaf overlapping the region (grown by a margin), stored leaf by
// leaf with each leaf's six face neighbours, so a neighbour is an add or one table
// lookup. The band lives in leaves; voxels outside them (tiles) are far from the
// surface and are not needed. Given the leaves whose voxels may be freed (`near`), only
// those and the leaves around them (face, edge or corner) are taken: everything a free
// voxel's seed, stencils and thin test read lies there (a drag segment's box at 1/256 holds
// some 4,000 leaves of band, of which a sixth lie farther from any).
class Domain {
  public:
    static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();

    Domain(Grid& grid, const openvdb::CoordBBox& region, int margin, const VoxelList* near) {
        openvdb::CoordBBox outer = region;
        outer.expand(margin);
        leaves_ = leavesIn(grid.tree(), outer);
        // The leaves' positions (origins in leaves).
        std::vector<openvdb::Coord> at(leaves_.size());
        for (std::size_t l = 0; l < leaves_.size(); ++l)
            at[l] = leaves_[l]->origin() >> Leaf::LOG2DIM;
        index(at);
        if (near) {
            std::vector<char> listed(leaves_.size(), 0), kept(leaves_.size(), 0);
            for (const LeafVoxels& leaf : *near)
                if (const int l = indexOf(leaf.origin); l >= 0) listed[std::size_t(l)] = 1;
            parallelFor(std::size_t(0), leaves_.size(), [&](std::size_t l) {
                for (int dx = -1; dx <= 1 && !kept[l]; ++dx)
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dz = -1; dz <= 1; ++dz)
                            if (const int k = find(at[l].offsetBy(dx, dy, dz)); k >= 0)
                                kept[l] |= listed[std::size_t(k)];
            });
            std::size_t n = 0;
            for (std::size_t l = 0; l < leaves_.size(); ++l)
                if (kept[l]) {
                    leaves_[n] = leaves_[l];
                    at[n++] = at[l];
                }
            leaves_.resize(n);
            at.resize(n);
            index(at);
        }
        neighbours_.resize(leaves_.size());
        // Each leaf's six neighbours (-1: none), in parallel.
        parallelFor(std::size_t(0), leaves_.size(), [&](std::size_t l) {
            for (int a = 0; a < 3; ++a)
                for (int d = 0; d < 2; ++d) {
                    openvdb::Coord p = at[l];
                    p[a] += d ? 1 : -1;
                    neighbours_[l][2 * std::size_t(a) + std::size_t(d)] = find(p);
                }
        });
    }

    // The index of the leaf at `origin`, or -1 where the domain has none.
    int indexOf(const openvdb::Coord& origin) const { return find(origin >> Leaf::LOG2DIM); }

    std::size_t size() const { return leaves_.size() * kLeafVoxels; }
    std::size_t leafCount() const { return leaves_.size(); }
    Leaf& leaf(std::size_t l) const { return *leaves_[l]; }

    // The face neighbour of voxel i one step along axis A (dir = +-1), or npos.
    template <int A> std::size_t neighbour(std::size_t i, int dir) const {
        constexpr int shift = 6 - 3 * A; // offsets are x * 64 + y * 8 + z
        constexpr std::size_t stride = std::size_t(1) << shift;
        const int c = int((i >> shift) & 7) + dir;
        if (c >= 0 && c < 8) return dir > 0 ? i + stride : i - stride;
        const int nl = neighbours_[i >> 9][2 * A + (dir > 0)];
        if (nl < 0) return npos;
        // The same row or column of the neighbouring leaf, at its other end.
        const std::size_t rest = i & 511 & ~(std::size_t(7) << shift);
        return (std::size_t(nl) << 9) | rest | (dir > 0 ? 0 : std::size_t(7) << shift);
    }
    template <int A> std::size_t neighbour(std::size_t i, int dir, Axis<A>) const {
        return neighbour<A>(i, dir);
    }

    // A voxel set of a leaf as eight words, one per x; bit y * 8 + z of word x is the voxel
    // at offset x * 64 + y * 8 + z. Scans of the domain test whole words of voxels at once
    // and only visit the few voxels a test leaves, instead of reading six neighbours of
    // every voxel of every leaf.
    using Bits = leafwords::Words;

    // `out` gets, for each voxel of leaf l, the bit of its neighbour one step along axis A
    // (dir = +-1) in `sets` (one Bits per leaf); `valid` gets the voxels that have such a
    // neighbour in the domain (0 where it would lie in a leaf outside it).
    template <int A>
    void stepped(const Bits* sets, std::size_t l, int dir, Bits& out, Bits& valid) const {
        using namespace leafwords;
        const Word* w = sets[l].data();
        const int nl = neighbours_[l][2 * A + (dir > 0)];
        const Word* n = nl < 0 ? nullptr : sets[std::size_t(nl)].data();
        // The voxels whose step leaves the leaf: without a neighbour in the domain they have
        // none.
        const Words leaving = nearFace<A>(dir, 1);
        for (int x = 0; x < 8; ++x) {
            out[x] = leafwords::stepped<A>(w, x, dir, n ? facing<A>(n, x, dir) : 0);
            valid[x] = n ? ~Word(0) : ~leaving[std::size_t(x)];
        }
    }

    // The index of leaf l's face neighbour k = 2 * axis + (dir > 0), or -1.
    int neighbourLeaf(std::size_t l, int k) const { return neighbours_[l][std::size_t(k)]; }

  private:
    // Finds the leaves (at positions `at`, in leaves) by position: in a table over their box
    // where a band fills enough of it (a drag's band fills about a fifth of its box of
    // leaves), since a table look-up is one load where a binary search is a dozen dependent
    // ones; else (shapes far apart, where a table over their box would be mostly empty) in
    // the leaves sorted by position.
    void index(const std::vector<openvdb::Coord>& at) {
        table_.reset();
        sorted_.clear();
        if (at.empty()) return;
        openvdb::CoordBBox box;
        for (const openvdb::Coord& p : at)
            box.expand(p);
        const openvdb::Coord dim = box.dim();
        const double slots = double(dim.x()) * dim.y() * dim.z();
        if (slots <= double(kSlotsPerLeaf * at.size() + kFewSlots)) {
            table_.emplace(box.min(), box.max());
            for (std::size_t l = 0; l < at.size(); ++l)
                table_->at(at[l]) = int(l);
        } else {
            sorted_.resize(at.size());
            for (std::size_t l = 0; l < at.size(); ++l)
                sorted_[l] = {at[l], int(l)};
            std::sort(sorted_.begin(), sorted_.end());
        }
    }

    // The index of the leaf at position p (in leaves), or -1.
    int find(const openvdb::Coord& p) const {
        if (table_) return table_->get(p);
        const auto it = std::lower_bound(
            sorted_.begin(), sorted_.end(), p,
            [](const auto& entry, const openvdb::Coord& c) { return entry.first < c; });
        return it != sorted_.end() && it->first == p ? it->second : -1;
    }

    std::vector<Leaf*> leaves_;
    std::vector<std::array<int, 6>> neighbours_;
    // The leaves by position: a table over their box, or (far apart) sorted.
    std::optional<LeafBox> table_;
    std::vector<std::pair<openvdb::Coord, int>> sorted_;
};

using Bits = Domain::Bits;

// Calls visit(offset) for every voxel of a leaf whose bit is set.
template <typename Visit> void forEachBit(const Bits& bits, const Visit& visit) {
    for (int x = 0; x < 8; ++x)
        for (std::uint64_t w = bits[x]; w; w &= w - 1)
            visit(x * 64 + __builtin_ctzll(w));
}

inline Bits operator&(Bits a, const Bits& b) {
    for (std::size_t x = 0; x < 8; ++x)
        a[x] &= b[x];
    return a;
}
inline Bits operator|(Bits a, const Bits& b) {
    for (std::size_t x = 0; x < 8; ++x)
        a[x] |= b[x];
    return a;
}
inline Bits operator~(Bits a) {
    for (std::uint64_t& word : a)
        word = ~word;
    return a;
}

// The voxels of a leaf whose stencils read a voxel of `bits`: those up to `reach` steps from
// one along an axis, within the leaf (either side: an over-estimate, which only costs work).
inline Bits readers(const Bits& bits, int reach) {
    Bits out = bits;
    forEachAxis([&](auto a) {
        for (const int dir : {-1, 1}) {
            Bits step = bits;
            for (int k = 0; k < reach; ++k) {
                Bits next;
                for (int x = 0; x < 8; ++x)
                    next[std::size_t(x)] =
                        leafwords::stepped<decltype(a)::value>(step.data(), x, dir, 0);
                step = next;
                out = out | step;
            }
        }
    });
    return out;
}

// Bit 8 * j of the result for each byte j of w that is not zero.
inline leafwords::Word nonzeroBytes(leafwords::Word w) {
    w |= w >> 4;
    w |= w >> 2;
    w |= w >> 1;
    return w & leafwords::kZ0;
}

inline bool isSet(const Bits& bits, int off) {
    return (bits[std::size_t(off) >> 6] >> (off & 63)) & 1;
}
inline void set(Bits& bits, int off) {
    bits[std::size_t(off) >> 6] |= std::uint64_t(1) << (off & 63);
}

using leafwords::Word;

// The layer `pos` of a leaf's voxel set across axis A, as a plane of 64 bits: bit u * 8 + v
// for the voxel at (u, v) along the other two axes, in order (y, z; x, z; x, y).
template <int A> Word plane(const Bits& bits, int pos) {
    if constexpr (A == 0) return bits[std::size_t(pos)];
    Word out = 0;
    for (int x = 0; x < 8; ++x) {
        Word row;
        if constexpr (A == 1)
            row = (bits[std::size_t(x)] >> (8 * pos)) & 0xffu;
        else // bit `pos` of each byte, y = 0..7, gathered into a byte by one multiply
            row = (((bits[std::size_t(x)] >> pos) & leafwords::kZ0) * 0x0102040810204080ull) >> 56;
        out |= row << (8 * x);
    }
    return out;
}

// The leaf offset of bit `bit` of plane<A>(_, pos).
template <int A> int inPlane(int pos, int bit) {
    if constexpr (A == 0) return pos * 64 + bit;
    if constexpr (A == 1) return (bit >> 3) * 64 + pos * 8 + (bit & 7);
    return (bit >> 3) * 64 + (bit & 7) * 8 + pos;
}

inline bool negative(float v) {
    return v < 0.0f;
}

// A distance as the solve stores it: with the sign of its voxel's side (the sign bit set
// inside, for 0 and +infinity too), so that the side travels with the value and a block is
// filled from values alone.
inline float signedAs(bool inside, float d) {
    return inside ? -d : d;
}

// Four floats, and four lanes of a mask (GCC's vector extensions; SSE2 on x86-64): blocks are
// filled and distances written back four values at a time.
using Floats4 = float __attribute__((vector_size(16)));
using Lanes4 = std::int32_t __attribute__((vector_size(16)));

// One leaf of the domain and a rim of two voxels taken from its six face neighbours, in a
// dense block: the upwind stencils (which reach two voxels along each axis) read their
// neighbours by fixed strides, without branching on leaf borders. Each side of the surface
// has its own copy, in which the other side's voxels read as infinitely far: an update only
// ever reads its own side. Only face neighbours are filled; the stencils never read the
// block's edges and corners.
//
// The block's rows (stride 1) are solved eight voxels at once, each from the values of its
// neighbours as they were before (upwind::relaxRow), so a change travels one voxel along a
// row per sweep, and as far as the sweep goes across rows. Along the rows it fades by about
// the gradient's component there at each step: the rows run along the leaf's axis closest to
// the surface's tangent plane (the block is the leaf with its axes permuted). On the drag a
// leaf's values move by 0.05-0.1 voxel in its first sweep and by a fifth to a tenth as much
// in each after, so its first solve takes five to eight sweeps to 1e-6 voxel.
struct Block {
    static constexpr int kRim = 2, kDim = Leaf::DIM + 2 * kRim;
    static constexpr int kStride[3] = {kDim * kDim, kDim, 1}; // of the block's own axes
    static constexpr std::size_t kSize = std::size_t(kDim) * kDim * kDim;

    // Lays the leaf out with its axis `axis` along the block's rows: the block's axes are the
    // leaf's (x, y, z), (x, z, y) or (z, y, x).
    void setRowAxis(int axis) {
        rowAxis = axis;
        stride = axis == 2   ? std::array<int, 3>{kStride[0], kStride[1], kStride[2]}
                 : axis == 1 ? std::array<int, 3>{kStride[0], kStride[2], kStride[1]}
                             : std::array<int, 3>{kStride[2], kStride[1], kStride[0]};
    }
    // The block index of the voxel at offset `off` of the leaf.
    int at(int off) const {
        return ((off >> 6) + kRim) * stride[0] + (((off >> 3) & 7) + kRim) * stride[1] +
               ((off & 7) + kRim) * stride[2];
    }

    int rowAxis = 2;
    std::array<int, 3> stride{};                  // the block strides of the leaf's x, y and z
    std::array<std::array<float, kSize>, 2> side; // [inside][index]
};

// The 8 x 8 bit matrix of a word, transposed: bit r * 8 + c goes to c * 8 + r (three swaps
// of blocks of bits across the diagonal: 1 x 1, 2 x 2, then 4 x 4).
inline leafwords::Word transposed8(leafwords::Word w) {
    w = (w & 0xaa55aa55aa55aa55ull) | ((w & 0x00aa00aa00aa00aaull) << 7) |
        ((w >> 7) & 0x00aa00aa00aa00aaull);
    w = (w & 0xcccc3333cccc3333ull) | ((w & 0x0000cccc0000ccccull) << 14) |
        ((w >> 14) & 0x0000cccc0000ccccull);
    w = (w & 0xf0f0f0f00f0f0f0full) | ((w & 0x00000000f0f0f0f0ull) << 28) |
        ((w >> 28) & 0x00000000f0f0f0f0ull);
    return w;
}

// A voxel set of a leaf in the order of a block whose rows run along `rowAxis` (word i, bit
// j * 8 + k for the block's axes i, j, k), or back: each permutation swaps two axes, so it is
// its own inverse.
inline Bits inBlockOrder(const Bits& bits, int rowAxis) {
    if (rowAxis == 2) return bits;
    Bits out{};
    if (rowAxis == 1) { // (x, y, z) -> (x, z, y): within each word
        for (std::size_t x = 0; x < 8; ++x)
            out[x] = transposed8(bits[x]);
        return out;
    }
    // (x, y, z) -> (z, y, x): for each y, the bits (x, z) of the eight words, transposed.
    for (int y = 0; y < 8; ++y) {
        leafwords::Word w = 0;
        for (int x = 0; x < 8; ++x)
            w |= ((bits[std::size_t(x)] >> (8 * y)) & 0xffu) << (8 * x);
        w = transposed8(w);
        for (int z = 0; z < 8; ++z)
            out[std::size_t(z)] |= ((w >> (8 * z)) & 0xffu) << (8 * y);
    }
    return out;
}

} // namespace sweepers::upwind
