// SPDX-License-Identifier: Apache-2.0
#include "levelset/dilate.h"
#include "vdb/parallel.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "levelset/leaf_box.h"
#include "vdb/leaf_words.h"

namespace sweepers {

namespace {

using Leaf = openvdb::MaskTree::LeafNodeType;
constexpr int kDim = int(Leaf::DIM); // 8
// A leaf's mask as eight words, one per x; bit y * 8 + z of word x is voxel (x, y, z).
using leafwords::kZ0;
using leafwords::Word;
using Bits = std::array<Word, kDim>;

struct MaskLeaf {
    openvdb::Coord at; // the leaf's position in leaves (origin / 8)
    Bits bits;
};

// Per byte of a word (a row along z), the bits of z below s, and of z at 8 - s and above.
constexpr Word lowBits(int s) {
    return kZ0 * ((Word(1) << s) - 1);
}
constexpr Word highBits(int s) {
    return lowBits(s) << (kDim - s);
}

// Unit u (a row of word x along y, or word u along x) of a leaf.
template <int Axis> Word unitOf(const Bits& b, int x, int u) {
    return Axis == 1 ? (b[std::size_t(x)] >> (8 * u)) & 0xffu : b[std::size_t(u)];
}

// The voxels of a leaf within r (1..8) steps along Axis (0 = x, 1 = y, 2 = z) of its own
// voxels `own`, of its neighbour before it `before` and after it `after` (null: none).
template <int Axis>
Bits dilatedAlong(const Bits& own, const Bits* before, const Bits* after, int r) {
    Bits out{};
    if constexpr (Axis == 2) {
        // Rows of eight bits in each byte: shifted within the byte, and in from the ends of
        // the rows of the leaves before and after.
        for (std::size_t x = 0; x < kDim; ++x) {
            Word w = own[x];
            for (int s = 1; s <= r; ++s) {
                w |= ((own[x] << s) & ~lowBits(s)) | ((own[x] >> s) & ~highBits(s));
                if (before) w |= (((*before)[x] >> (kDim - s)) & lowBits(s));
                if (after) w |= (((*after)[x] << (kDim - s)) & highBits(s));
            }
            out[x] = w;
        }
    } else if constexpr (Axis == 1) {
        // Rows along z are the bytes of a word, one per y: a shift of the word by s bytes
        // moves every row s steps along y, and the neighbours' rows come in from the ends.
        // (A unit at a time, as along x, read 2r + 1 rows for each of the 64 rows: this
        // axis cost four times the other two together.)
        const auto up = [](Word w, int bytes) { return bytes < 8 ? w << (8 * bytes) : Word(0); };
        const auto down = [](Word w, int bytes) { return bytes < 8 ? w >> (8 * bytes) : Word(0); };
        for (std::size_t x = 0; x < kDim; ++x) {
            Word w = own[x];
            for (int s = 1; s <= r; ++s) {
                w |= up(own[x], s) | down(own[x], s);
                if (before) w |= down((*before)[x], kDim - s);
                if (after) w |= up((*after)[x], kDim - s);
            }
            out[x] = w;
        }
    } else {
        // Along x the units are whole words: words u - r ... u + r of this leaf and those past
        // its ends in the neighbours.
        const auto wordAt = [&](int t) -> Word {
            const Bits* in = t < 0 ? before : t >= kDim ? after : &own;
            const int at = t < 0 ? t + kDim : t >= kDim ? t - kDim : t;
            return in ? (*in)[std::size_t(at)] : 0;
        };
        for (int u = 0; u < kDim; ++u) {
            Word v = 0;
            for (int t = u - r; t <= u + r; ++t)
                v |= wordAt(t);
            out[std::size_t(u)] = v;
        }
    }
    return out;
}

// Whether a leaf reaches into its neighbour along Axis on side dir (+-1) when dilated by r.
template <int Axis> bool spills(const Bits& b, int dir, int r) {
    for (int x = 0; x < kDim; ++x)
        for (int t = 0; t < r; ++t) {
            const int u = dir > 0 ? kDim - 1 - t : t; // the units within r of that face
            if (Axis == 2) {
                if (b[std::size_t(x)] & (kZ0 << u)) return true;
            } else if (unitOf<Axis>(b, x, u)) {
                return true;
            }
        }
    return false;
}

// One dilation by r (1..8) along Axis of every leaf of the list, the list growing by the
// neighbours it reaches into. Each leaf's result is read from itself and its two neighbours
// along the axis, so the leaves are done in parallel.
template <int Axis> void dilateList(std::vector<MaskLeaf>& leaves, LeafBox& box, int r) {
    // Which leaves reach into a neighbour the list lacks, found in parallel (the box is only
    // read); the few new leaves are then added on this thread, in the list's order.
    const std::size_t count = leaves.size();
    std::vector<std::uint8_t> reaches(count);
    parallelFor(tbb::blocked_range<std::size_t>(0, count, grainFor(count, 256)),
                [&](const auto& range) {
                    for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        std::uint8_t sides = 0;
                        for (const int dir : {-1, 1}) {
                            openvdb::Coord c = leaves[i].at;
                            c[Axis] += dir;
                            if (box.get(c) < 0 && spills<Axis>(leaves[i].bits, dir, r))
                                sides |= dir < 0 ? 1 : 2;
                        }
                        reaches[i] = sides;
                    }
                });
    for (std::size_t i = 0; i < count; ++i)
        for (const int dir : {-1, 1}) {
            if (!(reaches[i] & (dir < 0 ? 1 : 2))) continue;
            openvdb::Coord c = leaves[i].at;
            c[Axis] += dir;
            if (box.at(c) >= 0) continue; // added already, from its other side
            box.at(c) = int(leaves.size());
            leaves.push_back({c, Bits{}});
        }
    std::vector<Bits> out(leaves.size());
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size(), grainFor(leaves.size(), 64)),
                [&](const auto& range) {
                    for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        openvdb::Coord c = leaves[i].at;
                        c[Axis] -= 1;
                        const int b = box.get(c);
                        c[Axis] += 2;
                        const int a = box.get(c);
                        out[i] = dilatedAlong<Axis>(
                            leaves[i].bits, b < 0 ? nullptr : &leaves[std::size_t(b)].bits,
                            a < 0 ? nullptr : &leaves[std::size_t(a)].bits, r);
                    }
                });
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size(), grainFor(leaves.size(), 256)),
                [&](const auto& range) {
                    for (std::size_t i = range.begin(); i != range.end(); ++i)
                        leaves[i].bits = out[i];
                });
}

// Dilates the leaves of [begin, end) by the cube of half-side `radius`, onto the end of
// `out`. The cube distributes over a union, so a set whose leaves are far apart (more slots
// in their box than kSlotsPerLeaf a leaf) is split in two along its longest side, and each
// half is dilated in its own box. Returns whether it was split: each leaf is listed once
// unless it was (a leaf both halves reach is listed by both).
bool dilateInto(std::vector<MaskLeaf>::iterator begin, std::vector<MaskLeaf>::iterator end,
                int radius, VoxelList& out) {
    const int reach = (radius + kDim - 1) / kDim; // in leaves
    openvdb::Coord lo = begin->at, hi = begin->at;
    for (auto it = begin; it != end; ++it) {
        lo.minComponent(it->at);
        hi.maxComponent(it->at);
    }
    lo -= openvdb::Coord(reach);
    hi += openvdb::Coord(reach);
    const openvdb::Coord n = hi - lo + openvdb::Coord(1);
    const double slots = double(n.x()) * n.y() * n.z();
    const std::size_t count = std::size_t(end - begin);
    if (count > 1 && slots > double(kSlotsPerLeaf * count + kFewSlots)) {
        const int axis = int(n.maxIndex());
        const auto middle = begin + std::ptrdiff_t(count / 2);
        std::nth_element(begin, middle, end, [axis](const MaskLeaf& a, const MaskLeaf& b) {
            return a.at[axis] < b.at[axis];
        });
        dilateInto(begin, middle, radius, out);
        dilateInto(middle, end, radius, out);
        return true;
    }
    // Each leaf once: one listed again joins its first entry.
    std::vector<MaskLeaf> leaves;
    leaves.reserve(count);
    LeafBox box(lo, hi);
    for (auto it = begin; it != end; ++it) {
        int& slot = box.at(it->at);
        if (slot < 0) {
            slot = int(leaves.size());
            leaves.push_back(*it);
            continue;
        }
        leafwords::unite(leaves[std::size_t(slot)].bits, it->bits);
    }
    // Cubes add up: past a leaf's width, dilate one leaf's width at a time.
    for (int left = radius; left > 0; left -= kDim) {
        const int r = std::min(left, kDim);
        dilateList<2>(leaves, box, r);
        dilateList<1>(leaves, box, r);
        dilateList<0>(leaves, box, r);
    }
    const std::size_t first = out.size();
    out.resize(first + leaves.size());
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size(), grainFor(leaves.size(), 256)),
                [&](const auto& range) {
                    for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const MaskLeaf& leaf = leaves[i];
                        // (Multiplied, not shifted: a left shift of a negative coordinate is
                        // undefined.)
                        out[first + i] = {openvdb::Coord(leaf.at.x() * kDim, leaf.at.y() * kDim,
                                                         leaf.at.z() * kDim),
                                          leaf.bits};
                    }
                });
    return false;
}

} // namespace

VoxelList dilatedByCube(const VoxelList& from, int radius) {
    if (radius < 0) throw std::invalid_argument("dilatedByCube: a negative radius");
    if (radius == 0) return eachLeafOnce(from);
    std::vector<MaskLeaf> leaves(from.size());
    parallelFor(tbb::blocked_range<std::size_t>(0, from.size(), grainFor(from.size(), 256)),
                [&](const auto& range) {
                    for (std::size_t i = range.begin(); i != range.end(); ++i)
                        leaves[i] = {from[i].origin >> Leaf::LOG2DIM, from[i].words};
                });
    VoxelList out;
    if (!leaves.empty() && dilateInto(leaves.begin(), leaves.end(), radius, out))
        out = eachLeafOnce(std::move(out));
    return out;
}

VoxelList eachLeafOnce(VoxelList list) {
    std::sort(list.begin(), list.end(),
              [](const LeafVoxels& p, const LeafVoxels& q) { return p.origin < q.origin; });
    VoxelList out;
    for (const LeafVoxels& leaf : list) {
        if (!out.empty() && out.back().origin == leaf.origin) {
            leafwords::unite(out.back().words, leaf.words);
            continue;
        }
        out.push_back(leaf);
    }
    return out;
}

VoxelList listLeaves(const openvdb::MaskTree& tree) {
    VoxelList out;
    out.reserve(tree.leafCount());
    for (auto it = tree.cbeginLeaf(); it; ++it) {
        LeafVoxels leaf{it->origin(), {}};
        for (int x = 0; x < kDim; ++x)
            leaf.words[std::size_t(x)] = it->getValueMask().getWord<Word>(x);
        out.push_back(leaf);
    }
    return out;
}

void uniteMasks(openvdb::MaskTree& into, const VoxelList& from) {
    openvdb::tree::ValueAccessor<openvdb::MaskTree, false> acc(into);
    for (const LeafVoxels& leaf : from) {
        if (!leafwords::any(leaf.words)) continue;
        auto& words = acc.touchLeaf(leaf.origin)->getValueMask();
        for (int x = 0; x < kDim; ++x)
            words.getWord<Word>(x) |= leaf.words[std::size_t(x)];
    }
}

} // namespace sweepers
