// SPDX-License-Identifier: Apache-2.0
// Stroke advection: one sweep segment of a ball tool against tools::LevelSetAdvection
// given the same motion as a velocity field.
//
// The tool (radius 0.25, falloff 0.25) sits on the unit sphere's pole and is pulled 0.2
// outward. Its continuous motion is the flow of v(x, tau) = mu(d(x, c(tau))) t with the
// centre c(tau) = c0 + tau t, tau in [0, 1] (3.6 with a translating tool); our segment is
// the fold-over-free discretisation of that flow (3.12, 5.18), OpenVDB integrates the
// same field with its upwind schemes. The two results are compared by the thickness of
// the region where they disagree.
#include <openvdb/tools/LevelSetAdvect.h>
#include <openvdb/tools/LevelSetMeasure.h>

#include "bench.h"
#include "core/falloff.h"
#include "deform/sweep.h"
#include "levelset/advect.h"
#include "levelset/create.h"
#include "tools/ellipsoid.h"

namespace sweepers::bench {
namespace {

constexpr double kRadius = 0.25, kFalloff = 0.25;
const Eigen::Vector3d kStart(0, 0, 1), kMove(0, 0, 0.2);

// The tool's velocity field in the form LevelSetAdvection samples (world positions, since
// its transform differs from the grid's).
struct PullField {
    using ValueType = float;
    using VectorType = openvdb::Vec3f;
    openvdb::math::Transform transform() const { return {}; }
    VectorType operator()(const openvdb::Vec3d& x, ValueType time) const {
        const Eigen::Vector3d c = kStart + double(time) * kMove;
        const double d = std::max(0.0, (toEigen(x) - c).norm() - kRadius);
        const Eigen::Vector3d v = falloffMu(d, kFalloff) * kMove;
        return VectorType(float(v.x()), float(v.y()), float(v.z()));
    }
    VectorType operator()(const openvdb::Coord& ijk, ValueType time) const {
        return (*this)(ijk.asVec3d(), time);
    }
};

Sweep pull() {
    Placement a, b;
    a.t = kStart;
    b.t = kStart + kMove;
    return Sweep{{{std::make_shared<EllipsoidShape>(kRadius), kFalloff, {a, b}}}};
}

// The results of the last run at each size, for the symmetric difference.
std::map<int, GridPtr>& results(const std::string& method) {
    static std::map<std::string, std::map<int, GridPtr>> all;
    return all[method];
}

void compare(benchmark::State& state, int div, const std::string& other, const Grid& mine) {
    state.counters["volume_change_pct"] =
        100.0 * (openvdb::tools::levelSetVolume(mine) / (4.0 / 3.0 * M_PI) - 1.0);
    const auto it = results(other).find(div);
    if (it != results(other).end())
        state.counters["sym_diff_layers"] = symmetricDifferenceLayers(mine, *it->second);
}

} // namespace

void registerAdvectBenchmarks() {
    for (const int div : voxelDivisions()) {
        const double h = 1.0 / div;
        const std::string item = "pull_h" + std::to_string(div);
        add(
            "advect/" + item + "/sweepers",
            [div, h](benchmark::State& state) {
                const GridPtr start = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3.0);
                const Sweep sweep = pull();
                AdvectStats stats;
                const GridPtr g = timedOnCopies(state, *start, [&](Grid& grid) {
                    stats = advectSegment(grid, SweepSegment(sweep, 0));
                });
                state.counters["substeps"] = stats.subSteps;
                state.counters["grow_ms"] = 1e3 * stats.growSeconds;
                state.counters["sample_ms"] = 1e3 * stats.sampleSeconds;
                state.counters["renorm_ms"] = 1e3 * stats.renormalizeSeconds;
                results("sweepers")[div] = g;
                compare(state, div, "openvdb", *g);
            },
            3);
        add(
            "advect/" + item + "/openvdb_LevelSetAdvection",
            [div, h](benchmark::State& state) {
                const GridPtr start = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3.0);
                const GridPtr g = timedOnCopies(state, *start, [](Grid& grid) {
                    openvdb::tools::LevelSetAdvection<Grid, PullField> advection(grid, PullField());
                    advection.advect(0.0, 1.0);
                });
                results("openvdb")[div] = g;
                compare(state, div, "sweepers", *g);
            },
            1);
    }
}

} // namespace sweepers::bench
