// SPDX-License-Identifier: Apache-2.0
// Enright's 3D deformation test (Enright, Fedkiw, Ferziger and Mitchell 2002): the sphere of
// radius 0.15 at (0.35, 0.35, 0.35) in the unit box, carried by the periodic field of period
// 3 to t = 1.5 (the thinnest sheet) and to t = 3 (back where it began). Ours (a flow stroke:
// each voxel's characteristic traced back through a whole segment, as few segments as the
// stretch allows) against tools::LevelSetAdvection with tools::EnrightField, with its
// default schemes (HJWENO5, TVD-RK2) and with TVD-RK3, at 1/50, 1/100 and 1/200 of the box.
// Figures: the volume change against the start sphere's grid, and at t = 3 the thickness of
// the region where the result and the start disagree, in voxel layers. At t = 3 ours also
// runs as two strokes, to t = 1.5 and back, so that it resamples the thinnest sheet.
#include <map>

#include <openvdb/tools/LevelSetAdvect.h>
#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/VelocityFields.h>

#include "bench.h"
#include "levelset/create.h"
#include "sculpt/sculptor.h"

namespace sweepers::bench {
namespace {

GridPtr startSphere(int div) {
    return makeSphere(Eigen::Vector3d::Constant(0.35), 0.15, 1.0 / div, 3.0);
}

void figures(benchmark::State& state, const Grid& start, const Grid& result, double to) {
    const double v0 = openvdb::tools::levelSetVolume(start);
    state.counters["volume_change_pct"] =
        100.0 * (openvdb::tools::levelSetVolume(result) / v0 - 1.0);
    if (to == 3.0) state.counters["sym_diff_layers"] = symmetricDifferenceLayers(start, result);
}

template <openvdb::math::TemporalIntegrationScheme Time>
void openvdbEnright(benchmark::State& state, int div, double to) {
    const GridPtr start = startSphere(div);
    const GridPtr g = timedOnCopies(state, *start, [to](Grid& grid) {
        using Field = openvdb::tools::EnrightField<float>;
        openvdb::tools::LevelSetAdvection<Grid, Field> advection(grid, Field());
        advection.setSpatialScheme(openvdb::math::HJWENO5_BIAS);
        advection.setTemporalScheme(Time);
        advection.advect(0.0, to);
    });
    figures(state, *start, *g, to);
}

} // namespace

void registerEnrightBenchmarks() {
    for (const int div : {50, 100, 200})
        for (const double to : {1.5, 3.0}) {
            const std::string item = "h" + std::to_string(div) + (to == 3.0 ? "_t3" : "_t1.5");
            add(
                "enright/" + item + "/sweepers",
                [div, to](benchmark::State& state) {
                    const GridPtr start = startSphere(div);
                    FlowStroke flow;
                    flow.field.kind = FieldSpec::Kind::Enright;
                    flow.to = to;
                    std::size_t segments = 0;
                    const GridPtr g = timedOnCopies(state, *start, [&](Grid& grid) {
                        Sculptor sculptor(grid.deepCopy());
                        segments = 0;
                        sculptor.applyStroke(flow, [&](const SegmentReport&) { ++segments; });
                        grid.setTree(sculptor.grid().treePtr());
                    });
                    state.counters["segments"] = double(segments);
                    figures(state, *start, *g, to);
                },
                1);
            if (to == 3.0)
                // The same, resampled at the thinnest sheet: two strokes, to t = 1.5 and back.
                add(
                    "enright/" + item + "/sweepers_through_the_sheet",
                    [div](benchmark::State& state) {
                        const GridPtr start = startSphere(div);
                        FlowStroke there, back;
                        there.to = back.from = 1.5;
                        back.to = 3.0;
                        std::size_t segments = 0;
                        const GridPtr g = timedOnCopies(state, *start, [&](Grid& grid) {
                            Sculptor sculptor(grid.deepCopy());
                            segments = 0;
                            for (const FlowStroke& f : {there, back})
                                sculptor.applyStroke(f, [&](const SegmentReport&) { ++segments; });
                            grid.setTree(sculptor.grid().treePtr());
                        });
                        state.counters["segments"] = double(segments);
                        figures(state, *start, *g, 3.0);
                    },
                    1);
            add(
                "enright/" + item + "/openvdb_LevelSetAdvection",
                [div, to](benchmark::State& state) {
                    openvdbEnright<openvdb::math::TVD_RK2>(state, div, to);
                },
                1);
            add(
                "enright/" + item + "/openvdb_LevelSetAdvection_rk3",
                [div, to](benchmark::State& state) {
                    openvdbEnright<openvdb::math::TVD_RK3>(state, div, to);
                },
                1);
        }
}

} // namespace sweepers::bench
