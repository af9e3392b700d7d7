// SPDX-License-Identifier: Apache-2.0
#include "levelset/peer_check.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <openvdb/math/Stencils.h>
#include <openvdb/tools/Diagnostics.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/parallel_reduce.h>

namespace sweepers {

namespace {

// The exact distance of an edge where the surface turns by about 30 degrees or more (sharp,
// or rounded within a voxel) fails the eikonal test next to the edge, and there the central
// differences of c and a face neighbour straddle the kink and see about half that turn.
constexpr double kCreaseTurnDegrees = 15.0;

// A sheet or rod this thin, in voxels, crossing the stencil's row along an axis.
constexpr double kThinVoxels = 1.25;

// Whether a voxel next to the surface lies on a feature finer than the eikonal test's stencil.
template <typename Sampler> class ThinFeatures {
  public:
    ThinFeatures(const Grid::ConstAccessor& acc, const Sampler& sample, float h)
        : acc_(acc), sample_(sample), h_(h) {}

    // Along the normal (the central gradient) through c, sampled each voxel for three voxels
    // either way: the surface is crossed more than once (a sheet or a gap thinner than that),
    // or |phi| stops growing away from the surface on either side (a ridge of the distance,
    // the medial axis of a part thinner than that). Or a crease: the normal turns by more
    // than kCreaseTurnDegrees from c to a face neighbour. Or the stencil's row along an axis
    // reads across a thin part that is such a feature itself (acrossAxis).
    bool on(const openvdb::Coord& c) const {
        if (itself(c)) return true;
        for (int a = 0; a < 3; ++a)
            if (acrossAxis(c, a)) return true;
        return false;
    }

  private:
    bool itself(const openvdb::Coord& c) const {
        openvdb::Vec3d n = normal(c);
        if (n.lengthSqr() < 1e-12 * h_ * h_) return true; // no direction at all: a ridge
        n.normalize();
        const double cosCrease = std::cos(kCreaseTurnDegrees * M_PI / 180.0);
        for (int a = 0; a < 3; ++a)
            for (const int d : {-1, 1}) {
                openvdb::Coord q = c;
                q[a] += d;
                const openvdb::Vec3d m = normal(q);
                if (m.lengthSqr() < 1e-12 * h_ * h_ || m.unit().dot(n) < cosCrease) return true;
            }
        float row[7];
        if (alongNormal(c, n, row) > 1) return true;
        // From the crossing outward on each side, |phi| grows (a tenth of a voxel of slack).
        int cross = 0;
        while (cross < 6 && (row[cross] < 0.0f) == (row[cross + 1] < 0.0f))
            ++cross;
        if (cross == 6) return false; // the normal misses the surface within reach
        for (int k = cross + 1; k < 6; ++k)
            if (std::abs(row[k + 1]) < std::abs(row[k]) - 0.1f * h_) return true;
        for (int k = cross; k > 0; --k)
            if (std::abs(row[k - 1]) < std::abs(row[k]) - 0.1f * h_) return true;
        return false;
    }

    openvdb::Vec3d normal(const openvdb::Coord& q) const {
        const auto u = [&](int dx, int dy, int dz) {
            return double(acc_.getValue(q.offsetBy(dx, dy, dz)));
        };
        return {u(1, 0, 0) - u(-1, 0, 0), u(0, 1, 0) - u(0, -1, 0), u(0, 0, 1) - u(0, 0, -1)};
    }

    // The values along the unit normal n through q, a voxel apart, three either way; returns
    // how often they cross the surface.
    int alongNormal(const openvdb::Coord& q, const openvdb::Vec3d& n, float row[7]) const {
        const openvdb::Vec3d at = q.asVec3d();
        for (int k = -3; k <= 3; ++k)
            row[k + 3] = k == 0 ? acc_.getValue(q) : float(sample_.isSample(at + double(k) * n));
        int crossings = 0;
        for (int k = 0; k < 6; ++k)
            crossings += (row[k] < 0.0f) != (row[k + 1] < 0.0f);
        return crossings;
    }

    // A sheet or rod thinner than kThinVoxels crosses the stencil's row through c along axis
    // a, as the test reads it at c but the normal through c may miss it: between two crossings
    // of the row, a run of one sign whose thickness (its length along the row times the slope
    // the row crosses the surface with: the cosine of the angle between the axis and the
    // feature's normal, where the values are distances) is under kThinVoxels, and whose
    // deepest voxel is on a thin feature or a crease itself (where the row only grazes a
    // smooth part thicker than the stencil, it is not).
    bool acrossAxis(const openvdb::Coord& c, int a) const {
        float row[7];
        const auto voxel = [&](int k) {
            openvdb::Coord q = c;
            q[a] += k - 3;
            return q;
        };
        for (int k = 0; k < 7; ++k)
            row[k] = acc_.getValue(voxel(k));
        // The crossings along the row: between k and k + 1, at their linear place, with the
        // slope there.
        int edge[6];
        double at[6], slope[6];
        int n = 0;
        for (int k = 0; k < 6; ++k)
            if ((row[k] < 0.0f) != (row[k + 1] < 0.0f)) {
                const double d = double(row[k + 1]) - double(row[k]);
                edge[n] = k;
                at[n] = k - double(row[k]) / d;
                slope[n++] = std::abs(d);
            }
        for (int i = 0; i + 1 < n; ++i) {
            if ((at[i + 1] - at[i]) * 0.5 * (slope[i] + slope[i + 1]) >= kThinVoxels * h_) continue;
            int deepest = edge[i] + 1;
            for (int k = deepest + 1; k <= edge[i + 1]; ++k)
                if (std::abs(row[k]) > std::abs(row[deepest])) deepest = k;
            if (itself(voxel(deepest))) return true;
        }
        return false;
    }

    const Grid::ConstAccessor& acc_;
    const Sampler& sample_;
    float h_;
};

struct Counts {
    std::size_t eikonal = 0, eikonalThin = 0, surface = 0, thin = 0;
    openvdb::CoordBBox thinBox, elsewhereBox;
};

} // namespace

PeerCheck peerCheck(const Grid& grid) {
    PeerCheck r;
    openvdb::tools::CheckLevelSet<Grid> check(grid);
    r.message = check.check(/*n=*/9, /*updateMask=*/false);
    while (!r.message.empty() && std::isspace(static_cast<unsigned char>(r.message.back())))
        r.message.pop_back();
    if (!grid.hasUniformVoxels()) return r;
    const float h = float(grid.voxelSize()[0]);
    openvdb::tree::LeafManager<const Grid::TreeType> leaves(grid.tree());
    const Counts c = tbb::parallel_reduce(
        leaves.leafRange(), Counts(),
        [&](const auto& range, Counts acc) {
            openvdb::math::WenoStencil<Grid> stencil(grid);
            const Grid::ConstAccessor values = grid.getConstAccessor();
            const openvdb::tools::GridSampler<Grid::ConstAccessor, openvdb::tools::BoxSampler>
                sample(values, grid.transform());
            const ThinFeatures<decltype(sample)> features(values, sample, h);
            for (auto leaf = range.begin(); leaf; ++leaf)
                for (auto it = leaf->cbeginValueOn(); it; ++it) {
                    stencil.moveTo(it.getCoord());
                    if (!stencil.zeroCrossing()) continue; // as CheckEikonal
                    ++acc.surface;
                    const bool thin = features.on(it.getCoord());
                    if (thin) {
                        ++acc.thin;
                        acc.thinBox.expand(it.getCoord());
                    }
                    const float g2 = stencil.normSqGrad();
                    if (g2 < 0.5f || g2 > 1.5f) {
                        ++acc.eikonal;
                        acc.eikonalThin += thin;
                        if (!thin) acc.elsewhereBox.expand(it.getCoord());
                    }
                }
            return acc;
        },
        [](Counts a, const Counts& b) {
            a.eikonal += b.eikonal;
            a.eikonalThin += b.eikonalThin;
            a.surface += b.surface;
            a.thin += b.thin;
            a.thinBox.expand(b.thinBox);
            a.elsewhereBox.expand(b.elsewhereBox);
            return a;
        });
    r.eikonal = c.eikonal;
    r.eikonalThin = c.eikonalThin;
    r.surfaceVoxels = c.surface;
    r.thinVoxels = c.thin;
    const auto worldBox = [&](const openvdb::CoordBBox& b) {
        return Box(toEigen(grid.indexToWorld(b.min())), toEigen(grid.indexToWorld(b.max())));
    };
    if (c.thin > 0) r.thinBox = worldBox(c.thinBox);
    if (c.eikonal > c.eikonalThin) r.elsewhereBox = worldBox(c.elsewhereBox);
    return r;
}

} // namespace sweepers
