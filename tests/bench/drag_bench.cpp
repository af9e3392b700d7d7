// SPDX-License-Identifier: Apache-2.0
// The interactive budget: data/drag.json, a recorded drag of 100 short segments with a
// ball tool of radius 0.25 on the unit sphere, replayed as the modeler does it (advect,
// renormalize, re-mesh the touched leaves after every segment), at every size of the run
// and one twice as fine as the finest. Reports the latency of a segment, p50 and p95,
// split by stage, and the case's peak memory.
//
// The scale group: the first 20 segments of the same drag at voxel size 1/128 on spheres
// of radius 1, 2 and 4 (the drag moved out to the surface): a segment must cost what the
// brush touches, not what the model holds.
#include <algorithm>
#include <cstdio>
#include <thread>

#include <tbb/global_control.h>

#include "bench.h"
#include "core/memory.h"
#include "core/statistics.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "sculpt/sculptor.h"

namespace sweepers::bench {
namespace {

// Per-segment figures of a run: p50 and p95 of the whole segment and p50 of each stage.
void addSegmentCounters(benchmark::State& state, const std::vector<SegmentReport>& reports) {
    std::vector<double> total, advect, renorm, mesh, serial;
    double allTime = 0.0, allSerial = 0.0;
    for (const SegmentReport& r : reports) {
        total.push_back(1e3 * (r.seconds + r.meshSeconds));
        advect.push_back(1e3 * r.advectSeconds());
        renorm.push_back(1e3 * r.stats.renormalizeSeconds);
        mesh.push_back(1e3 * r.meshSeconds);
        serial.push_back(1e3 * r.serialSeconds());
        allTime += r.seconds + r.meshSeconds;
        allSerial += r.serialSeconds();
    }
    for (const auto& [name, v] : {std::pair{"segment", &total},
                                  {"advect", &advect},
                                  {"renorm", &renorm},
                                  {"mesh", &mesh},
                                  {"serial", &serial}}) {
        state.counters[std::string(name) + "_p50_ms"] = percentile(*v, 0.5);
        state.counters[std::string(name) + "_p95_ms"] = percentile(*v, 0.95);
    }
    // The share of the segments' time during which one thread worked and the others waited
    // (vdb/parallel.h): at one thread, Amdahl's bound on what more cores can give.
    state.counters["serial_fraction"] = allTime > 0.0 ? allSerial / allTime : 0.0;
    // Where it is: each phase's serial time, mean per segment.
    for (std::size_t k = 0; k < kAdvectPhases.size(); ++k) {
        double serialOfPhase = 0.0;
        for (const SegmentReport& r : reports)
            serialOfPhase += r.stats.phases[k].serialSeconds;
        state.counters[std::string(kAdvectPhases[k]) + "_serial_ms"] =
            1e3 * serialOfPhase / double(std::max<std::size_t>(reports.size(), 1));
    }
    double meshSerial = 0.0;
    for (const SegmentReport& r : reports)
        meshSerial += r.meshSerialSeconds;
    state.counters["mesh_serial_ms"] =
        1e3 * meshSerial / double(std::max<std::size_t>(reports.size(), 1));
    state.counters["segments"] = double(reports.size());
}

// Starts the case's own count of peak memory (what earlier cases freed and the heap kept
// is handed back first); the counter says so where the kernel refused, rather than
// reporting the process's peak as the case's.
void startPeak() {
    if (!restartPeakResident())
        std::fprintf(stderr, "peak_rss_mb: the kernel would not restart the peak count, so "
                             "it is the process's peak\n");
}
double peakMegabytes() {
    return peakResidentBytes() / double(1 << 20);
}

} // namespace

void registerScaleBenchmarks() {
    for (const int radius : {1, 2, 4}) {
        add(
            "scale/drag20_r" + std::to_string(radius) + "_h128/sweepers",
            [radius](benchmark::State& state) {
                StrokeScript script =
                    readStrokeScript(std::string(SWEEPERS_DATA_DIR) + "/drag.json");
                script.start.radius = radius;
                auto& sweep = std::get<SweepStroke>(script.strokes.at(0));
                auto& path = sweep.tools.at(0).path;
                path.resize(21);
                for (Placement& p : path)
                    p.t.z() += radius - 1.0; // the drag runs over the front of the sphere
                std::vector<SegmentReport> reports;
                GridPtr grid;
                for (auto _ : state) {
                    state.PauseTiming();
                    grid.reset();
                    startPeak();
                    grid = makeStartGrid(script, SWEEPERS_DATA_DIR, 1.0 / 128);
                    Sculptor sculptor(grid);
                    sculptor.startMeshing();
                    state.ResumeTiming();
                    reports = applyStrokes(sculptor, script.strokes);
                }
                addSegmentCounters(state, reports);
                state.counters["active_voxels"] = double(grid->activeVoxelCount());
                state.counters["peak_rss_mb"] = peakMegabytes();
            },
            1);
    }
}

void registerThreadBenchmarks() {
    // The drag at 1/256 and 1/512 at 1, 2, 4 and 8 threads and at every core the machine has:
    // the speed-up over one thread (printed against threads_1) and the serial fraction.
    std::vector<int> counts{1, 2, 4, 8};
    const int all = int(std::max(1u, std::thread::hardware_concurrency()));
    if (std::find(counts.begin(), counts.end(), all) == counts.end()) counts.push_back(all);
    for (const int div : {256, 512})
        for (const int threads : counts)
            add(
                "threads/drag100_h" + std::to_string(div) + "/threads_" + std::to_string(threads),
                [div, threads](benchmark::State& state) {
                    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                                    std::size_t(threads));
                    const StrokeScript script =
                        readStrokeScript(std::string(SWEEPERS_DATA_DIR) + "/drag.json");
                    std::vector<SegmentReport> reports;
                    for (auto _ : state) {
                        state.PauseTiming();
                        Sculptor sculptor(makeStartGrid(script, SWEEPERS_DATA_DIR, 1.0 / div));
                        sculptor.startMeshing();
                        state.ResumeTiming();
                        reports = applyStrokes(sculptor, script.strokes);
                    }
                    addSegmentCounters(state, reports);
                    state.counters["threads"] = threads;
                },
                1);
}

void registerDragBenchmarks() {
    // Every size of the run, and one twice as fine as the finest (1/512 by default): where
    // the interactive budget stands on a grid finer than the modeler's default.
    std::vector<int> divisions = voxelDivisions();
    divisions.push_back(2 * *std::max_element(divisions.begin(), divisions.end()));
    for (const int div : divisions) {
        add(
            "drag/drag100_h" + std::to_string(div) + "/sweepers",
            [div](benchmark::State& state) {
                const std::string path = std::string(SWEEPERS_DATA_DIR) + "/drag.json";
                const StrokeScript script = readStrokeScript(path);
                std::vector<SegmentReport> reports;
                GridPtr grid;
                for (auto _ : state) {
                    state.PauseTiming();
                    grid.reset();
                    startPeak();
                    grid = makeStartGrid(script, SWEEPERS_DATA_DIR, 1.0 / div);
                    Sculptor sculptor(grid);
                    sculptor.startMeshing();
                    state.ResumeTiming();
                    reports = applyStrokes(sculptor, script.strokes);
                }
                addSegmentCounters(state, reports);
                state.counters["active_voxels"] = double(grid->activeVoxelCount());
                state.counters["peak_rss_mb"] = peakMegabytes();
            },
            1);
    }
}

} // namespace sweepers::bench
