// SPDX-License-Identifier: Apache-2.0
// The brushes group: every kind of stroke with the same ball (radius 0.25 on the unit
// sphere) at voxel sizes 1/64, 1/128 and 1/256 (r/h = 16, 32, 64), and 1/512 for the sweep
// and the smooth dab: the per-segment (or per-dab) p50 and p95 of the engine's time (no
// meshing), the voxels each touched, and, after each kind's sizes, the exponent of its p50
// fitted against r/h (least squares on the logarithms): the law by which it grows as the
// detail gets finer. Smooth dabs run the explicit flow too, as the reference; and a dab of
// the modeler's largest ball (radius 2) at 1/256.
#include <cmath>
#include <map>

#include "bench.h"
#include "core/limits.h"
#include "core/statistics.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "sculpt/sculptor.h"

namespace sweepers::bench {
namespace {

constexpr double kBall = 0.25;

struct BrushCase {
    const char* name;
    const char* stroke;   // JSON, the ball's radius and falloff kBall
    bool finest;          // also at 1/512
    bool only256 = false; // at 1/256 alone (no fit)
    double ball = kBall;  // the ball's radius
};

// Short strokes near the sphere's top; the sweep is the first ten segments of
// data/drag.json, as the hand makes them.
const BrushCase kCases[] = {
    {"sweep", nullptr, true},
    {"swirl", R"({"type": "swirl", "at": [0, 1, 0], "move": [0.1, 0.1, 0], "radius": 0.25})",
     false},
    {"swirl_convolution",
     R"({"type": "swirl", "at": [0, 1, 0], "move": [0.1, 0.1, 0], "radius": 0.25,
         "ring": "convolution"})",
     false},
    {"inflation", R"({"type": "inflate", "at": [0, 1, 0], "radius": 0.25})", false},
    {"clay", R"({"type": "inflate", "at": [0, 0.875, 0], "radius": 0.25})", false},
    {"fluid", R"({"type": "fluid", "radius": 0.25,
                  "path": [[0, 0.85, 0], [0, 0.9, 0], [0, 0.95, 0], [0, 1.0, 0]]})",
     false},
    {"pinch", R"({"type": "pinch", "at": [0, 1, 0], "axis": [1, 0, 0], "size": 0.25,
                  "falloff": 0.25, "open": 0.1})",
     false},
    {"strangle", R"({"type": "strangle", "at": [0, 1, 0], "axis": [0, 1, 0], "size": 0.25,
                     "falloff": 0.25, "open": 0.1})",
     false},
    {"smooth", R"({"type": "smooth", "tool": {"shape": "ball", "size": 0.25, "falloff": 0.25,
                   "path": [{"t": [0, 1, 0]}, {"t": [0.05, 0.999, 0]}, {"t": [0.1, 0.995, 0]},
                            {"t": [0.15, 0.989, 0]}, {"t": [0.2, 0.98, 0]},
                            {"t": [0.25, 0.968, 0]}]}})",
     true},
    {"smooth_radial5",
     R"({"type": "smooth", "radial": {"axis": [0, 1, 0], "center": [0, 0, 0], "count": 5},
         "tool": {"shape": "ball", "size": 0.25, "falloff": 0.25,
                  "path": [{"t": [0.3, 0.954, 0]}, {"t": [0.32, 0.947, 0]}]}})",
     false},
    // Strength 10, the most: a flow time ten times the default dab's.
    {"smooth_strength10", R"({"type": "smooth", "strength": 10,
                             "tool": {"shape": "ball", "size": 0.25, "falloff": 0.25,
                             "path": [{"t": [0, 1, 0]}, {"t": [0.05, 0.999, 0]},
                                      {"t": [0.1, 0.995, 0]}, {"t": [0.15, 0.989, 0]}]}})",
     true},
    // The modeler's largest ball: on the unit sphere it covers the whole surface, about 16
    // times the footprint of the ball of 0.25 with its falloff.
    {"smooth_radius2", R"({"type": "smooth", "tool": {"shape": "ball", "size": 2, "falloff": 0.25,
                          "path": [{"t": [0, 1, 0]}, {"t": [0.05, 0.999, 0]},
                                   {"t": [0.1, 0.995, 0]}]}})",
     false, true, 2.0},
};

std::vector<Stroke> strokesOf(const BrushCase& c) {
    if (!c.stroke) {
        StrokeScript drag = readStrokeScript(std::string(SWEEPERS_DATA_DIR) + "/drag.json");
        auto& sweep = std::get<SweepStroke>(drag.strokes.at(0));
        sweep.tools.at(0).path.resize(11);
        return drag.strokes;
    }
    const std::string text = std::string(R"({"sweepers": 1, "grid": {"voxel_size": 0.02},
        "start": {"sphere": {"center": [0, 0, 0], "radius": 1}}, "strokes": [)") +
                             c.stroke + "]}";
    return loadStrokeScript(text, std::string("brushes/") + c.name + ".json", SWEEPERS_DATA_DIR)
        .strokes;
}

// p50 of each kind by r/h, for the fit.
std::map<std::string, std::map<double, double>>& medians() {
    static std::map<std::string, std::map<double, double>> m;
    return m;
}

} // namespace

void registerBrushBenchmarks() {
    for (const BrushCase& c : kCases) {
        std::vector<int> divisions{64, 128, 256};
        if (c.finest) divisions.push_back(512);
        if (c.only256) divisions = {256};
        const bool smooth = std::string(c.name).rfind("smooth", 0) == 0;
        for (const int div : divisions)
            for (const bool flow : {false, true}) {
                // A smooth dab's reference: the explicit flow, in the same run.
                if (flow && (!smooth || c.only256)) continue;
                add(
                    std::string("brushes/") + c.name + "_h" + std::to_string(div) +
                        (flow ? "/explicit_flow" : "/sweepers"),
                    [&c, div, flow, smooth](benchmark::State& state) {
                        const std::vector<Stroke> strokes = strokesOf(c);
                        StrokeScript script;
                        script.start.radius = 1.0;
                        std::vector<SegmentReport> reports;
                        for (auto _ : state) {
                            state.PauseTiming();
                            Sculptor sculptor(makeStartGrid(script, SWEEPERS_DATA_DIR, 1.0 / div));
                            SmoothOptions options;
                            if (flow) options.scheme = SmoothScheme::ExplicitFlow;
                            sculptor.setSmoothOptions(options);
                            state.ResumeTiming();
                            try {
                                reports = applyStrokes(sculptor, strokes);
                            } catch (const LimitExceeded& e) {
                                // (The explicit flow of the longest dabs at the finest.)
                                state.SkipWithError(e.what());
                                return;
                            }
                        }
                        std::vector<double> ms, voxels, plan, update, renorm;
                        for (const SegmentReport& r : reports) {
                            ms.push_back(1e3 * r.seconds);
                            plan.push_back(1e3 * r.smooth.planSeconds);
                            update.push_back(1e3 * r.smooth.updateSeconds);
                            renorm.push_back(1e3 * r.smooth.renormalizeSeconds);
                            voxels.push_back(double(r.smooth.weighted ? r.smooth.weighted
                                                                      : r.stats.sampledVoxels));
                        }
                        const double p50 = percentile(ms, 0.5);
                        state.counters["p50_ms"] = p50;
                        state.counters["p95_ms"] = percentile(ms, 0.95);
                        state.counters["voxels"] = percentile(voxels, 0.5);
                        state.counters["segments"] = double(reports.size());
                        state.counters["r_over_h"] = c.ball * div;
                        if (smooth) {
                            // A dab's phases: planning, the update (the filter or the flow, the
                            // band's growth) and the renormalization.
                            state.counters["plan_p50_ms"] = percentile(plan, 0.5);
                            state.counters["update_p50_ms"] = percentile(update, 0.5);
                            state.counters["renorm_p50_ms"] = percentile(renorm, 0.5);
                        }
                        if (!reports.empty() && reports.back().smooth.weighted)
                            state.counters["work_per_voxel"] =
                                reports.back().smooth.work / double(reports.back().smooth.weighted);
                        if (!reports.empty() && reports.back().smooth.latticeSpacing)
                            state.counters["lattice_spacing"] =
                                double(reports.back().smooth.latticeSpacing);
                        medians()[std::string(c.name) + (flow ? "/explicit_flow" : "")]
                                 [c.ball * div] = p50;
                    },
                    1);
            }
        // The exponent k of p50 ~ (r/h)^k over the sizes just run.
        for (const bool flow : {false, true}) {
            if ((flow && !smooth) || c.only256) continue;
            const std::string key = std::string(c.name) + (flow ? "/explicit_flow" : "");
            add(
                std::string("brushes/") + c.name + "_exponent/" +
                    (flow ? "explicit_flow" : "sweepers"),
                [key](benchmark::State& state) {
                    for (auto _ : state) {
                    }
                    const auto& m = medians()[key];
                    double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
                    for (const auto& [rh, p50] : m) {
                        const double x = std::log(rh), y = std::log(p50);
                        sx += x;
                        sy += y;
                        sxx += x * x;
                        sxy += x * y;
                        ++n;
                    }
                    state.counters["exponent"] =
                        n >= 2 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : std::nan("");
                },
                1);
        }
    }
}

} // namespace sweepers::bench
