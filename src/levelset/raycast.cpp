// SPDX-License-Identifier: Apache-2.0
#include "levelset/raycast.h"

#include <openvdb/tools/Interpolation.h>

namespace sweepers {

namespace {

// The first point along the ray where phi * sign crosses to negative (sign +1: from
// outside in; -1: from inside out).
std::optional<Eigen::Vector3d> march(const Grid& grid, const Eigen::Vector3d& origin,
                                     const Eigen::Vector3d& direction, double maxDistance,
                                     double sign) {
    const Eigen::Vector3d d = direction.normalized();
    const double h = grid.voxelSize()[0];
    const Grid::ConstAccessor acc = grid.getConstAccessor(); // the sampler keeps a reference
    const openvdb::tools::GridSampler<Grid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
        acc, grid.transform());
    auto phi = [&](double t) { return sign * double(sampler.wsSample(toVdb(origin + t * d))); };
    // Start where the ray enters the box of the active voxels (plus the band).
    const openvdb::CoordBBox ibox = grid.evalActiveVoxelBoundingBox();
    if (ibox.empty()) return std::nullopt;
    double t0 = 0.0, t1 = maxDistance;
    const openvdb::Vec3d lo = grid.indexToWorld(ibox.min()), hi = grid.indexToWorld(ibox.max());
    for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-12) {
            if (origin[a] < lo[a] - h || origin[a] > hi[a] + h) return std::nullopt;
            continue;
        }
        double ta = (lo[a] - h - origin[a]) / d[a], tb = (hi[a] + h - origin[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    if (t0 > t1) return std::nullopt;
    double t = t0, v = phi(t);
    if (v < 0) return sign > 0 ? std::optional(Eigen::Vector3d(origin + t * d)) : std::nullopt;
    while (t < t1) {
        const double step = std::max(0.9 * v, 0.5 * h);
        const double tn = std::min(t + step, t1);
        const double vn = phi(tn);
        if (vn < 0) {
            double a = t, b = tn;
            while (b - a > 1e-4 * h) {
                const double m = 0.5 * (a + b);
                (phi(m) < 0 ? b : a) = m;
            }
            return origin + b * d;
        }
        if (tn >= t1) break;
        t = tn;
        v = vn;
    }
    return std::nullopt;
}

} // namespace

std::optional<Eigen::Vector3d> raycastLevelSet(const Grid& grid, const Eigen::Vector3d& origin,
                                               const Eigen::Vector3d& direction,
                                               double maxDistance) {
    return march(grid, origin, direction, maxDistance, 1.0);
}

std::optional<Eigen::Vector3d> exitLevelSet(const Grid& grid, const Eigen::Vector3d& inside,
                                            const Eigen::Vector3d& direction, double maxDistance) {
    return march(grid, inside, direction, maxDistance, -1.0);
}

} // namespace sweepers
