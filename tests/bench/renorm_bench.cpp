// SPDX-License-Identifier: Apache-2.0
// Renormalization: our fast marching (first and second order) against tools::sdfToSdf
// (fast sweeping) and tools::LevelSetTracker::normalize, all with their defaults.
//
// (a) an analytic sphere and torus whose band values were scaled by a smooth factor
//     between 1.2 and 2 (the surface stays, the distances are wrong), errors against the
//     analytic distance;
// (b) the unit sphere right after a large pull advected without renormalization, errors
//     against the exact distance to its zero-crossing mesh (meshToLevelSet of our
//     marching-cubes mesh of that grid: the interface all methods must keep).
#include <optional>

#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/LevelSetTracker.h>

#include "bench.h"
#include "levelset/create.h"
#include "levelset/renormalize.h"
#include "mesh/marching_cubes.h"

namespace sweepers::bench {
namespace {

void distort(Grid& g) {
    for (auto it = g.beginValueOn(); it; ++it) {
        const Eigen::Vector3d p = toEigen(g.indexToWorld(it.getCoord()));
        const double wobble = 1.6 + 0.4 * std::sin(4.0 * p.x() + 3.0 * p.y() - 2.0 * p.z());
        it.setValue(float(*it * wobble));
    }
}

struct Case {
    std::string name;
    GridPtr grid;             // the distorted input
    Sdf exact;                // distance the result should hold
    openvdb::CoordBBox local; // what our engine renormalizes after the stroke (case b)
};

Case sphereCase(int div) {
    const double h = 1.0 / div;
    Sdf sdf = [](const Eigen::Vector3d& p) { return p.norm() - 1.0; };
    GridPtr g =
        gridFromSdf(sdf, h, Eigen::Vector3d::Constant(-1.1), Eigen::Vector3d::Constant(1.1));
    distort(*g);
    return {"sphere_h" + std::to_string(div), g, sdf, {}};
}

Case torusCase(int div) {
    const double h = 1.0 / div, R = 0.6, r = 0.25;
    Sdf sdf = [=](const Eigen::Vector3d& p) {
        const double q = std::hypot(p.x(), p.y()) - R;
        return std::hypot(q, p.z()) - r;
    };
    GridPtr g =
        gridFromSdf(sdf, h, Eigen::Vector3d(-0.9, -0.9, -0.3), Eigen::Vector3d(0.9, 0.9, 0.3));
    distort(*g);
    return {"torus_h" + std::to_string(div), g, sdf, {}};
}

Case strokeCase(int div) {
    const double h = 1.0 / div;
    openvdb::CoordBBox touched;
    const GridPtr g = afterLargeStroke(div, false, &touched);
    // The reference: exact distances to the interface the grid holds now.
    const TriangleMesh mesh = meshLevelSet(*g);
    const GridPtr reference = levelSetFromMesh(mesh.positions, mesh.triangles, h, 6.0);
    Sdf exact = [reference](const Eigen::Vector3d& p) {
        return double(
            reference->tree().getValue(reference->transform().worldToIndexCellCentered(toVdb(p))));
    };
    return {"stroke_h" + std::to_string(div), g, exact, touched};
}

void report(benchmark::State& state, const Grid& result, const Case& c) {
    const DistanceErrors e = distanceErrors(result, c.exact);
    state.counters["max_near_vox"] = e.maxNear;
    state.counters["rms_near_vox"] = e.rmsNear;
    state.counters["max_band_vox"] = e.maxBand;
    state.counters["rms_band_vox"] = e.rmsBand;
    state.counters["active_voxels"] = double(result.activeVoxelCount());
}

void registerCase(const std::string& item, std::function<Case()> make) {
    // Cases are built once, on first use, and shared by the methods.
    auto shared = std::make_shared<std::optional<Case>>();
    auto get = [shared, make]() -> const Case& {
        if (!*shared) *shared = make();
        return **shared;
    };
    const std::string base = "renorm/" + item + "/";
    auto fmm = [get](UpwindOrder order, bool local) {
        return [get, order, local](benchmark::State& state) {
            const Case& c = get();
            const GridPtr g = timedOnCopies(state, *c.grid, [&](Grid& grid) {
                RenormalizeOptions o;
                if (local) o.region = c.local;
                o.order = order;
                renormalize(grid, o);
            });
            report(state, *g, c);
        };
    };
    add(base + "sweepers_fmm1", fmm(UpwindOrder::First, false), 3);
    add(base + "sweepers_fmm2", fmm(UpwindOrder::Second, false), 3);
    if (item.rfind("stroke", 0) == 0)
        add(base + "sweepers_fmm2_stroke_region", fmm(UpwindOrder::Second, true), 3);
    add(
        base + "openvdb_sdfToSdf",
        [get](benchmark::State& state) {
            const Case& c = get();
            GridPtr g;
            for (auto _ : state)
                g = openvdb::tools::sdfToSdf(*c.grid);
            report(state, *g, c);
        },
        3);
    add(
        base + "openvdb_LevelSetTracker_normalize",
        [get](benchmark::State& state) {
            const Case& c = get();
            const GridPtr g = timedOnCopies(state, *c.grid, [](Grid& grid) {
                openvdb::tools::LevelSetTracker<Grid> tracker(grid);
                tracker.normalize();
            });
            report(state, *g, c);
        },
        3);
}

} // namespace

void registerRenormalizeBenchmarks() {
    for (const int div : voxelDivisions()) {
        registerCase("sphere_h" + std::to_string(div), [div] { return sphereCase(div); });
        registerCase("torus_h" + std::to_string(div), [div] { return torusCase(div); });
        registerCase("stroke_h" + std::to_string(div), [div] { return strokeCase(div); });
    }
}

} // namespace sweepers::bench
