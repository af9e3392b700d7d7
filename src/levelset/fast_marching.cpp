#include "levelset/fast_marching.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <vector>

#include <openvdb/tools/Prune.h>

namespace sweepers {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kUnitSlack = 0.05;

enum State : std::uint8_t { Far = 0, Trial = 1, Known = 2, Fixed = 3 };

// Dense copy of a box of the grid with a margin of fixed boundary voxels around it.
class Block {
  public:
    Block(const Grid& grid, const openvdb::CoordBBox& inner, int margin)
        : inner_(inner), outer_(inner.min().offsetBy(-margin), inner.max().offsetBy(margin)) {
        const openvdb::Coord d = outer_.dim();
        nx_ = d.x();
        ny_ = d.y();
        nz_ = d.z();
        const std::size_t n = std::size_t(nx_) * ny_ * nz_;
        phi_.resize(n);
        active_.resize(n);
        auto acc = grid.getConstAccessor();
        std::size_t i = 0;
        for (int x = outer_.min().x(); x <= outer_.max().x(); ++x)
            for (int y = outer_.min().y(); y <= outer_.max().y(); ++y)
                for (int z = outer_.min().z(); z <= outer_.max().z(); ++z, ++i) {
                    const openvdb::Coord ijk(x, y, z);
                    phi_[i] = acc.getValue(ijk);
                    active_[i] = acc.isValueOn(ijk);
                }
    }

    std::size_t size() const { return phi_.size(); }
    std::size_t index(int x, int y, int z) const { return (std::size_t(x) * ny_ + y) * nz_ + z; }
    openvdb::Coord coord(std::size_t i) const {
        const int z = int(i % nz_), y = int((i / nz_) % ny_), x = int(i / (std::size_t(nz_) * ny_));
        return outer_.min().offsetBy(x, y, z);
    }
    bool inInner(std::size_t i) const { return inner_.isInside(coord(i)); }
    // Neighbour along axis a in direction dir (+1/-1), or npos outside the block.
    std::size_t neighbour(std::size_t i, int a, int dir) const {
        const openvdb::Coord c = coord(i) - outer_.min();
        const int dims[3] = {nx_, ny_, nz_};
        const int v = c[a] + dir;
        if (v < 0 || v >= dims[a]) return npos;
        const std::size_t strides[3] = {std::size_t(ny_) * nz_, std::size_t(nz_), 1};
        return dir > 0 ? i + strides[a] : i - strides[a];
    }
    static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();

    std::vector<float> phi_;
    std::vector<std::uint8_t> active_;
    openvdb::CoordBBox inner_, outer_;
    int nx_, ny_, nz_;
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

FmmStats renormalize(Grid& grid, const openvdb::CoordBBox& region, FmmOrder order) {
    FmmStats stats;
    if (region.empty()) return stats;
    const float h = float(grid.voxelSize()[0]);
    const float bg = grid.background();
    const float limit = bg; // march as far as the band reaches
    Block b(grid, region, 2);
    const std::size_t n = b.size();
    std::vector<float> u(n, kInf);
    std::vector<std::uint8_t> state(n, Far);

    // Boundary voxels outside the region keep their values.
    for (std::size_t i = 0; i < n; ++i) {
        if (b.inInner(i)) continue;
        state[i] = Fixed;
        u[i] = std::abs(b.phi_[i]);
    }

    // 1. Seeds (voxels with a face neighbour across the surface): phi / |grad phi| with
    //    central differences, which turns a sampled field that is no longer a distance back
    //    into one to second order where the field is smooth, capped by the distance to the
    //    nearest axis crossing (the surface is no farther). The sign is always kept.
    // Thin voxels: the surface on both sides along some axis.
    // Their central differences span the feature, and so do those of voxels up to two
    // steps away, so those are flagged too.
    std::vector<std::uint8_t> thin(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const bool neg = negative(b.phi_[i]);
        for (int a = 0; a < 3 && !thin[i]; ++a) {
            const std::size_t lo = b.neighbour(i, a, -1), hi = b.neighbour(i, a, 1);
            thin[i] = lo != Block::npos && hi != Block::npos && negative(b.phi_[lo]) != neg &&
                      negative(b.phi_[hi]) != neg;
        }
    }
    for (std::uint8_t ring = 1; ring <= 2; ++ring) {
        for (std::size_t i = 0; i < n; ++i) {
            if (thin[i] != ring) continue;
            for (int a = 0; a < 3; ++a)
                for (int dir : {-1, 1}) {
                    const std::size_t j = b.neighbour(i, a, dir);
                    if (j != Block::npos && !thin[j]) thin[j] = ring + 1;
                }
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (state[i] == Fixed) continue;
        const float p = b.phi_[i];
        double inv2 = 0.0, grad2 = 0.0;
        float nearestCrossing = kInf;
        bool crossing = false, central = true;
        for (int a = 0; a < 3; ++a) {
            float best = kInf;
            float side[2] = {p, p};
            for (int dir : {-1, 1}) {
                const std::size_t j = b.neighbour(i, a, dir);
                if (j == Block::npos) {
                    central = false;
                    continue;
                }
                side[dir > 0] = b.phi_[j];
                if (negative(b.phi_[j]) == negative(p)) continue;
                crossing = true;
                const float q = b.phi_[j];
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
        if (!crossing) continue;
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
        ++stats.seeds;
    }

    // 2. March from every known or fixed voxel.
    using Item = std::pair<float, std::size_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    auto update = [&](std::size_t i) {
        const bool neg = negative(b.phi_[i]);
        float m[3], c[3];
        int k = 0;
        for (int a = 0; a < 3; ++a) {
            float best = kInf, second = kInf;
            for (int dir : {-1, 1}) {
                const std::size_t j = b.neighbour(i, a, dir);
                if (j == Block::npos || state[j] < Known || negative(b.phi_[j]) != neg) continue;
                if (u[j] < best) {
                    best = u[j];
                    second = kInf;
                    if (order == FmmOrder::Second) {
                        const std::size_t j2 = b.neighbour(j, a, dir);
                        if (j2 != Block::npos && state[j2] >= Known &&
                            negative(b.phi_[j2]) == neg && u[j2] <= u[j])
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
    for (std::size_t i = 0; i < n; ++i) {
        if (state[i] < Known) continue;
        for (int a = 0; a < 3; ++a)
            for (int dir : {-1, 1}) {
                const std::size_t j = b.neighbour(i, a, dir);
                if (j != Block::npos && state[j] < Known) update(j);
            }
    }
    while (!heap.empty()) {
        const auto [v, i] = heap.top();
        heap.pop();
        if (state[i] != Trial || v != u[i]) continue;
        state[i] = Known;
        ++stats.marched;
        if (v > limit) continue; // far enough: leave its neighbours far
        for (int a = 0; a < 3; ++a)
            for (int dir : {-1, 1}) {
                const std::size_t j = b.neighbour(i, a, dir);
                if (j != Block::npos && state[j] < Known) update(j);
            }
    }

    // 3. Write back: inside the band active with the new distance, beyond it off.
    auto acc = grid.getAccessor();
    for (std::size_t i = 0; i < n; ++i) {
        if (state[i] == Fixed) continue;
        const bool neg = negative(b.phi_[i]);
        const openvdb::Coord ijk = b.coord(i);
        if (u[i] < bg) {
            acc.setValueOn(ijk, neg ? -u[i] : u[i]);
        } else {
            const float off = neg ? -bg : bg;
            if (b.active_[i] || b.phi_[i] != off) acc.setValueOff(ijk, off);
        }
    }
    openvdb::tools::pruneLevelSet(grid.tree());
    return stats;
}

FmmStats renormalizeAll(Grid& grid, FmmOrder order) {
    openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    if (box.empty()) return {};
    box.expand(2);
    return renormalize(grid, box, order);
}

} // namespace sweepers
