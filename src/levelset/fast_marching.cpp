#include "levelset/fast_marching.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <unordered_map>
#include <vector>

#include <openvdb/tools/Prune.h>
#include <tbb/blocked_range.h>
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

// The voxels of every leaf overlapping the region (grown by a margin), stored leaf by
// leaf with each leaf's six face neighbours, so a neighbour is an add or one table
// lookup. The band lives in leaves; voxels outside them (tiles) are far from the
// surface and are not needed.
class Domain {
  public:
    static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();

    Domain(Grid& grid, const openvdb::CoordBBox& region, int margin,
           const openvdb::MaskGrid* only) {
        openvdb::CoordBBox outer = region;
        outer.expand(margin);
        leaves_ = leavesIn(grid.tree(), outer);
        std::unordered_map<openvdb::Coord, int> index;
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
        phi.resize(size());
        active.resize(size());
        inRegion.resize(size());
        tbb::parallel_for(std::size_t(0), leaves_.size(), [&](std::size_t l) {
            const Leaf& leaf = *leaves_[l];
            const bool whole = region.isInside(leaf.getNodeBoundingBox());
            const auto* mask = only ? only->tree().probeConstLeaf(leaf.origin()) : nullptr;
            for (int off = 0; off < kLeafVoxels; ++off) {
                const std::size_t i = (l << 9) + off;
                phi[i] = leaf.getValue(off);
                active[i] = leaf.isValueOn(off);
                inRegion[i] = (whole || region.isInside(leaf.offsetToGlobalCoord(off))) &&
                              (!only || (mask && mask->isValueOn(off)));
            }
        });
    }

    std::size_t size() const { return leaves_.size() * kLeafVoxels; }
    std::size_t leafCount() const { return leaves_.size(); }
    Leaf& leaf(std::size_t l) { return *leaves_[l]; }

    std::size_t neighbour(std::size_t i, int a, int dir) const {
        static constexpr int stride[3] = {64, 8, 1};
        const int off = int(i & 511);
        const int c = (off / stride[a]) & 7;
        const int v = c + dir;
        if (v >= 0 && v < 8) return dir > 0 ? i + stride[a] : i - stride[a];
        const int nl = neighbours_[i >> 9][2 * a + (dir > 0)];
        if (nl < 0) return npos;
        // The same row or column of the neighbouring leaf, at its other end.
        return (std::size_t(nl) << 9) + std::size_t(off + (dir > 0 ? -7 : 7) * stride[a]);
    }

    std::vector<float> phi;
    std::vector<std::uint8_t> active, inRegion;

  private:
    std::vector<Leaf*> leaves_;
    std::vector<std::array<int, 6>> neighbours_;
};

bool negative(float v) {
    return v < 0.0f;
}

// Solves sum_a c_a (u - m_a)^2 = h^2 for the largest root, using axes in increasing m_a
// while the root stays above them.
float solveUpwind(float m[3], float c[3], int n, float h) {
    // sort by m
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

} // namespace

namespace {
FmmStats renormalizeWhere(Grid& grid, const openvdb::CoordBBox& region,
                          const openvdb::MaskGrid* only, FmmOrder order, Interrupter* interrupter);
} // namespace

FmmStats renormalize(Grid& grid, const openvdb::CoordBBox& region, FmmOrder order,
                     Interrupter* interrupter) {
    return renormalizeWhere(grid, region, nullptr, order, interrupter);
}

FmmStats renormalize(Grid& grid, const openvdb::CoordBBox& region, const openvdb::MaskGrid& only,
                     FmmOrder order, Interrupter* interrupter) {
    return renormalizeWhere(grid, region, &only, order, interrupter);
}

namespace {
// Heap pops between two polls of the interrupter.
constexpr std::size_t kPollEvery = 1 << 14;

FmmStats renormalizeWhere(Grid& grid, const openvdb::CoordBBox& region,
                          const openvdb::MaskGrid* only, FmmOrder order, Interrupter* interrupter) {
    FmmStats stats;
    if (region.empty()) return stats;
    const float h = float(grid.voxelSize()[0]);
    const float bg = grid.background();
    const float limit = bg; // march as far as the band reaches
    pollInterrupt(interrupter);
    Domain b(grid, region, 2, only);
    const std::size_t n = b.size();
    std::vector<float> u(n, kInf);
    std::vector<std::uint8_t> state(n, Far);

    // Boundary voxels outside the region keep their values.
    for (std::size_t i = 0; i < n; ++i) {
        if (b.inRegion[i]) continue;
        state[i] = Fixed;
        u[i] = std::abs(b.phi[i]);
    }

    // Thin voxels: the surface on both sides along some axis. Their central differences
    // span the feature, and so do those of voxels up to two steps away, which are flagged
    // too (ring 2 and 3).
    std::vector<std::uint8_t> thin(n, 0);
    auto forAll = [&](const auto& body) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i)
                body(i);
        });
    };
    forAll([&](std::size_t i) {
        const bool neg = negative(b.phi[i]);
        for (int a = 0; a < 3 && !thin[i]; ++a) {
            const std::size_t lo = b.neighbour(i, a, -1), hi = b.neighbour(i, a, 1);
            thin[i] = lo != Domain::npos && hi != Domain::npos && negative(b.phi[lo]) != neg &&
                      negative(b.phi[hi]) != neg;
        }
    });
    for (std::uint8_t ring = 1; ring <= 2; ++ring) {
        forAll([&](std::size_t i) {
            if (thin[i]) return;
            for (int a = 0; a < 3; ++a)
                for (int dir : {-1, 1}) {
                    const std::size_t j = b.neighbour(i, a, dir);
                    if (j != Domain::npos && thin[j] == ring) thin[i] = ring + 1;
                }
        });
    }

    // 1. Seeds (voxels with a face neighbour across the surface): phi / |grad phi| with
    //    central differences, which turns a sampled field that is no longer a distance back
    //    into one to second order where the field is smooth, capped by the distance to the
    //    nearest axis crossing (the surface is no farther). The sign is always kept.
    forAll([&](std::size_t i) {
        if (state[i] == Fixed) return;
        const float p = b.phi[i];
        double inv2 = 0.0, grad2 = 0.0;
        float nearestCrossing = kInf;
        bool crossing = false, central = true;
        for (int a = 0; a < 3; ++a) {
            float best = kInf;
            float side[2] = {p, p};
            for (int dir : {-1, 1}) {
                const std::size_t j = b.neighbour(i, a, dir);
                if (j == Domain::npos) {
                    central = false;
                    continue;
                }
                side[dir > 0] = b.phi[j];
                if (negative(b.phi[j]) == negative(p)) continue;
                crossing = true;
                const float q = b.phi[j];
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
        }
        if (!crossing) return;
        // The surface is no farther than the nearest axis crossing; the plane through the
        // crossings is a first-order estimate below that.
        const bool nearThin = thin[i] != 0;
        float d;
        if (!central || nearThin) {
            // On or next to a feature about one voxel thin (the surface on both sides along an
            // axis) no gradient estimate is trustworthy, so the value is kept: recomputing it
            // would move its crossings a little every time and let the feature drift.
            d = std::min(std::abs(p), h);
        } else if (grad2 > 1e-12 * double(h) * h) {
            const double gradNorm = std::sqrt(grad2) / h;
            // A value whose gradient is already unit within kUnitSlack is a distance: kept, so
            // that renormalizing a renormalized grid changes nothing and nothing drifts.
            d = std::abs(gradNorm - 1.0) < kUnitSlack
                    ? std::abs(p)
                    : std::min(float(std::abs(p) / gradNorm), nearestCrossing * h);
        } else {
            d = float(h / std::sqrt(inv2)); // distance to the plane through the crossings
        }
        u[i] = d;
        state[i] = Known;
    });

    for (std::size_t i = 0; i < n; ++i)
        stats.seeds += state[i] == Known;
    pollInterrupt(interrupter);

    // 2. March from every known or fixed voxel, inside and outside at once: a voxel's
    //    update only reads neighbours of its own sign, so the two marches share no data.
    using Item = std::pair<float, std::size_t>;
    auto march = [&](const bool side) {
        std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
        std::size_t marched = 0, pops = 0;
        auto update = [&](std::size_t i) {
            float m[3], c[3];
            int k = 0;
            for (int a = 0; a < 3; ++a) {
                float best = kInf, second = kInf;
                for (int dir : {-1, 1}) {
                    const std::size_t j = b.neighbour(i, a, dir);
                    if (j == Domain::npos || negative(b.phi[j]) != side || state[j] < Known)
                        continue;
                    if (u[j] < best) {
                        best = u[j];
                        second = kInf;
                        if (order == FmmOrder::Second) {
                            const std::size_t j2 = b.neighbour(j, a, dir);
                            if (j2 != Domain::npos && negative(b.phi[j2]) == side &&
                                state[j2] >= Known && u[j2] <= u[j])
                                second = u[j2];
                        }
                    }
                }
                if (best == kInf) continue;
                if (second < kInf) {
                    m[k] = (4.0f * best - second) / 3.0f; // (3u - 4u1 + u2) / 2h
                    c[k] = 2.25f;
                } else {
                    m[k] = best;
                    c[k] = 1.0f;
                }
                ++k;
            }
            if (k == 0) return;
            const float v = solveUpwind(m, c, k, h);
            if (v < u[i]) {
                u[i] = v;
                state[i] = Trial;
                heap.push({v, i});
            }
        };
        auto updateNeighbours = [&](std::size_t i) {
            for (int a = 0; a < 3; ++a)
                for (int dir : {-1, 1}) {
                    const std::size_t j = b.neighbour(i, a, dir);
                    if (j != Domain::npos && negative(b.phi[j]) == side && state[j] < Known)
                        update(j);
                }
        };
        // The first trial values: every far voxel of this side next to a known or fixed one
        // (the values and the heap that updating the neighbours of every known voxel gives,
        // without visiting all the fixed voxels around the region).
        for (std::size_t i = 0; i < n; ++i)
            if (state[i] == Far && negative(b.phi[i]) == side) update(i);
        while (!heap.empty()) {
            const auto [v, i] = heap.top();
            heap.pop();
            if (++pops % kPollEvery == 0) pollInterrupt(interrupter);
            if (state[i] != Trial || v != u[i]) continue;
            state[i] = Known;
            ++marched;
            if (v > limit) continue; // far enough: leave its neighbours far
            updateNeighbours(i);
        }
        return marched;
    };
    std::size_t marchedOutside = 0, marchedInside = 0;
    tbb::parallel_invoke([&] { marchedOutside = march(false); },
                         [&] { marchedInside = march(true); });
    stats.marched = marchedOutside + marchedInside;
    pollInterrupt(interrupter); // the last chance: nothing has been written yet

    // 3. Write back: inside the band active with the new distance, beyond it off. Every
    //    voxel lives in an existing leaf, so leaves are written in parallel.
    tbb::parallel_for(std::size_t(0), b.leafCount(), [&](std::size_t l) {
        Leaf& leaf = b.leaf(l);
        for (int off = 0; off < kLeafVoxels; ++off) {
            const std::size_t i = (l << 9) + off;
            if (state[i] == Fixed) continue;
            const bool neg = negative(b.phi[i]);
            if (u[i] < bg) {
                leaf.setValueOn(off, neg ? -u[i] : u[i]);
            } else {
                leaf.setValueOff(off, neg ? -bg : bg);
            }
        }
    });
    openvdb::CoordBBox written = region;
    written.expand(2);
    pruneEmptyLeavesIn(grid.tree(), written);
    stats.leaves = b.leafCount();
    return stats;
}
} // namespace

FmmStats renormalizeAll(Grid& grid, FmmOrder order, Interrupter* interrupter) {
    openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    if (box.empty()) return {};
    box.expand(2);
    const FmmStats stats = renormalize(grid, box, order, interrupter);
    openvdb::tools::pruneLevelSet(grid.tree()); // the whole grid: its internal nodes too
    return stats;
}

} // namespace sweepers
