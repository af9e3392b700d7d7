// SPDX-License-Identifier: Apache-2.0
#include "levelset/upwind_row.h"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>

// Compiled without errno for the math functions (see CMakeLists.txt): nothing reads it, and
// a square root that may set it cannot work on a vector of lanes. The helpers below pass
// vectors wider than the baseline's registers by value; they are internal and inlined, so
// the ABI note GCC gives for them does not concern any caller.
#pragma GCC diagnostic ignored "-Wpsabi"

#if defined(__x86_64__) && defined(__GNUC__)
#define SWEEPERS_AVX2_ROWS 1
#endif

namespace sweepers::upwind {

namespace {

// Four lanes fit the registers of every x86-64 (SSE2) and ARM (NEON) CPU; eight those of
// AVX2. (GCC lowers a vector of eight lanes for a CPU without AVX to scalar code.)
struct Four {
    using F = float __attribute__((vector_size(16)));
    using I = int __attribute__((vector_size(16)));
};
struct Eight {
    using F = float __attribute__((vector_size(32)));
    using I = int __attribute__((vector_size(32)));
};

constexpr float kInf = std::numeric_limits<float>::infinity();

template <typename F> [[gnu::always_inline]] inline F splat(float x) {
    return F{} + x;
}
template <typename F> [[gnu::always_inline]] inline F load(const float* p) {
    F v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
template <typename F> [[gnu::always_inline]] inline F sqrtOf(F x) {
    for (std::size_t i = 0; i < sizeof(F) / sizeof(float); ++i)
        x[i] = std::sqrt(x[i]);
    return x;
}

// Bit z: whether lane z of the mask is set.
template <typename I> [[gnu::always_inline]] inline unsigned lanesOf(I mask) {
    unsigned out = 0;
    for (std::size_t z = 0; z < sizeof(I) / sizeof(int); ++z)
        out |= unsigned(mask[z] != 0) << z;
    return out;
}

// The new values of the lanes of the row from block index b (kept where they did not move,
// or are not in `lanes`), and the lanes that moved.
template <typename L> struct Solved {
    typename L::F now;
    unsigned moved;
};

// The solution of sum_a c_a (u - m_a)^2 = h^2 for the largest root, using axes in increasing
// m_a while the root stays above them (the upwind discretization of |grad u| = 1; c_a = 1
// for the first-order difference, 9/4 for the second-order one (3u - 4u1 + u2) / 2h where
// the voxel beyond the upwind neighbour is closer still: HAFMM). Solved for w = u - m_0,
// where every term is of the order of h^2, so single precision keeps the root to about
// 1e-7 h. Every branch of a voxel-at-a-time solve is a select here: the lanes take their own
// ways through the same instructions.
template <typename L>
[[gnu::always_inline]] inline Solved<L> solveLanes(const RowBlock& block, int b, unsigned lanes) {
    using F = typename L::F;
    using I = typename L::I;
    constexpr int kLanes = int(sizeof(F) / sizeof(float));
    const float* v = block.values;
    const std::ptrdiff_t strides[3] = {block.strideX, block.strideY, 1};
    const F inf = splat<F>(kInf), one = splat<F>(1.0f);
    F m[3], c[3];
    for (int a = 0; a < 3; ++a) {
        const std::ptrdiff_t s = strides[a];
        const F lo = load<F>(v + b - s), hi = load<F>(v + b + s);
        const I down = lo <= hi; // ties take the lower side
        const F best = down ? lo : hi;
        if (block.reach == 2) {
            const F beyond = down ? load<F>(v + b - 2 * s) : load<F>(v + b + 2 * s);
            const I second = (best < inf) & (beyond <= best);
            m[a] = second ? (4.0f * best - beyond) * (1.0f / 3.0f) : best;
            c[a] = second ? splat<F>(2.25f) : one;
        } else {
            m[a] = best;
            c[a] = one;
        }
    }
    // A lane of +infinity stays there when every axis's m lies within 0.38 h of the
    // background or past it: the root w below is at least h / sqrt(sum c_a) >= h / 2.6 (each
    // term of its equation is at most c_a w^2), so m_0 + w lies past the background too. A
    // third of the rows a drag segment's solve relaxes are such lanes only, beyond the band's
    // edge next to voxels that moved: they return at once, unchanged.
    const F was = load<F>(v + b);
    {
        const F low = m[0] < m[1] ? (m[0] < m[2] ? m[0] : m[2]) : (m[1] < m[2] ? m[1] : m[2]);
        const I live = (low + 0.38f * block.h <= block.background) | (was < inf);
        if (!(lanesOf(live) & lanes)) return {was, 0u};
    }
    // Sorted by m (a network of three compare-and-swaps; +infinity, no neighbour of the side
    // along that axis, sorts last and is never used).
    const auto order = [&](int p, int q) {
        const I swap = m[q] < m[p];
        const F mp = m[p], mq = m[q], cp = c[p], cq = c[q];
        m[p] = swap ? mq : mp;
        m[q] = swap ? mp : mq;
        c[p] = swap ? cq : cp;
        c[q] = swap ? cp : cq;
    };
    order(0, 1);
    order(1, 2);
    order(0, 1);
    // h / sqrt(c_0) without the root: c_0 is 1 or 9/4, whose root is 3/2 exactly.
    F w = c[0] == one ? splat<F>(block.h) : splat<F>(block.h / 1.5f);
    // sum_k c_k (w - d_k)^2 - h^2 = A w^2 - 2 B w + C, with d_k = m_k - m_0, over the first
    // two axes and over all three. The third is only ever taken after the second, so both
    // roots are found at once, and only which one holds waits for the other: a lane's value
    // is a chain of dependent operations, and a sweep's next row reads it.
    F root[2], d[2];
    I valid[2];
    {
        F A = c[0], B = F{}, C = splat<F>(-block.h * block.h);
        for (int k = 0; k < 2; ++k) {
            d[k] = m[k + 1] - m[0];
            A += c[k + 1];
            B += c[k + 1] * d[k];
            C += c[k + 1] * d[k] * d[k];
            const F disc = B * B - A * C;
            valid[k] = disc >= 0.0f;
            root[k] = (B + sqrtOf<F>(valid[k] ? disc : F{})) * (1.0f / A);
        }
    }
    I more = m[0] < inf; // the lanes still taking axes
    for (int k = 0; k < 2; ++k) {
        more &= (w > d[k]) & valid[k] & (root[k] >= d[k]);
        w = more ? root[k] : w;
    }
    const F u = ((m[0] == inf) | (m[0] + w > block.background)) ? inf : m[0] + w;
    // Moved: by more than the tolerance, or to or from +infinity (inf - inf is NaN, which
    // compares false: no move).
    const F delta = u - was;
    I bit;
    for (int z = 0; z < kLanes; ++z)
        bit[z] = 1 << z;
    const I take =
        ((delta > block.tolerance) | (delta < -block.tolerance)) & ((bit & int(lanes)) != 0);
    return {take ? u : was, lanesOf(take)};
}

} // namespace

namespace detail {

unsigned relaxRowIn4s(const RowBlock& block, int b, unsigned lanes) {
    // Both halves are solved before either is written: each reads the row as it was.
    const Solved<Four> lo = solveLanes<Four>(block, b, lanes & 15u);
    const Solved<Four> hi = solveLanes<Four>(block, b + 4, lanes >> 4);
    std::memcpy(block.values + b, &lo.now, sizeof lo.now);
    std::memcpy(block.values + b + 4, &hi.now, sizeof hi.now);
    return lo.moved | hi.moved << 4;
}

#ifdef SWEEPERS_AVX2_ROWS
__attribute__((target("avx2"))) unsigned relaxRowIn8s(const RowBlock& block, int b,
                                                      unsigned lanes) {
    const Solved<Eight> row = solveLanes<Eight>(block, b, lanes);
    std::memcpy(block.values + b, &row.now, sizeof row.now);
    return row.moved;
}

bool hasAvx2() {
    return __builtin_cpu_supports("avx2");
}
#else
unsigned relaxRowIn8s(const RowBlock& block, int b, unsigned lanes) {
    return relaxRowIn4s(block, b, lanes);
}

bool hasAvx2() {
    return false;
}
#endif

} // namespace detail

RowRelaxer rowRelaxer() {
    static const RowRelaxer best = detail::hasAvx2() ? detail::relaxRowIn8s : detail::relaxRowIn4s;
    return best;
}

unsigned relaxRow(const RowBlock& block, int b, unsigned lanes) {
    return rowRelaxer()(block, b, lanes);
}

} // namespace sweepers::upwind
