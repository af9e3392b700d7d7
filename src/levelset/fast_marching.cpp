#include "levelset/fast_marching.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include <openvdb/tools/Prune.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "levelset/local_tree.h"

namespace sweepers {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kUnitSlack = 0.01;

enum State : std::uint8_t { Far = 0, Trial = 1, Known = 2, Fixed = 3 };

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
// surface and are not needed.
class Domain {
  public:
    static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();

    Domain(Grid& grid, const openvdb::CoordBBox& region, int margin) {
        openvdb::CoordBBox outer = region;
        outer.expand(margin);
        leaves_ = leavesIn(grid.tree(), outer);
        std::unordered_map<openvdb::Coord, int> index;
        index.reserve(leaves_.size());
        for (std::size_t l = 0; l < leaves_.size(); ++l)
            index[leaves_[l]->origin()] = int(l);
        neighbours_.resize(leaves_.size());
        for (std::size_t l = 0; l < leaves_.size(); ++l)
            for (int a = 0; a < 3; ++a)
                for (int d = 0; d < 2; ++d) {
                    openvdb::Coord o = leaves_[l]->origin();
                    o[a] += d ? Leaf::DIM : -int(Leaf::DIM);
                    auto it = index.find(o);
                    neighbours_[l][2 * a + d] = it == index.end() ? -1 : it->second;
                }
    }

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
    using Bits = std::array<std::uint64_t, 8>;

    // `out` gets, for each voxel of leaf l, the bit of its neighbour one step along axis A
    // (dir = +-1) in `sets` (one Bits per leaf); `valid` gets the voxels that have such a
    // neighbour in the domain (0 where it would lie in a leaf outside it).
    template <int A>
    void stepped(const std::vector<Bits>& sets, std::size_t l, int dir, Bits& out,
                 Bits& valid) const {
        constexpr std::uint64_t z0 = 0x0101010101010101ull, z7 = z0 << 7;
        constexpr std::uint64_t y0 = 0xffull, y7 = y0 << 56;
        const Bits& w = sets[l];
        const int nl = neighbours_[l][2 * A + (dir > 0)];
        const Bits* n = nl < 0 ? nullptr : &sets[std::size_t(nl)];
        for (int x = 0; x < 8; ++x) {
            if constexpr (A == 2) { // z: within rows of eight bits
                out[x] = dir > 0 ? ((w[x] >> 1) & ~z7) | (n ? ((*n)[x] & z0) << 7 : 0)
                                 : ((w[x] << 1) & ~z0) | (n ? ((*n)[x] & z7) >> 7 : 0);
                valid[x] = n ? ~0ull : ~(dir > 0 ? z7 : z0);
            } else if constexpr (A == 1) { // y: rows of a word
                out[x] = dir > 0 ? (w[x] >> 8) | (n ? ((*n)[x] & y0) << 56 : 0)
                                 : (w[x] << 8) | (n ? (*n)[x] >> 56 : 0);
                valid[x] = n ? ~0ull : ~(dir > 0 ? y7 : y0);
            } else { // x: words of a leaf
                const int t = x + dir;
                const bool inside = t >= 0 && t < 8;
                out[x] = inside ? w[std::size_t(t)] : (n ? (*n)[dir > 0 ? 0 : 7] : 0);
                valid[x] = inside || n ? ~0ull : 0;
            }
        }
    }

  private:
    std::vector<Leaf*> leaves_;
    std::vector<std::array<int, 6>> neighbours_;
};

using Bits = Domain::Bits;

// Calls visit(offset) for every voxel of a leaf whose bit is set.
template <typename Visit> void forEachBit(const Bits& bits, const Visit& visit) {
    for (int x = 0; x < 8; ++x)
        for (std::uint64_t w = bits[x]; w; w &= w - 1)
            visit(x * 64 + __builtin_ctzll(w));
}

bool negative(float v) {
    return v < 0.0f;
}

// Solves sum_a c_a (u - m_a)^2 = h^2 for the largest root, using axes in increasing m_a
// while the root stays above them.
float solveUpwind(float m[3], float c[3], int n, float h) {
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j)
            if (m[j] < m[i]) {
                std::swap(m[i], m[j]);
                std::swap(c[i], c[j]);
            }
    float u = m[0] + h / std::sqrt(c[0]);
    for (int k = 2; k <= n; ++k) {
        if (u <= m[k - 1]) break;
        double A = 0, B = 0, C = -double(h) * h;
        for (int a = 0; a < k; ++a) {
            A += c[a];
            B += -2.0 * c[a] * m[a];
            C += c[a] * double(m[a]) * m[a];
        }
        const double disc = B * B - 4 * A * C;
        if (disc < 0) break;
        const float root = float((-B + std::sqrt(disc)) / (2 * A));
        if (root < m[k - 1]) break;
        u = root;
    }
    return u;
}

// A heap entry: the value's bits above the voxel index. Values are never negative, and
// the bits of non-negative floats order as the floats do, so one integer comparison
// orders entries by value, then by index.
using Entry = std::uint64_t;
Entry entry(float v, std::size_t i) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    return (Entry(bits) << 32) | Entry(i);
}
std::size_t indexOf(Entry e) {
    return std::size_t(e & 0xffffffffu);
}

// The queue of trial voxels: entries leave in increasing order, as from a binary heap.
// Fast marching nearly always pushes values at least as large as the last one popped (an
// upwind solution is no smaller than the values it uses), so most entries go to a radix
// heap on the values, whose buckets are plain vectors: pushes and pops touch memory in order
// instead of sifting through a large binary heap. The exception is a second-order stencil
// that became available after a voxel's last update (a neighbour's neighbour was accepted)
// and lowers its value below the front: such entries wait in a small binary heap of their
// own, which is emptied first.
class MarchQueue {
  public:
    explicit MarchQueue(const std::vector<Entry>& items) {
        for (const Entry e : items)
            push(e);
    }
    bool empty() const { return below_.empty() && size_ == 0; }
    void push(Entry e) {
        if (valueBits(e) < last_) {
            pushHeap(below_, e);
            return;
        }
        const int b = bucketOf(e);
        if (b == 0)
            pushHeap(buckets_[0], e); // ties leave in index order
        else
            buckets_[b].push_back(e);
        ++size_;
    }
    Entry pop() {
        if (!below_.empty()) return popHeap(below_);
        auto& ties = buckets_[0];
        if (ties.empty()) {
            int b = 1;
            while (buckets_[b].empty())
                ++b;
            // Every entry of the first non-empty bucket agrees with the smallest of them above
            // the highest bit in which it differs from the last value popped, so measured from
            // that smallest value they all land in lower buckets.
            last_ = valueBits(*std::min_element(buckets_[b].begin(), buckets_[b].end()));
            for (const Entry e : buckets_[b])
                buckets_[bucketOf(e)].push_back(e);
            buckets_[b].clear();
            std::make_heap(ties.begin(), ties.end(), std::greater<>());
        }
        --size_;
        return popHeap(ties);
    }

  private:
    static std::uint32_t valueBits(Entry e) { return std::uint32_t(e >> 32); }
    int bucketOf(Entry e) const {
        const std::uint32_t v = valueBits(e);
        return v == last_ ? 0 : 32 - __builtin_clz(v ^ last_);
    }
    static void pushHeap(std::vector<Entry>& heap, Entry e) {
        heap.push_back(e);
        std::push_heap(heap.begin(), heap.end(), std::greater<>());
    }
    static Entry popHeap(std::vector<Entry>& heap) {
        std::pop_heap(heap.begin(), heap.end(), std::greater<>());
        const Entry e = heap.back();
        heap.pop_back();
        return e;
    }
    std::array<std::vector<Entry>, 33> buckets_; // bucket b: values whose highest bit
                                                 // differing from last_ is bit b - 1
    std::vector<Entry> below_;
    std::uint32_t last_ = 0; // the value bits of the last entry taken from the buckets
    std::size_t size_ = 0;   // entries in the buckets
};

// Heap pops between two polls of the interrupter.
constexpr std::size_t kPollEvery = 1 << 14;

// Queue entries hold a voxel's index in 32 bits.
std::size_t indexable(std::size_t voxels) {
    if (voxels >= (std::size_t(1) << 32))
        throw std::length_error("renormalization: the region holds too many voxels");
    return voxels;
}

class Marcher {
  public:
    Marcher(Grid& grid, const openvdb::CoordBBox& region, const openvdb::MaskGrid* only,
            FmmOrder order, Interrupter* interrupter)
        : b_(grid, region, 2), n_(indexable(b_.size())), h_(float(grid.voxelSize()[0])),
          bg_(grid.background()), order_(order), interrupter_(interrupter), phi_(new float[n_]),
          cells_(new Cell[n_]), thin_(new std::uint8_t[n_]), neg_(b_.leafCount(), Bits{}),
          settled_(b_.leafCount(), Bits{}) {
        // Voxels outside the region (or outside `only`) are boundary: they keep their values.
        tbb::parallel_for(std::size_t(0), b_.leafCount(), [&](std::size_t l) {
            const Leaf& leaf = b_.leaf(l);
            const bool whole = region.isInside(leaf.getNodeBoundingBox());
            const auto* mask = only ? only->tree().probeConstLeaf(leaf.origin()) : nullptr;
            std::memset(&thin_[l << 9], 0, kLeafVoxels);
            for (int off = 0; off < kLeafVoxels; ++off) {
                const std::size_t i = (l << 9) + off;
                const float p = leaf.getValue(off);
                phi_[i] = p;
                const bool inRegion = (whole || region.isInside(leaf.offsetToGlobalCoord(off))) &&
                                      (!only || (mask && mask->isValueOn(off)));
                cells_[i] = {inRegion ? kInf : std::abs(p), inRegion ? Far : Fixed, negative(p)};
                const std::uint64_t bit = std::uint64_t(1) << (off & 63);
                if (negative(p)) neg_[l][off >> 6] |= bit;
                if (!inRegion) settled_[l][off >> 6] |= bit;
            }
        });
    }

    FmmStats run(const openvdb::CoordBBox& region, Grid& grid) {
        FmmStats stats;
        flagThin();
        stats.seeds = seed();
        pollInterrupt(interrupter_);
        std::size_t marched[2] = {0, 0};
        tbb::parallel_invoke([&] { marched[0] = march(false); }, [&] { marched[1] = march(true); });
        stats.marched = marched[0] + marched[1];
        pollInterrupt(interrupter_); // the last chance: nothing has been written yet
        writeBack();
        openvdb::CoordBBox written = region;
        written.expand(2);
        pruneEmptyLeavesIn(grid.tree(), written);
        stats.leaves = b_.leafCount();
        return stats;
    }

  private:
    // Runs visit(leaf) for every leaf of the domain, in parallel.
    template <typename Visit> void forEachLeaf(const Visit& visit) const {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, b_.leafCount()), [&](const auto& r) {
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
            b_.stepped<decltype(a)::value>(neg_, l, dir, out, valid);
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
                thin_[i] = 1;
                found.local().push_back(i);
            });
        });
        std::vector<std::size_t> ring;
        for (const auto& f : found)
            ring.insert(ring.end(), f.begin(), f.end());
        for (std::uint8_t r = 2; r <= 3; ++r) {
            std::vector<std::size_t> next;
            for (const std::size_t i : ring)
                forEachAxis([&](auto a) {
                    for (const int dir : {-1, 1}) {
                        const std::size_t j = b_.neighbour(i, dir, a);
                        if (j == Domain::npos || thin_[j]) continue;
                        thin_[j] = r;
                        next.push_back(j);
                    }
                });
            ring = std::move(next);
        }
    }

    // 1. Seeds (voxels with a face neighbour across the surface): phi / |grad phi| with
    //    central differences, which turns a sampled field that is no longer a distance back
    //    into one to second order where the field is smooth, capped by the distance to the
    //    nearest axis crossing (the surface is no farther). The sign is always kept.
    std::size_t seed() {
        tbb::enumerable_thread_specific<std::size_t> count(0);
        const float h = h_;
        const auto seedOne = [&](std::size_t i) {
            const float p = phi_[i];
            double inv2 = 0.0, grad2 = 0.0;
            float nearestCrossing = kInf;
            bool crossing = false, central = true;
            forEachAxis([&](auto a) {
                float best = kInf;
                float side[2] = {p, p};
                for (const int dir : {-1, 1}) {
                    const std::size_t j = b_.neighbour(i, dir, a);
                    if (j == Domain::npos) {
                        central = false;
                        continue;
                    }
                    const float q = phi_[j];
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
            if (!crossing) return;
            float d;
            if (!central || thin_[i] != 0) {
                // On or next to a feature about one voxel thin (the surface on both sides along
                // an axis) no gradient estimate is trustworthy, so the value is kept:
                // recomputing it would move its crossings a little every time and let the
                // feature drift.
                d = std::min(std::abs(p), h);
            } else if (grad2 > 1e-12 * double(h) * h) {
                const double gradNorm = std::sqrt(grad2) / h;
                // A value whose gradient is already unit within kUnitSlack is a distance: kept,
                // so that renormalizing a renormalized grid changes nothing and nothing drifts.
                d = std::abs(gradNorm - 1.0) < kUnitSlack
                        ? std::abs(p)
                        : std::min(float(std::abs(p) / gradNorm), nearestCrossing * h);
            } else {
                d = float(h / std::sqrt(inv2)); // distance to the plane through the crossings
            }
            cells_[i].u = d;
            cells_[i].state = Known;
            ++count.local();
        };
        // Only voxels with a face neighbour across the surface can be seeds.
        forEachLeaf([&](std::size_t l) {
            Bits candidates = acrossSurface(l, false);
            for (int x = 0; x < 8; ++x)
                candidates[x] &= ~settled_[l][x];
            forEachBit(candidates, [&](int off) {
                const std::size_t i = (l << 9) + std::size_t(off);
                seedOne(i);
                if (cells_[i].state == Known)
                    settled_[l][std::size_t(off) >> 6] |= std::uint64_t(1) << (off & 63);
            });
        });
        return count.combine(std::plus<>());
    }

    // The upwind value of voxel i from its known neighbours of its own side, or kInf.
    float upwind(std::size_t i, bool side) const {
        float m[3], c[3];
        int k = 0;
        forEachAxis([&](auto a) {
            float best = kInf, second = kInf;
            for (const int dir : {-1, 1}) {
                const std::size_t j = b_.neighbour(i, dir, a);
                if (j == Domain::npos || cells_[j].neg != side || cells_[j].state < Known) continue;
                if (cells_[j].u < best) {
                    best = cells_[j].u;
                    second = kInf;
                    if (order_ == FmmOrder::Second) {
                        const std::size_t j2 = b_.neighbour(j, dir, a);
                        if (j2 != Domain::npos && cells_[j2].neg == side &&
                            cells_[j2].state >= Known && cells_[j2].u <= cells_[j].u)
                            second = cells_[j2].u;
                    }
                }
            }
            if (best == kInf) return;
            if (second < kInf) {
                m[k] = (4.0f * best - second) / 3.0f; // (3u - 4u1 + u2) / 2h
                c[k] = 2.25f;
            } else {
                m[k] = best;
                c[k] = 1.0f;
            }
            ++k;
        });
        return k == 0 ? kInf : solveUpwind(m, c, k, h_);
    }

    // 2. March from every known or fixed voxel in increasing distance. A voxel's update only
    //    reads neighbours of its own sign, so the inside and the outside march at once.
    std::size_t march(const bool side) {
        // Values past the band's half-width are never queued: such a voxel would end up
        // outside the band whatever its value, and every value computed from it would be past
        // the half-width too (an upwind solution is at least each value it uses), so leaving
        // it far changes no value inside the band.
        const float limit = bg_;
        // The first trial values: every far voxel of this side next to a known or fixed one.
        // They read only known and fixed voxels, which do not change meanwhile, so they are
        // found in parallel and queued at once.
        // Only far voxels of this side next to a known or fixed one of this side have one.
        std::vector<Bits> sources(b_.leafCount());
        forEachLeaf([&](std::size_t l) {
            for (int x = 0; x < 8; ++x)
                sources[l][x] = settled_[l][x] & (side ? neg_[l][x] : ~neg_[l][x]);
        });
        tbb::enumerable_thread_specific<std::vector<Entry>> first;
        forEachLeaf([&](std::size_t l) {
            Bits candidates = nextTo(false, [&](auto a, int dir, Bits& out, Bits& valid) {
                b_.stepped<decltype(a)::value>(sources, l, dir, out, valid);
            });
            for (int x = 0; x < 8; ++x)
                candidates[x] &= ~settled_[l][x] & (side ? neg_[l][x] : ~neg_[l][x]);
            auto& out = first.local();
            forEachBit(candidates, [&](int off) {
                const std::size_t i = (l << 9) + std::size_t(off);
                const float v = upwind(i, side);
                if (v > limit) return;
                cells_[i].u = v;
                cells_[i].state = Trial;
                out.push_back(entry(v, i));
            });
        });
        std::vector<Entry> items;
        for (const auto& f : first)
            items.insert(items.end(), f.begin(), f.end());
        MarchQueue heap(items);

        std::size_t marched = 0, pops = 0;
        while (!heap.empty()) {
            const Entry e = heap.pop();
            if (++pops % kPollEvery == 0) pollInterrupt(interrupter_);
            const std::size_t i = indexOf(e);
            if (cells_[i].state != Trial || e != entry(cells_[i].u, i)) continue; // a stale entry
            cells_[i].state = Known;
            ++marched;
            forEachAxis([&](auto a) {
                for (const int dir : {-1, 1}) {
                    const std::size_t j = b_.neighbour(i, dir, a);
                    if (j == Domain::npos || cells_[j].neg != side || cells_[j].state >= Known)
                        continue;
                    const float v = upwind(j, side);
                    if (v < cells_[j].u && v <= limit) {
                        cells_[j].u = v;
                        cells_[j].state = Trial;
                        heap.push(entry(v, j));
                    }
                }
            });
        }
        return marched;
    }

    // 3. Write back: inside the band active with the new distance, beyond it off. Every
    //    voxel lives in an existing leaf, so leaves are written in parallel.
    void writeBack() {
        tbb::parallel_for(std::size_t(0), b_.leafCount(), [&](std::size_t l) {
            Leaf& leaf = b_.leaf(l);
            for (int off = 0; off < kLeafVoxels; ++off) {
                const std::size_t i = (l << 9) + off;
                if (cells_[i].state == Fixed) continue;
                const bool neg = negative(phi_[i]);
                if (cells_[i].u < bg_)
                    leaf.setValueOn(off, neg ? -cells_[i].u : cells_[i].u);
                else
                    leaf.setValueOff(off, neg ? -bg_ : bg_);
            }
        });
    }

    const Domain b_;
    const std::size_t n_;
    const float h_, bg_;
    const FmmOrder order_;
    Interrupter* const interrupter_;
    // What the march reads of a voxel, together: one cache line holds a row of eight.
    struct Cell {
        float u; // the distance found so far
        State state;
        bool neg; // inside
    };
    // Every entry is written by the constructor's parallel loop over the leaves, so these
    // are allocated without the serial zeroing of a std::vector (8 MB for a drag segment).
    std::unique_ptr<float[]> phi_;
    std::unique_ptr<Cell[]> cells_;
    std::unique_ptr<std::uint8_t[]> thin_;
    // Per leaf: the voxels inside, and those known or fixed (after seeding).
    std::vector<Bits> neg_, settled_;
};

FmmStats renormalizeWhere(Grid& grid, const openvdb::CoordBBox& region,
                          const openvdb::MaskGrid* only, FmmOrder order, Interrupter* interrupter) {
    if (region.empty()) return {};
    pollInterrupt(interrupter);
    Marcher marcher(grid, region, only, order, interrupter);
    return marcher.run(region, grid);
}

} // namespace

FmmStats renormalize(Grid& grid, const openvdb::CoordBBox& region, FmmOrder order,
                     Interrupter* interrupter) {
    return renormalizeWhere(grid, region, nullptr, order, interrupter);
}

FmmStats renormalize(Grid& grid, const openvdb::CoordBBox& region, const openvdb::MaskGrid& only,
                     FmmOrder order, Interrupter* interrupter) {
    return renormalizeWhere(grid, region, &only, order, interrupter);
}

FmmStats renormalizeAll(Grid& grid, FmmOrder order, Interrupter* interrupter) {
    openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    if (box.empty()) return {};
    box.expand(2);
    const FmmStats stats = renormalize(grid, box, order, interrupter);
    openvdb::tools::pruneLevelSet(grid.tree()); // the whole grid: its internal nodes too
    return stats;
}

} // namespace sweepers
