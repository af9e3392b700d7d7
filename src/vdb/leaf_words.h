// SPDX-License-Identifier: Apache-2.0
// A leaf's voxel sets as eight 64-bit words, one per x: bit y * 8 + z of word x is the voxel
// at offset x * 64 + y * 8 + z (the layout of a leaf's value mask). The scans of the band
// (voxels next to the surface, seeds, thin features) test 64 voxels at a time by moving a
// set one step along an axis; that step is written once, here.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <type_traits>

#ifdef __SSE2__
#include <xmmintrin.h>
#endif

namespace sweepers::leafwords {

using Word = std::uint64_t;
using Words = std::array<Word, 8>;                          // a set of one leaf's voxels
constexpr Word kZ0 = 0x0101010101010101ull, kZ7 = kZ0 << 7; // the voxels at z = 0, z = 7
constexpr Word kY0 = 0xffull, kY7 = kY0 << 56;              // the voxels at y = 0, y = 7

// Bit k: whether v[k] < 0, for k < n (n <= 64): the signs of a row or a word of a leaf's
// values, four compares at once where the CPU has SSE (a compare, a shift and an or per
// value made these scans, which every segment runs, a visible share of it). The same answer as
// `v[k] < 0.0f` for every value, -0 and NaN included.
inline Word negatives(const float* v, int n) {
    Word w = 0;
    int k = 0;
#ifdef __SSE2__
    const __m128 zero = _mm_setzero_ps();
    for (; k + 4 <= n; k += 4)
        w |= Word(unsigned(_mm_movemask_ps(_mm_cmplt_ps(_mm_loadu_ps(v + k), zero)))) << k;
#endif
    for (; k < n; ++k)
        w |= Word(v[k] < 0.0f) << k;
    return w;
}

// Whether the set holds any voxel.
inline bool any(const Words& set) {
    Word all = 0;
    for (const Word w : set)
        all |= w;
    return all != 0;
}

// Adds the voxels of `from` to `into`.
inline void unite(Words& into, const Words& from) {
    for (std::size_t x = 0; x < into.size(); ++x)
        into[x] |= from[x];
}

// The smallest leaf-local box holding every voxel of a set that holds one: lo and hi (bounds
// included) along x, y and z, read from the words (the set's union folds into its rows).
inline void bounds(const Words& set, int (&lo)[3], int (&hi)[3]) {
    Word all = 0;
    int first = 8, last = -1;
    for (int x = 0; x < 8; ++x)
        if (set[std::size_t(x)]) {
            all |= set[std::size_t(x)];
            first = std::min(first, x);
            last = x;
        }
    unsigned rows = 0, cols = 0; // bit y: row y holds a voxel; bit z: some row holds z
    for (int y = 0; y < 8; ++y) {
        const unsigned row = unsigned(all >> (8 * y)) & 0xffu;
        rows |= unsigned(row != 0) << y;
        cols |= row;
    }
    lo[0] = first;
    hi[0] = last;
    lo[1] = __builtin_ctz(rows);
    hi[1] = 31 - __builtin_clz(rows);
    lo[2] = __builtin_ctz(cols);
    hi[2] = 31 - __builtin_clz(cols);
}

// Word x of the set `own` seen one step along axis A (dir = +-1): its bit for a voxel is the
// bit of the voxel one step away. Past the leaf's face it reads `facing`, the layer of the
// next leaf that faces it, laid out as that axis needs it: along x the whole word, along y
// the row of eight bits (bits 0-7), along z one bit a row (bit y * 8).
template <int A> Word stepped(const Word* own, int x, int dir, Word facing) {
    if constexpr (A == 2)
        return dir > 0 ? ((own[x] >> 1) & ~kZ7) | (facing << 7) : ((own[x] << 1) & ~kZ0) | facing;
    else if constexpr (A == 1)
        return dir > 0 ? (own[x] >> 8) | (facing << 56) : (own[x] << 8) | facing;
    else
        return x + dir >= 0 && x + dir < 8 ? own[x + dir] : facing;
}

// The voxels of a leaf within `reach` (1 or 2) steps of its face along axis A (dir = +-1):
// those whose step of `reach` along the axis leaves the leaf.
template <int A> Words nearFace(int dir, int reach) {
    Words out{};
    for (int x = 0; x < 8; ++x) {
        if constexpr (A == 0)
            out[std::size_t(x)] = (dir > 0 ? x >= 8 - reach : x < reach) ? ~Word(0) : 0;
        else if constexpr (A == 1)
            out[std::size_t(x)] =
                dir > 0 ? (reach > 1 ? kY7 | kY7 >> 8 : kY7) : (reach > 1 ? kY0 | kY0 << 8 : kY0);
        else
            out[std::size_t(x)] =
                dir > 0 ? (reach > 1 ? kZ7 | kZ7 >> 1 : kZ7) : (reach > 1 ? kZ0 | kZ0 << 1 : kZ0);
    }
    return out;
}

// The layer of the set `next` (the leaf one step along axis A, dir = +-1) that faces this
// leaf, for word x, laid out as stepped<A> reads it.
template <int A> Word facing(const Word* next, int x, int dir) {
    if constexpr (A == 2)
        return dir > 0 ? next[x] & kZ0 : (next[x] & kZ7) >> 7;
    else if constexpr (A == 1)
        return dir > 0 ? next[x] & kY0 : next[x] >> 56;
    else
        return next[dir > 0 ? 0 : 7];
}

// The voxels of the leaf at `origin` that lie inside `box` (index space, bounds included).
template <typename Box, typename Coord> Words inBox(const Box& box, const Coord& origin) {
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = std::max(box.min()[a] - origin[a], 0);
        hi[a] = std::min(box.max()[a] - origin[a], 7);
        if (lo[a] > hi[a]) return Words{};
    }
    const Word row = (Word(0xff) >> (7 - hi[2])) & (Word(0xff) << lo[2]);
    Word word = 0;
    for (int y = lo[1]; y <= hi[1]; ++y)
        word |= row << (8 * y);
    Words out{};
    for (int x = lo[0]; x <= hi[0]; ++x)
        out[std::size_t(x)] = word;
    return out;
}

// Calls f(axis, dir, origin, next) for the six faces of `leaf`: axis an
// std::integral_constant of 0, 1 or 2, dir +-1, origin that of the leaf across the face and
// next that leaf, or nullptr where a tile is.
template <typename Leaf, typename Accessor, typename F>
void forEachFace(const Leaf& leaf, const Accessor& acc, F&& f) {
    const auto along = [&](auto axis) {
        for (const int dir : {-1, 1}) {
            auto o = leaf.origin();
            o[decltype(axis)::value] += dir * int(Leaf::DIM);
            f(axis, dir, o, acc.probeConstLeaf(o));
        }
    };
    along(std::integral_constant<int, 0>{});
    along(std::integral_constant<int, 1>{});
    along(std::integral_constant<int, 2>{});
}

} // namespace sweepers::leafwords
