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

namespace sweepers::upwind {

namespace {

using F8 = float __attribute__((vector_size(32)));
using I8 = int __attribute__((vector_size(32)));

constexpr float kInf = std::numeric_limits<float>::infinity();

F8 splat(float x) {
    return F8{} + x;
}
F8 load(const float* p) {
    F8 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
F8 sqrtOf(F8 x) {
    for (int i = 0; i < 8; ++i)
        x[i] = std::sqrt(x[i]);
    return x;
}

} // namespace

// The solution of sum_a c_a (u - m_a)^2 = h^2 for the largest root, using axes in increasing
// m_a while the root stays above them (the upwind discretization of |grad u| = 1; c_a = 1
// for the first-order difference, 9/4 for the second-order one (3u - 4u1 + u2) / 2h where
// the voxel beyond the upwind neighbour is closer still: HAFMM). Solved for w = u - m_0,
// where every term is of the order of h^2, so single precision keeps the root to about
// 1e-7 h. Every branch of a voxel-at-a-time solve is a select here: the lanes take their own
// ways through the same instructions.
// (Built for AVX2 too where the compiler can: 8 lanes in one register instead of two.)
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default")))
#endif
unsigned
relaxRow(const RowBlock& block, int b, unsigned lanes) {
    const float* v = block.values;
    const std::ptrdiff_t strides[3] = {block.strideX, block.strideY, 1};
    const F8 inf = splat(kInf), one = splat(1.0f);
    F8 m[3], c[3];
    for (int a = 0; a < 3; ++a) {
        const std::ptrdiff_t s = strides[a];
        const F8 lo = load(v + b - s), hi = load(v + b + s);
        const I8 down = lo <= hi; // ties take the lower side
        const F8 best = down ? lo : hi;
        if (block.reach == 2) {
            const F8 beyond = down ? load(v + b - 2 * s) : load(v + b + 2 * s);
            const I8 second = (best < inf) & (beyond <= best);
            m[a] = second ? (4.0f * best - beyond) * (1.0f / 3.0f) : best;
            c[a] = second ? splat(2.25f) : one;
        } else {
            m[a] = best;
            c[a] = one;
        }
    }
    // Sorted by m (a network of three compare-and-swaps; +infinity, no neighbour of the side
    // along that axis, sorts last and is never used).
    const auto order = [&](int p, int q) {
        const I8 swap = m[q] < m[p];
        const F8 mp = m[p], mq = m[q], cp = c[p], cq = c[q];
        m[p] = swap ? mq : mp;
        m[q] = swap ? mp : mq;
        c[p] = swap ? cq : cp;
        c[q] = swap ? cp : cq;
    };
    order(0, 1);
    order(1, 2);
    order(0, 1);
    // h / sqrt(c_0) without the root: c_0 is 1 or 9/4, whose root is 3/2 exactly.
    F8 w = c[0] == one ? splat(block.h) : splat(block.h / 1.5f);
    // sum_k c_k (w - d_k)^2 - h^2 = A w^2 - 2 B w + C, with d_k = m_k - m_0, over the first
    // two axes and over all three. The third is only ever taken after the second, so both
    // roots are found at once, and only which one holds waits for the other: a lane's value
    // is a chain of dependent operations, and a sweep's next row reads it.
    F8 root[2], d[2];
    I8 valid[2];
    {
        F8 A = c[0], B = F8{}, C = splat(-block.h * block.h);
        for (int k = 0; k < 2; ++k) {
            d[k] = m[k + 1] - m[0];
            A += c[k + 1];
            B += c[k + 1] * d[k];
            C += c[k + 1] * d[k] * d[k];
            const F8 disc = B * B - A * C;
            valid[k] = disc >= 0.0f;
            root[k] = (B + sqrtOf(valid[k] ? disc : F8{})) * (1.0f / A);
        }
    }
    I8 more = m[0] < inf; // the lanes still taking axes
    for (int k = 0; k < 2; ++k) {
        more &= (w > d[k]) & valid[k] & (root[k] >= d[k]);
        w = more ? root[k] : w;
    }
    const F8 u = ((m[0] == inf) | (m[0] + w > block.background)) ? inf : m[0] + w;
    // Moved: by more than the tolerance, or to or from +infinity (inf - inf is NaN, which
    // compares false: no move).
    const F8 was = load(v + b);
    const F8 delta = u - was;
    const I8 bit = {1, 2, 4, 8, 16, 32, 64, 128};
    const I8 take =
        ((delta > block.tolerance) | (delta < -block.tolerance)) & ((bit & int(lanes)) != 0);
    const F8 now = take ? u : was;
    std::memcpy(block.values + b, &now, sizeof now);
    unsigned out = 0;
    for (int z = 0; z < 8; ++z)
        out |= unsigned(take[z] & bit[z]);
    return out;
}

} // namespace sweepers::upwind
