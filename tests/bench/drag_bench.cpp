// The interactive budget: data/drag.json, a recorded drag of 100 short segments with a
// ball tool of radius 0.25 on the unit sphere, replayed as the modeler does it (advect,
// renormalize, re-mesh the touched leaves after every segment). Reports the latency of a
// segment, p50 and p95, split by stage, and the process's peak memory.
#include <sys/resource.h>

#include <algorithm>

#include "bench.h"
#include "core/statistics.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "sculpt/sculptor.h"

namespace sweepers::bench {
void registerDragBenchmarks() {
    for (const int div : voxelDivisions()) {
        add(
            "drag/drag100_h" + std::to_string(div) + "/sweepers",
            [div](benchmark::State& state) {
                const std::string path = std::string(SWEEPERS_DATA_DIR) + "/drag.json";
                const StrokeScript script = readStrokeScript(path);
                std::vector<SegmentReport> reports;
                GridPtr grid;
                for (auto _ : state) {
                    state.PauseTiming();
                    grid = makeStartGrid(script, SWEEPERS_DATA_DIR, 1.0 / div);
                    Sculptor sculptor(grid);
                    sculptor.startMeshing();
                    state.ResumeTiming();
                    reports = applyStrokes(sculptor, script.strokes);
                }
                std::vector<double> total, advect, renorm, mesh;
                for (const SegmentReport& r : reports) {
                    total.push_back(1e3 * (r.seconds + r.meshSeconds));
                    advect.push_back(1e3 * (r.stats.growSeconds + r.stats.sampleSeconds));
                    renorm.push_back(1e3 * r.stats.renormalizeSeconds);
                    mesh.push_back(1e3 * r.meshSeconds);
                }
                for (const auto& [name, v] : {std::pair{"segment", &total},
                                              {"advect", &advect},
                                              {"renorm", &renorm},
                                              {"mesh", &mesh}}) {
                    state.counters[std::string(name) + "_p50_ms"] = percentile(*v, 0.5);
                    state.counters[std::string(name) + "_p95_ms"] = percentile(*v, 0.95);
                }
                state.counters["segments"] = double(reports.size());
                state.counters["active_voxels"] = double(grid->activeVoxelCount());
                rusage usage{};
                getrusage(RUSAGE_SELF, &usage);
                state.counters["peak_rss_mb"] = double(usage.ru_maxrss) / 1024.0;
            },
            1);
    }
}

} // namespace sweepers::bench
