// SPDX-License-Identifier: Apache-2.0
#include "levelset/renormalize.h"
#include "vdb/parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <type_traits>
#include <vector>

#include <emmintrin.h>
#include <openvdb/tools/Prune.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "levelset/linear_surface.h"
#include "levelset/upwind_domain.h"
#include "levelset/upwind_row.h"
#include "vdb/leaf_words.h"
#include "vdb/local_tree.h"

namespace sweepers {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kUnitSlack = 0.01;
// The least drop (in voxels) across each of the two crossings along an axis for a voxel to
// be one voxel thin (thinAlongSomeAxis): the axis meets the surface at more than about 15
// degrees.
constexpr double kLeastThinDrop = 0.25;
// How far (in voxels) a seed's second-order estimate may lie from its central one before it
// replaces it. Below this the two differ by the order of the bias that reading the grid
// linearly (trilinear sampling, marching cubes' edge crossings) puts on a curved surface,
// and the central value, whose own bias partly cancels it, places the surface better.
constexpr double kSecondOrderSlack = 0.05;
// The same for a seed divided by the stretch (in voxels): a hundredth, the change advection
// leaves out as a nudge. Below it the two differ by the model's own error (its second
// differences), and taking it at every segment of a long stroke lets the surface creep.
constexpr double kStretchedSecondOrderSlack = 0.01;

using namespace upwind;

// A solved value may still move by this fraction of a voxel: below it a leaf counts as
// settled (its neighbours are not solved again for it).
constexpr float kSolveTolerance = 1e-6f;
// Sweeps over a leaf at most each time it is solved, and rounds over all leaves at most: the
// iteration converges in a few of each (second-order updates are not monotone, so a bound
// guards against a cycle).
constexpr int kMostSweeps = 32, kMostRounds = 100;

class Renormalizer {
  public:
    Renormalizer(Grid& grid, const openvdb::CoordBBox& region, const RenormalizeOptions& options)
        : b_(grid, region, 2, options.only), n_(b_.size()), h_(float(grid.voxelSize()[0])),
          bg_(grid.background()), order_(options.order), seeding_(options.seeding),
          gradientBefore_(b_.leafCount(), nullptr), interrupter_(options.interrupter),
          phi_(b_.leafCount(), nullptr), dist_(new float[n_]), thin_(b_.leafCount(), Bits{}),
          neg_(new Bits[b_.leafCount()]), fixed_(new Bits[b_.leafCount()]),
          settled_(new Bits[b_.leafCount()]), beyond_(new Bits[b_.leafCount()]),
          layout_(b_.leafCount(), 2) {
        const VoxelList* only = options.only;
        const Seeding seeding = options.seeding;
        const VoxelValues* gradientBefore = options.gradientBefore;
        // Only smooth deformations' seeds divide by the stretch (Seeding).
        if (gradientBefore && seeding == Seeding::Lower)
            for (const LeafValues& leaf : *gradientBefore)
                if (const int l = b_.indexOf(leaf.origin); l >= 0)
                    gradientBefore_[std::size_t(l)] = leaf.values.data();
        // Voxels outside the region (or outside `only`) are boundary: they keep their values.
        std::vector<Bits> freeOf(b_.leafCount()); // per leaf, its free voxels
        std::vector<Bits> within;                 // per leaf, the voxels of `only`
        if (only) {
            within.resize(b_.leafCount());
            for (const LeafVoxels& leaf : *only) {
                const int l = b_.indexOf(leaf.origin);
                if (l >= 0) leafwords::unite(within[std::size_t(l)], leaf.words);
            }
        }
        parallelFor(std::size_t(0), b_.leafCount(), [&](std::size_t l) {
            const Leaf& leaf = b_.leaf(l);
            // The leaves' values are read where they are: nothing writes them before the
            // write-back.
            const float* phi = phi_[l] = leaf.buffer().data();
            float* dist = &dist_[l << 9];
            // Free voxels start from their own values (their order is nearly right). Two loops,
            // so that this one is vectorized.
            for (int i = 0; i < kLeafVoxels; ++i) {
                const float a = std::abs(phi[i]);
                dist[i] = signedAs(negative(phi[i]), a < bg_ ? a : kInf);
            }
            layout_[l] = layoutOf(phi);
            for (std::size_t x = 0; x < 8; ++x)
                neg_[l][x] = leafwords::negatives(phi + 64 * x, 64);
            Bits free = leafwords::inBox(region, leaf.origin());
            if (only) free = free & within[l];
            fixed_[l] = ~free;
            freeOf[l] = free;
        });
        // The band may have to grow past the free voxels: an inactive voxel next to one is
        // free too (it has no value to keep), to be reached by the solve only: it starts
        // without a value and is never a seed (what it holds is stale). Kept fixed, it stayed
        // off where a free voxel at the edge of `only` came within bg - h of the surface: a
        // hole in the band (the strangle of data/strangle_torus.json left four at 1/32).
        parallelFor(std::size_t(0), b_.leafCount(), [&](std::size_t l) {
            // (Domain::stepped moves a set within the leaf as well as across its faces.)
            const Bits next = nextTo(false, [&](auto a, int dir, Bits& out, Bits& valid) {
                b_.stepped<decltype(a)::value>(freeOf.data(), l, dir, out, valid);
            });
            const auto& active = b_.leaf(l).getValueMask();
            Bits& added = beyond_[l];
            for (std::size_t x = 0; x < 8; ++x) {
                added[x] = next[x] & ~active.getWord<std::uint64_t>(int(x)) & fixed_[l][x];
                fixed_[l][x] &= ~added[x];
            }
            forEachBit(added, [&](int off) {
                dist_[(l << 9) + std::size_t(off)] = signedAs(isSet(neg_[l], off), kInf);
            });
            settled_[l] = fixed_[l];
        });
        if (options.moved) findStencilsMoved(*options.moved);
    }

    // How leaf l's block is laid out and swept (bits 0-1: the leaf axis along its rows; bits
    // 2 and 3: whether the sweeps of the outside go down the block's first and second axes,
    // the inside's going the other way). From the leaf's mean gradient (phi clamped to the
    // band, differences summed over a quarter of its lines): the rows run along the axis it
    // has least of, and each side is swept the way its distances grow.
    std::uint8_t layoutOf(const float* phi) const {
        const auto d = [&](int off) { return std::clamp(phi[off], -bg_, bg_); };
        float g[3] = {0.0f, 0.0f, 0.0f};
        for (int p = 0; p < 8; p += 2)
            for (int q = 0; q < 8; q += 2) {
                g[0] += d(7 * 64 + p * 8 + q) - d(p * 8 + q);
                g[1] += d(p * 64 + 7 * 8 + q) - d(p * 64 + q);
                g[2] += d(p * 64 + q * 8 + 7) - d(p * 64 + q * 8);
            }
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (std::abs(g[a]) < std::abs(g[axis])) axis = a;
        // The leaf axes along the block's first and second axes (Block::setRowAxis).
        const int first = axis == 0 ? 2 : 0, second = axis == 1 ? 2 : 1;
        return std::uint8_t(axis | (g[first] < 0.0f) << 2 | (g[second] < 0.0f) << 3);
    }

    RenormalizeStats run(Grid& grid) {
        RenormalizeStats stats;
        flagThin();
        stats.seeds = seed();
        pollInterrupt(interrupter_);
        solve();
        pollInterrupt(interrupter_); // the last chance: nothing has been written yet
        stats.marched = writeBack();
        // Leaves the write-back left without an active voxel become tiles of their sign, one at
        // a time (the tree changes), from what the write-back saw in parallel.
        for (std::size_t l = 0; l < b_.leafCount(); ++l) {
            if (!emptied_[l]) continue;
            const Leaf& leaf = b_.leaf(l);
            const float value = leaf.getFirstValue() < 0.0f ? -bg_ : bg_;
            grid.tree().addTile(1, leaf.origin(), value, false); // frees the leaf
        }
        stats.leaves = b_.leafCount();
        return stats;
    }

  private:
    // Runs visit(leaf) for every leaf of the domain, in parallel.
    template <typename Visit> void forEachLeaf(const Visit& visit) const {
        parallelFor(tbb::blocked_range<std::size_t>(0, b_.leafCount()), [&](const auto& r) {
            for (std::size_t l = r.begin(); l != r.end(); ++l)
                visit(l);
        });
    }

    // The voxels of a leaf with a face neighbour in a set along some axis: one of the two
    // neighbours when `both` is false, both of them along one axis when it is true.
    // `other(axis, dir, out, valid)` gives, per voxel, whether its neighbour one step along
    // the axis is in the set, and whether it has one in the domain (Domain::stepped).
    template <typename Other> static Bits nextTo(bool both, const Other& other) {
        Bits any{};
        forEachAxis([&](auto a) {
            Bits lo, hi, validLo, validHi;
            other(a, -1, lo, validLo);
            other(a, 1, hi, validHi);
            for (int x = 0; x < 8; ++x)
                any[x] |= both ? (lo[x] & validLo[x]) & (hi[x] & validHi[x])
                               : (lo[x] & validLo[x]) | (hi[x] & validHi[x]);
        });
        return any;
    }

    // Per voxel of leaf l: whether its neighbour along an axis is of the other sign.
    Bits acrossSurface(std::size_t l, bool both) const {
        return nextTo(both, [&](auto a, int dir, Bits& out, Bits& valid) {
            b_.stepped<decltype(a)::value>(neg_.get(), l, dir, out, valid);
            for (int x = 0; x < 8; ++x)
                out[x] ^= neg_[l][x];
        });
    }

    // Thin voxels: the surface on both sides along some axis. Their central differences
    // span the feature, and so do those of voxels up to two steps away, which are flagged
    // too (ring 2 and 3). Thin voxels are rare, so the rings are spread from lists.
    void flagThin() {
        tbb::enumerable_thread_specific<std::vector<std::size_t>> found;
        forEachLeaf([&](std::size_t l) {
            forEachBit(acrossSurface(l, true), [&](int off) {
                const std::size_t i = (l << 9) + std::size_t(off);
                if (!thinAlongSomeAxis(i)) return;
                set(thin_[l], off);
                found.local().push_back(i);
            });
        });
        std::vector<std::size_t> ring;
        for (const auto& f : found)
            ring.insert(ring.end(), f.begin(), f.end());
        for (int step = 0; step < 2; ++step) { // rings 2 and 3
            std::vector<std::size_t> next;
            for (const std::size_t i : ring)
                forEachAxis([&](auto a) {
                    for (const int dir : {-1, 1}) {
                        const std::size_t j = b_.neighbour(i, dir, a);
                        if (j == Domain::npos || thin(j)) continue;
                        set(thin_[j >> 9], int(j & 511));
                        next.push_back(j);
                    }
                });
            ring = std::move(next);
        }
    }

    // Whether the surface lies on both sides of voxel i along an axis it crosses at a real
    // angle. Along an axis the surface nearly contains, values a hundredth of a voxel from it
    // flip sign from voxel to voxel: that is the surface itself, not a feature one voxel thin,
    // and freezing the seeds around it keeps values a third of a voxel too far. For a distance,
    // the drop across a crossing is the cosine between the normal and the axis.
    bool thinAlongSomeAxis(std::size_t i) const {
        const float p = phi(i), least = float(kLeastThinDrop) * h_;
        bool thin = false;
        forEachAxis([&](auto a) {
            const std::size_t lo = b_.neighbour(i, -1, a), hi = b_.neighbour(i, 1, a);
            if (thin || lo == Domain::npos || hi == Domain::npos) return;
            const float ql = phi(lo), qh = phi(hi);
            thin = negative(ql) != negative(p) && negative(qh) != negative(p) &&
                   std::abs(p - ql) >= least && std::abs(p - qh) >= least;
        });
        return thin;
    }

    float phi(std::size_t i) const { return phi_[i >> 9][i & 511]; }
    bool thin(std::size_t i) const { return isSet(thin_[i >> 9], int(i & 511)); }

    // 1. Seeds (voxels with a face neighbour across the surface): phi / |grad phi| with
    //    central differences, which turns a sampled field that is no longer a distance back
    //    into one to second order where the field is smooth, capped by the distance to the
    //    nearest axis crossing (the surface is no farther), or, given the norms before,
    //    phi over the stretch or the root of phi's second-order model; in a second pass (Seeding::
    //    Interface), the distance to the linear surface through the crossings. The sign is
    //    always kept.
    std::size_t seed() {
        tbb::enumerable_thread_specific<std::size_t> count(0);
        const float h = h_;
        const auto seedOne = [&](std::size_t i) {
            const float p = phi(i);
            double inv2 = 0.0, grad2 = 0.0;
            float nearestCrossing = kInf;
            bool crossing = false, central = true;
            std::size_t face[3][2]; // the face neighbours, -1 and +1 along each axis
            forEachAxis([&](auto a) {
                float best = kInf;
                float side[2] = {p, p};
                for (const int dir : {-1, 1}) {
                    const std::size_t j = face[a][dir > 0] = b_.neighbour(i, dir, a);
                    if (j == Domain::npos) {
                        central = false;
                        continue;
                    }
                    const float q = phi(j);
                    side[dir > 0] = q;
                    if (negative(q) == negative(p)) continue;
                    crossing = true;
                    const float t = p / (p - q); // fraction of the edge to the crossing
                    best = std::min(best, std::max(t, 1e-6f));
                }
                if (best < kInf) {
                    inv2 += 1.0 / (double(best) * best);
                    nearestCrossing = std::min(nearestCrossing, best);
                }
                if (negative(side[0]) != negative(p) && negative(side[1]) != negative(p))
                    central = false;
                const double g = 0.5 * (double(side[1]) - side[0]);
                grad2 += g * g;
            });
            if (!crossing) return false;
            float d;
            if (!central || thin(i)) {
                // On or next to a feature about one voxel thin (the surface on both sides along
                // an axis) no gradient estimate is trustworthy, so the value is kept (recomputing
                // it would move its crossings a little every time and let the feature drift),
                // but capped by the distance to its nearest axis crossing, as every seed is: a
                // value sampled from a stretched field may exceed it, and no distance does.
                d = std::min(std::abs(p), nearestCrossing * h);
            } else if (const float s =
                           seeding_ == Seeding::Interface ? linearSurfaceDistance(i, face) : kInf;
                       s < kInf) {
                d = s; // no farther than the nearest crossing: the surface passes through it
            } else if (const float before = gradientBefore(i);
                       before > 0.0f && grad2 > 1e-12 * double(h) * h) {
                // The stretch the deformation made here: the value is a distance times it
                // where the values were one before (a seed's, or the upwind solution's).
                const double stretch = std::sqrt(grad2) / h / before;
                if (std::abs(stretch - 1.0) < kUnitSlack) {
                    d = std::abs(p);
                } else {
                    d = std::min(float(std::abs(p) / stretch), nearestCrossing * h);
                    // Where the stretch changes along the normal (a pull's falloff), phi /
                    // stretch errs by its relative change per voxel times the squared distance,
                    // a few hundredths of a voxel: the root of the second-order model of phi,
                    // its gradient read against the same norms, replaces it where they differ.
                    const float d2 = std::min(secondOrderDistance(i, face, before),
                                              nearestQuadraticCrossing(i, face) * h);
                    if (std::abs(d - d2) > float(kStretchedSecondOrderSlack) * h) d = d2;
                }
            } else if (grad2 > 1e-12 * double(h) * h) {
                const double gradNorm = std::sqrt(grad2) / h;
                // A value whose gradient is already unit within kUnitSlack is a distance: kept,
                // so that renormalizing a renormalized grid changes nothing and nothing drifts.
                d = std::abs(gradNorm - 1.0) < kUnitSlack
                        ? std::abs(p)
                        : std::min(float(std::abs(p) / gradNorm), nearestCrossing * h);
                // Where the field bends within the voxel (a stretch that varies across it: a
                // fillet, a tool's edge, a tear's rim) the central differences straddle the bend
                // and read too small a gradient, and the value errs high, by a good part of a
                // voxel at times, even where the gradient passes for unit. The second-order
                // value replaces it downwards, or either way after a tear (Seeding).
                const float d2 = std::min(secondOrderDistance(i, face), nearestCrossing * h);
                if ((seeding_ == Seeding::Either ? std::abs(d - d2) : d - d2) >
                    float(kSecondOrderSlack) * h)
                    d = d2;
            } else {
                d = float(h / std::sqrt(inv2)); // distance to the plane through the crossings
            }
            dist_[i] = signedAs(negative(p), d);
            return true;
        };
        // Only voxels with a face neighbour across the surface can be seeds. (Counted a leaf
        // at a time: the thread's counter is a lookup in a table.)
        forEachLeaf([&](std::size_t l) {
            Bits candidates = acrossSurface(l, false);
            for (int x = 0; x < 8; ++x)
                candidates[x] &= ~settled_[l][x] & ~beyond_[l][x];
            if (!stencilMoved_.empty()) {
                // A seed none of whose stencil moved keeps its value: a boundary value, as
                // the fixed voxels are.
                for (int x = 0; x < 8; ++x) {
                    settled_[l][x] |= candidates[x] & ~stencilMoved_[l][x];
                    candidates[x] &= stencilMoved_[l][x];
                }
            }
            std::size_t n = 0;
            forEachBit(candidates, [&](int off) {
                if (!seedOne((l << 9) + std::size_t(off))) return;
                set(settled_[l], off);
                ++n;
            });
            count.local() += n;
        });
        return count.combine(std::plus<>());
    }

    // The gradient's norm voxel i's value had before the deformation
    // (RenormalizeOptions::gradientBefore), or 0 where none was given.
    float gradientBefore(std::size_t i) const {
        const float* values = gradientBefore_[i >> 9];
        return values ? values[i & 511] : 0.0f;
    }

    // The distance to the linear surface through the crossings of the 3x3x3 block around
    // voxel i (linear_surface.h), given its six face neighbours; +infinity where a voxel of
    // the block lies outside the domain.
    float linearSurfaceDistance(std::size_t i, const std::size_t (&face)[3][2]) const {
        Block27 block;
        for (int x = -1; x <= 1; ++x)
            for (int y = -1; y <= 1; ++y)
                for (int z = -1; z <= 1; ++z) {
                    // Step along x (from the face table), then y, then z.
                    std::size_t j = x != 0 ? face[0][x > 0] : i;
                    if (y != 0 && j != Domain::npos) j = b_.neighbour(j, y, Axis<1>{});
                    if (z != 0 && j != Domain::npos) j = b_.neighbour(j, z, Axis<2>{});
                    if (j == Domain::npos) return kInf;
                    block[(x + 1) * 9 + (y + 1) * 3 + (z + 1)] = phi(j);
                }
        return distanceToLinearSurface(block) * h_;
    }

    // The distance (in voxels) to the nearest crossing along an axis of the parabola through
    // the voxel's value and its two face neighbours' there: the cap of a second-order seed,
    // as the linear crossing caps a first-order one (the parabola and the linear edge cross at
    // the same point only where phi is linear along the axis). `face` as in seed(), all six
    // in the domain.
    float nearestQuadraticCrossing(std::size_t i, const std::size_t (&face)[3][2]) const {
        const double p = phi(i);
        float nearest = kInf;
        for (int a = 0; a < 3; ++a)
            for (const int dir : {-1, 1}) {
                const double q = phi(face[a][dir > 0]), m = phi(face[a][dir < 0]);
                if (negative(float(q)) == negative(float(p))) continue;
                // p + b t + c t^2 from t = -1 (m) to t = 1 (q): one root in (0, 1), since p
                // and q differ in sign; written so that it does not cancel as c goes to 0.
                const double b = 0.5 * (q - m), c = 0.5 * (q + m) - p;
                const double disc = std::max(b * b - 4.0 * c * p, 0.0);
                const double k = -0.5 * (b + std::copysign(std::sqrt(disc), b));
                double t = k != 0.0 ? p / k : -1.0;
                if (!(t > 0.0 && t <= 1.0) && c != 0.0) t = k / c;
                if (!(t > 0.0 && t <= 1.0)) t = p / (p - q); // rounding: the linear one
                nearest = std::min(nearest, float(std::max(t, 1e-6)));
            }
        return nearest;
    }

    // |s| h for the root s (in voxels) nearest the voxel of the quadratic model of phi along
    // its normal, phi + g s + c s^2 / 2 = 0, with g = |grad phi| and c = n^T H n (n = grad
    // phi / g) from central differences on the 3x3x3 block: a distance along the normal to
    // second order, where phi / |grad phi| is one to first order. `face` holds the voxel's six
    // face neighbours (all in the domain, and a nonzero gradient: seed() asks only then). The
    // first-order value where a corner of the block lies outside the domain or the model has
    // no real root. `unit` is the gradient's norm central differences read where the values
    // were a distance (the stretch's reference, gradientBefore()): g is divided by it.
    float secondOrderDistance(std::size_t i, const std::size_t (&face)[3][2],
                              float unit = 1.0f) const {
        const double p = phi(i);
        double g[3], H[3][3];
        for (int a = 0; a < 3; ++a) {
            const double minus = phi(face[a][0]), plus = phi(face[a][1]);
            g[a] = 0.5 * (plus - minus) / unit;
            H[a][a] = plus - 2.0 * p + minus;
        }
        const double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2], gn = std::sqrt(g2);
        // The mixed second differences, from the neighbours of the faces along the other axes.
        bool complete = true;
        forEachAxis([&](auto b) {
            constexpr int B = decltype(b)::value;
            for (int a = 0; a < B; ++a) {
                const auto corner = [&](int da, int db) {
                    const std::size_t j = b_.neighbour(face[a][da > 0], db, b);
                    complete &= j != Domain::npos;
                    return j == Domain::npos ? 0.0 : double(phi(j));
                };
                H[a][B] = H[B][a] =
                    0.25 * (corner(1, 1) - corner(1, -1) - corner(-1, 1) + corner(-1, -1));
            }
        });
        if (!complete) return float(std::abs(p) / gn * h_);
        double c = 0.0;
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                c += g[a] * H[a][b] * g[b];
        c /= g2;
        const double disc = g2 - 2.0 * c * p;
        // The root nearest 0, written so that it does not cancel as c goes to 0.
        const double s = disc > 0.0 ? 2.0 * std::abs(p) / (gn + std::sqrt(disc)) : std::abs(p) / gn;
        return float(s * h_);
    }

    // The voxels whose seed reads a value that moved: those in `moved` and their face
    // neighbours. Recomputing a seed is not idempotent where the surface curves within a
    // voxel: across a valley, central differences read a gradient below 1 even from a
    // distance, phi / |grad phi| grows, and the crossing creeps towards the other side a few
    // hundredths of a voxel at each renormalization. A segment renormalizes the band around
    // what it changed, so without this the voxels near a tool's edge, which no deformation
    // moves, were seeded again at every segment of a stroke.
    void findStencilsMoved(const VoxelList& moved) {
        std::vector<Bits> movedOf(b_.leafCount());
        for (const LeafVoxels& leaf : moved)
            if (const int l = b_.indexOf(leaf.origin); l >= 0)
                leafwords::unite(movedOf[std::size_t(l)], leaf.words);
        stencilMoved_.resize(b_.leafCount());
        parallelFor(std::size_t(0), b_.leafCount(), [&](std::size_t l) {
            stencilMoved_[l] =
                movedOf[l] | nextTo(false, [&](auto a, int dir, Bits& out, Bits& valid) {
                    b_.stepped<decltype(a)::value>(movedOf.data(), l, dir, out, valid);
                });
        });
    }

    // Which of two classes leaf l belongs to, by the parity of the sum of its position (a
    // checkerboard): leaves of one class never share a face, and a block reads only its leaf
    // and the faces of its neighbours, so the leaves of a class are solved in parallel. (The
    // eight classes of the parities along each axis would wait at eight barriers a round
    // where two do.)
    int classOf(std::size_t l) const {
        const openvdb::Coord o = b_.leaf(l).origin() >> Leaf::LOG2DIM;
        return (o.x() + o.y() + o.z()) & 1;
    }

    // Copies leaf l and `rim` layers of its face neighbours (1 or 2) into the block.
    void load(std::size_t l, int rim, Block& block) const {
        const int axis = layout_[l] & 3;
        block.setRowAxis(axis);
        if (axis == 2)
            loadAs<2>(l, rim, block);
        else if (axis == 1)
            loadAs<1>(l, rim, block);
        else
            loadAs<0>(l, rim, block);
    }

    // load() for a block whose rows run along leaf axis RowAxis: the block is written four
    // values at a time, read by fixed strides, each voxel's side taken from the sign of its
    // value, so that filling a block costs a few instructions per four voxels rather than a
    // bit test and two selects per voxel.
    template <int RowAxis> void loadAs(std::size_t l, int rim, Block& block) const {
        using Index = std::ptrdiff_t; // offsets into the block and the leaves
        constexpr Index R = Block::kRim;
        // The leaf axes along the block's axes, and their strides in a leaf (Block::setRowAxis).
        constexpr int kAxes[3] = {RowAxis == 0 ? 2 : 0, RowAxis == 1 ? 2 : 1, RowAxis};
        constexpr Index kLeafStride[3] = {Index(1) << (6 - 3 * kAxes[0]),
                                          Index(1) << (6 - 3 * kAxes[1]),
                                          Index(1) << (6 - 3 * kAxes[2])};
        constexpr Index S0 = Block::kStride[0], S1 = Block::kStride[1];
        float* in = block.side[1].data();
        float* out = block.side[0].data();
        using F = Floats4;
        using I = Lanes4;
        // Four stored distances, from d on by `stride`, as the two sides hold them: each side
        // the voxels of its sign, read from the sign bit as a mask, and +infinity for the
        // others.
        const auto sides = [](const float* d, Index stride, F& inside, F& outside) {
            const F v = {d[0], d[stride], d[2 * stride], d[3 * stride]};
            const I bits = reinterpret_cast<I>(v), signBit = bits < 0;
            const I infinity = reinterpret_cast<I>(F{} + kInf), distance = bits & 0x7fffffff;
            inside = reinterpret_cast<F>((distance & signBit) | (infinity & ~signBit));
            outside = reinterpret_cast<F>((infinity & signBit) | (distance & ~signBit));
        };
        // Eight voxels of the block from b on by `step`, from d on by `stride` in a leaf.
        const auto put = [&](const float* d, Index stride, Index b, Index step) {
            for (Index k = 0; k < 8; k += 4) {
                F sideIn, sideOut;
                sides(d + k * stride, stride, sideIn, sideOut);
                if (step == 1) {
                    std::memcpy(in + b + k, &sideIn, sizeof sideIn);
                    std::memcpy(out + b + k, &sideOut, sizeof sideOut);
                    continue;
                }
                for (Index n = 0; n < 4; ++n) {
                    in[b + (k + n) * step] = sideIn[n];
                    out[b + (k + n) * step] = sideOut[n];
                }
            }
        };
        const auto far = [&](Index b, Index step) {
            for (Index k = 0; k < 8; ++k)
                in[b + k * step] = out[b + k * step] = kInf;
        };
        const float* own = &dist_[l << 9];
        for (Index i = 0; i < 8; ++i)
            for (Index j = 0; j < 8; ++j)
                put(own + i * kLeafStride[0] + j * kLeafStride[1], kLeafStride[2],
                    (i + R) * S0 + (j + R) * S1 + R, 1);
        // The rims: for each face, `rim` layers of the leaf across it (or +infinity where
        // none is), eight voxels at a time along a row, or across the rows for the faces the
        // rows end at.
        forEachAxis([&](auto axis) {
            constexpr int a = decltype(axis)::value; // a block axis
            // The block and leaf strides of the layer's two axes, p (outer) and q.
            constexpr Index bp = a == 0 ? S1 : S0, bq = a == 2 ? S1 : 1;
            constexpr Index lp = kLeafStride[a == 0 ? 1 : 0], lq = kLeafStride[a == 2 ? 1 : 2];
            constexpr Index ba = Block::kStride[a], la = kLeafStride[a];
            for (int up = 0; up < 2; ++up) {
                const int nl = b_.neighbourLeaf(l, 2 * kAxes[a] + up);
                const float* from = nl < 0 ? nullptr : &dist_[std::size_t(nl) << 9];
                for (int t = 1; t <= rim; ++t) {
                    // The block layer `at` takes the neighbour's layer `src`.
                    const Index at = (up ? 7 + t : -t) + R, src = up ? t - 1 : 8 - t;
                    for (Index p = 0; p < 8; ++p) {
                        const Index b = at * ba + (p + R) * bp + R * bq;
                        if (from)
                            put(from + src * la + p * lp, lq, b, bq);
                        else
                            far(b, bq);
                    }
                }
            }
        });
    }

    // 2. Solve the upwind equations for every other voxel of the region, leaf by leaf, in
    //    the manner of the fast iterative method: each leaf is solved on its own, its border
    //    values taken from its neighbours as they stand, and a leaf whose border changed hands
    //    the voxels next to it to its neighbours, which are solved again, until nothing
    //    changes. Within a leaf, sweeps over its rows solve eight voxels at once until no
    //    value moves (settle); a voxel solved in the order of the values, as fast marching
    //    does, waits on the one before it, each update a long chain of a square root and a
    //    division, where the eight lanes of a row proceed together. Both sides are solved at
    //    once (an update reads only its own side). Everything a leaf reads is in a block
    //    small enough for the first-level cache, where fast marching's single front sweeps
    //    the whole region and misses the cache at nearly every voxel.
    void solve() {
        const std::size_t leaves = b_.leafCount();
        const int reach = order_ == UpwindOrder::Second ? 2 : 1; // how far a stencil reads
        std::array<std::vector<std::size_t>, 2> classes;
        for (std::size_t l = 0; l < leaves; ++l)
            classes[std::size_t(classOf(l))].push_back(l);
        // Per leaf: the voxels handed in by its neighbours (a word per x, as Bits), and
        // whether it is to be solved.
        std::unique_ptr<std::atomic<std::uint64_t>[]> inbox(
            new std::atomic<std::uint64_t>[leaves * 8]());
        std::unique_ptr<std::atomic<bool>[]> pending(new std::atomic<bool>[leaves]());
        // Every leaf with free voxels is solved (the first time, all of them).
        forEachLeaf([&](std::size_t l) {
            bool free = false;
            for (int x = 0; x < 8; ++x)
                free |= ~settled_[l][x] != 0;
            pending[l] = free;
        });
        tbb::enumerable_thread_specific<Block> blocks;
        std::vector<std::uint8_t> seen(leaves, 0); // solved once: later only what is handed in
        for (int round = 0, again = 1; again && round < kMostRounds; ++round) {
            for (const auto& leavesOfClass : classes) {
                pollInterrupt(interrupter_);
                parallelFor(
                    tbb::blocked_range<std::size_t>(0, leavesOfClass.size(),
                                                    grainFor(leavesOfClass.size(), 4)),
                    [&](const auto& r) {
                        Block& block = blocks.local();
                        for (std::size_t q = r.begin(); q != r.end(); ++q) {
                            const std::size_t l = leavesOfClass[q];
                            if (!pending[l].exchange(false)) continue;
                            const bool first = !seen[l];
                            seen[l] = 1;
                            Bits handed;
                            for (int x = 0; x < 8; ++x)
                                handed[x] =
                                    inbox[l * 8 + std::size_t(x)].exchange(0) & ~settled_[l][x];
                            load(l, reach, block);
                            Bits left;
                            const Bits changed = settle(l, handed, first, reach, block, left);
                            // What a leaf could not finish waits for the next round.
                            for (int x = 0; x < 8; ++x)
                                if (left[x]) {
                                    inbox[l * 8 + std::size_t(x)] |= left[x];
                                    pending[l] = true;
                                }
                            handOn(l, changed, block, reach, seen, inbox.get(), pending.get());
                            forEachBit(changed, [&](int off) {
                                const bool inside = isSet(neg_[l], off);
                                dist_[(l << 9) + std::size_t(off)] = signedAs(
                                    inside, block.side[inside][std::size_t(block.at(off))]);
                            });
                        }
                    });
            }
            again = 0;
            for (std::size_t l = 0; l < leaves && !again; ++l)
                again = pending[l];
        }
    }

    // Solves the free voxels of leaf l (loaded in `block`) until their values hold: all of
    // them the first time the leaf is solved, later those handed in. A sweep takes the block's
    // rows that hold voxels to solve, eight voxels at once (upwind::relaxRow), each side in the
    // direction its distances grow, each row reading the values of the rows before it as they
    // now stand; the next sweep takes the voxels whose stencils read a value that moved. Returns
    // the voxels whose values moved; `left` gets those still to solve after kMostSweeps sweeps.
    Bits settle(std::size_t l, const Bits& handed, bool first, int reach, Block& block,
                Bits& left) const {
        // Voxel sets in the block's order (readers() treats every axis alike).
        const int axis = block.rowAxis;
        const Bits inside = inBlockOrder(neg_[l], axis),
                   solvable = inBlockOrder(~settled_[l], axis);
        upwind::RowBlock rows[2];
        for (int side = 0; side < 2; ++side)
            rows[side] = {block.side[std::size_t(side)].data(),
                          Block::kStride[0],
                          Block::kStride[1],
                          h_,
                          bg_,
                          kSolveTolerance * h_,
                          reach};
        Bits todo = first ? solvable : inBlockOrder(handed, axis) & solvable, changed{};
        left = Bits{};
        // Each side in the direction its distances grow, every sweep: the values travel the
        // way the distances do, so turning the directions in turn, as fast sweeping does,
        // spends sweeps going against them.
        const unsigned outward = unsigned(layout_[l]) >> 2;
        for (int sweep = 0; sweep < kMostSweeps; ++sweep) {
            Bits moved{};
            bool anyMoved = false;
            // The rows of each side holding voxels to solve, in its order.
            std::array<std::array<std::uint8_t, 64>, 2> list;
            std::array<int, 2> count{0, 0};
            for (int side = 0; side < 2; ++side) {
                const unsigned flip = side ? outward ^ 3u : outward;
                for (int a = 0; a < 8; ++a) {
                    const int i = flip & 1u ? 7 - a : a;
                    const leafwords::Word mine =
                        side ? inside[std::size_t(i)] : ~inside[std::size_t(i)];
                    for (leafwords::Word filled = nonzeroBytes(todo[std::size_t(i)] & mine);
                         filled;) {
                        const int bit =
                            flip & 2u ? 63 - __builtin_clzll(filled) : __builtin_ctzll(filled);
                        filled &= ~(leafwords::Word(1) << bit);
                        list[std::size_t(side)][std::size_t(count[std::size_t(side)]++)] =
                            std::uint8_t(i * 8 + bit / 8);
                    }
                }
            }
            // The two sides' rows in turn: their updates do not depend on each other, so one
            // row's chain of operations overlaps the other's.
            for (int q = 0; q < std::max(count[0], count[1]); ++q)
                for (int side = 0; side < 2; ++side) {
                    if (q >= count[std::size_t(side)]) continue;
                    const int row = list[std::size_t(side)][std::size_t(q)], i = row >> 3;
                    const int shift = 8 * (row & 7);
                    const leafwords::Word mine =
                        side ? inside[std::size_t(i)] : ~inside[std::size_t(i)];
                    const unsigned free =
                        unsigned((solvable[std::size_t(i)] & mine) >> shift) & 0xffu;
                    constexpr int R = Block::kRim;
                    const int b =
                        (i + R) * Block::kStride[0] + ((row & 7) + R) * Block::kStride[1] + R;
                    // The whole row of the side: its other solvable voxels read the same values.
                    const unsigned m = relax_(rows[side], b, free);
                    moved[std::size_t(i)] |= std::uint64_t(m) << shift;
                    anyMoved |= m != 0;
                }
            if (!anyMoved) {
                todo = Bits{};
                break;
            }
            changed = changed | moved;
            todo = readers(moved, reach) & solvable;
        }
        left = leafwords::any(todo) ? inBlockOrder(todo, axis) : Bits{};
        return inBlockOrder(changed, axis);
    }

    // Hands to l's neighbours the voxels whose stencils may read a voxel of l that changed:
    // those of its side within `reach` steps along an axis (with no voxel of the other side
    // between), whose values lie above the changed voxel's old or new value. A stencil only
    // reads neighbours below the value it solves for, so the others would solve to what they
    // hold. Called before the changed values are written back (dist_ holds the old ones);
    // the neighbours are of another class, so nothing writes them meanwhile. The layers on
    // either side of a face are compared as planes of 64 bits, and only the voxels this
    // leaves have their values compared (rather than walking each changed voxel's steps a
    // bit test at a time), without a branch on each comparison. A neighbour not solved yet
    // (`seen`) gets nothing: its first solve takes all its free voxels anyway, and in the
    // first round most neighbours are such.
    void handOn(std::size_t l, const Bits& changed, const Block& block, int reach,
                const std::vector<std::uint8_t>& seen, std::atomic<std::uint64_t>* inbox,
                std::atomic<bool>* pending) const {
        std::array<Bits, 6> into{};
        // Voxel `off` of l as it reads its neighbours: the lower of its new and old values.
        const auto low = [&](int off) {
            const bool side = isSet(neg_[l], off);
            return std::min(block.side[side][std::size_t(block.at(off))],
                            std::abs(dist_[(l << 9) + std::size_t(off)]));
        };
        forEachAxis([&](auto a) {
            constexpr int A = decltype(a)::value;
            for (const int dir : {-1, 1}) {
                const int k = 2 * A + (dir > 0);
                const int nl = b_.neighbourLeaf(l, k);
                if (nl < 0 || !seen[std::size_t(nl)]) continue;
                // The layers along the axis, as planes of 64 bits: l's at its face (0) and one
                // in (1), the neighbour's facing it (0) and one in (1).
                const int own0 = dir > 0 ? 7 : 0, own1 = own0 - dir;
                const int next0 = 7 - own0, next1 = next0 + dir;
                const Bits& nextNeg = neg_[std::size_t(nl)];
                const Word in0 = plane<A>(neg_[l], own0), across0 = plane<A>(nextNeg, next0);
                // Changed voxels at the face and the neighbours one step on, of their side...
                const Word oneStep = plane<A>(changed, own0) & ~(in0 ^ across0);
                Word twoSteps = 0, fromInside = 0;
                if (reach > 1) {
                    // ... two steps on, with nothing of the other side between ...
                    twoSteps = oneStep & ~(in0 ^ plane<A>(nextNeg, next1));
                    // ... and from one layer in, two steps on, through the face layer.
                    const Word in1 = plane<A>(neg_[l], own1);
                    fromInside = plane<A>(changed, own1) & ~(in1 ^ in0) & ~(in1 ^ across0);
                }
                Bits& to = into[std::size_t(k)];
                // A neighbour is handed in where its value lies above what it would read.
                const auto above = [&](int n, float value) {
                    return std::abs(dist_[(std::size_t(nl) << 9) + std::size_t(n)]) > value;
                };
                for (Word w = oneStep | fromInside; w; w &= w - 1) {
                    const int bit = __builtin_ctzll(w), n = inPlane<A>(next0, bit);
                    const bool one = ((oneStep >> bit) & 1) & above(n, low(inPlane<A>(own0, bit)));
                    const bool in =
                        ((fromInside >> bit) & 1) & above(n, low(inPlane<A>(own1, bit)));
                    to[std::size_t(n) >> 6] |= Word(one | in) << (n & 63);
                }
                for (Word w = twoSteps; w; w &= w - 1) {
                    const int bit = __builtin_ctzll(w), n = inPlane<A>(next1, bit);
                    to[std::size_t(n) >> 6] |= Word(above(n, low(inPlane<A>(own0, bit))))
                                               << (n & 63);
                }
            }
        });
        for (int k = 0; k < 6; ++k) {
            const int nl = b_.neighbourLeaf(l, k);
            if (nl < 0) continue;
            bool any = false;
            for (int x = 0; x < 8; ++x)
                if (into[std::size_t(k)][std::size_t(x)]) {
                    inbox[std::size_t(nl) * 8 + std::size_t(x)] |=
                        into[std::size_t(k)][std::size_t(x)];
                    any = true;
                }
            if (any) pending[nl] = true;
        }
    }

    // 3. Write back: inside the band active with the new distance, beyond it off. Every
    //    voxel lives in an existing leaf, so leaves are written in parallel. Returns how many
    //    voxels the solve gave a distance within the band (seeds excluded).
    std::size_t writeBack() {
        tbb::enumerable_thread_specific<std::size_t> solved(0);
        emptied_.assign(b_.leafCount(), 0);
        parallelFor(std::size_t(0), b_.leafCount(), [&](std::size_t l) {
            // Only the free voxels, straight into the leaf's buffer and its mask a word at a
            // time (most of a domain is boundary; a setValueOn per voxel checked whether the
            // buffer was in memory every time). Four voxels at once: each distance capped at
            // the background, keeping its sign (its side: signedAs), and kept where the voxel
            // is not free.
            using F = Floats4;
            using I = Lanes4;
            const I laneBit = {1, 2, 4, 8}, signBit = I{} + std::numeric_limits<int>::min();
            const F bg = F{} + bg_;
            Leaf& leaf = b_.leaf(l);
            float* values = leaf.buffer().data();
            auto& mask = leaf.getValueMask();
            const float* dist = &dist_[l << 9];
            std::size_t n = 0;
            for (int x = 0; x < 8; ++x) {
                const std::uint64_t free = ~fixed_[l][std::size_t(x)];
                if (!free) continue;
                std::uint64_t band = 0; // the free voxels within the band
                for (int k = 0; k < 64; k += 4) {
                    if (!((free >> k) & 15u)) continue;
                    const std::ptrdiff_t at = std::ptrdiff_t(x) * 64 + k;
                    float* const to = values + at;
                    F d, was;
                    std::memcpy(&d, dist + at, sizeof d);
                    std::memcpy(&was, to, sizeof was);
                    const I bits = reinterpret_cast<I>(d);
                    const F a = reinterpret_cast<F>(bits & ~signBit);
                    const I within = a < bg;
                    const I mine = ((I{} + int((free >> k) & 15u)) & laneBit) != 0;
                    const F capped = within ? a : bg;
                    const F v = reinterpret_cast<F>(reinterpret_cast<I>(capped) | (bits & signBit));
                    const F out = mine ? v : was;
                    std::memcpy(to, &out, sizeof out);
                    band |= std::uint64_t(
                                unsigned(_mm_movemask_ps(reinterpret_cast<__m128>(within & mine))))
                            << k;
                }
                auto& on = mask.getWord<std::uint64_t>(x);
                on = (on & ~free) | band;
                n += std::size_t(__builtin_popcountll(band & ~settled_[l][std::size_t(x)]));
            }
            solved.local() += n;
            emptied_[l] = mask.isOff();
        });
        return solved.combine(std::plus<>());
    }

    const Domain b_;
    const upwind::RowRelaxer relax_ = upwind::rowRelaxer();
    const std::size_t n_;
    const float h_, bg_;
    const UpwindOrder order_;
    const Seeding seeding_;
    // Per leaf: the gradient norms its values had before the deformation
    // (RenormalizeOptions::gradientBefore), or null.
    std::vector<const float*> gradientBefore_;
    Interrupter* const interrupter_;
    // Per leaf: its values (the grid's, as they were sampled).
    std::vector<const float*> phi_;
    // Every entry is written by the constructor's parallel loop over the leaves, so this is
    // allocated without the serial zeroing of a std::vector, which would run on one thread.
    // The distance found so far (kInf: none yet), with its voxel's sign (signedAs).
    std::unique_ptr<float[]> dist_;
    // Per leaf: the voxels on or next to a feature one voxel thin (flagThin).
    std::vector<Bits> thin_;
    // Per leaf: the voxels inside, the fixed ones (outside the region: boundary values), and
    // those settled before the solve (fixed, and the seeds).
    // (Allocated without the serial zeroing of a std::vector: the constructor's parallel
    // loops write every entry.)
    std::unique_ptr<Bits[]> neg_, fixed_, settled_;
    // Per leaf: the inactive voxels next to free ones, free so that the band can grow into
    // them.
    std::unique_ptr<Bits[]> beyond_;
    // Per leaf: the voxels whose seed inputs moved (findStencilsMoved); empty when every seed
    // is recomputed.
    std::vector<Bits> stencilMoved_;
    // Per leaf: how its block is laid out and swept (layoutOf).
    std::vector<std::uint8_t> layout_;
    // Per leaf: whether the write-back left it without an active voxel.
    std::vector<char> emptied_;
};

} // namespace

RenormalizeStats renormalize(Grid& grid, const RenormalizeOptions& options) {
    openvdb::CoordBBox region;
    if (options.region) {
        region = *options.region;
    } else {
        region = grid.evalActiveVoxelBoundingBox();
        if (region.empty()) return {};
        region.expand(2);
    }
    if (region.empty()) return {};
    pollInterrupt(options.interrupter);
    Renormalizer renormalizer(grid, region, options);
    const RenormalizeStats stats = renormalizer.run(grid);
    // The whole grid: its internal nodes too.
    if (!options.region) openvdb::tools::pruneLevelSet(grid.tree());
    return stats;
}

} // namespace sweepers
