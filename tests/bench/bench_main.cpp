// SPDX-License-Identifier: Apache-2.0
// sweepers-bench: our engine against the OpenVDB tools a user would otherwise reach for,
// timed in the same process on the same grids. Google Benchmark runs and times each case;
// this file adds what it lacks: the speed-up of each of our methods over the OpenVDB
// reference of its group, and a CSV of every figure (appended, one run per commit) so
// commits can be compared.
//
//   sweepers-bench [--sizes=64,128,256] [--csv=FILE] [--benchmark_filter=REGEX] ...
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>

#include "bench.h"
#include "core/memory.h"
#include "deform/sweep.h"
#include "levelset/advect.h"
#include "levelset/band.h"
#include "levelset/create.h"
#include "tools/ellipsoid.h"

namespace sweepers::bench {

namespace {
std::vector<int> gDivisions = {64, 128, 256};
} // namespace

const std::vector<int>& voxelDivisions() {
    return gDivisions;
}
void setVoxelDivisions(std::vector<int> divisions) {
    gDivisions = std::move(divisions);
}

GridPtr gridFromSdf(const Sdf& sdf, double voxelSize, const Eigen::Vector3d& lo,
                    const Eigen::Vector3d& hi) {
    initVdb();
    const double halfWidth = 3.0;
    GridPtr g = Grid::create(float(voxelSize * halfWidth));
    g->setTransform(documentTransform(voxelSize));
    const openvdb::Coord a = g->transform().worldToIndexCellCentered(toVdb(lo));
    const openvdb::Coord b = g->transform().worldToIndexCellCentered(toVdb(hi));
    auto acc = g->getAccessor();
    for (auto it = openvdb::CoordBBox(a, b).begin(); it; ++it) {
        const double d = sdf(toEigen(g->indexToWorld(*it)));
        if (std::abs(d) < voxelSize * halfWidth) acc.setValueOn(*it, float(d));
    }
    openvdb::tools::signedFloodFill(g->tree());
    markAsDocument(*g);
    return g;
}

DistanceErrors distanceErrors(const Grid& grid, const Sdf& exact) {
    DistanceErrors e;
    const double h = grid.voxelSize()[0];
    auto acc = grid.getConstAccessor();
    double sumNear = 0.0, sumBand = 0.0;
    std::size_t near = 0, band = 0;
    // Methods keep bands of different widths: only the nominal band (3 voxels) counts.
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf)
        for (auto it = leaf->cbeginValueOn(); it; ++it) {
            const double d = exact(toEigen(grid.indexToWorld(it.getCoord())));
            if (std::abs(d) > 3.0 * h) continue;
            const double err = std::abs(*it - d) / h;
            e.maxBand = std::max(e.maxBand, err);
            sumBand += err * err;
            ++band;
            if (!nextToCrossing(*leaf, it.pos(), acc)) continue;
            e.maxNear = std::max(e.maxNear, err);
            sumNear += err * err;
            ++near;
        }
    e.rmsNear = std::sqrt(sumNear / double(std::max<std::size_t>(near, 1)));
    e.rmsBand = std::sqrt(sumBand / double(std::max<std::size_t>(band, 1)));
    return e;
}

double symmetricDifferenceLayers(const Grid& a, const Grid& b) {
    // A sign can only differ where one of the two grids is active: elsewhere both hold
    // their background of the same sign (inside or outside both shapes).
    auto accA = a.getConstAccessor();
    auto accB = b.getConstAccessor();
    std::size_t differ = 0;
    for (auto it = a.cbeginValueOn(); it; ++it)
        differ += (*it < 0) != (accB.getValue(it.getCoord()) < 0);
    for (auto it = b.cbeginValueOn(); it; ++it)
        if (!accA.isValueOn(it.getCoord()))
            differ += (*it < 0) != (accA.getValue(it.getCoord()) < 0);
    const double h = a.voxelSize()[0];
    const double area = openvdb::tools::levelSetArea(a);
    return double(differ) * h * h * h / (area * h);
}

VdbMesh openvdbMesh(const Grid& grid) {
    VdbMesh m;
    openvdb::tools::volumeToMesh(grid, m.points, m.triangles, m.quads, 0.0, 0.0);
    return m;
}

TriangleMesh toTriangleMesh(const VdbMesh& vdb) {
    TriangleMesh m;
    m.positions.reserve(vdb.points.size());
    for (const auto& p : vdb.points)
        m.positions.emplace_back(p.x(), p.y(), p.z());
    for (const auto& t : vdb.triangles)
        m.triangles.emplace_back(int(t[0]), int(t[1]), int(t[2]));
    for (const auto& q : vdb.quads) {
        m.triangles.emplace_back(int(q[0]), int(q[1]), int(q[2]));
        m.triangles.emplace_back(int(q[0]), int(q[2]), int(q[3]));
    }
    return m;
}

void addMeshCounters(benchmark::State& state, const TriangleMesh& mesh) {
    const MeshTopology topo = meshTopology(mesh);
    state.counters["triangles"] = double(mesh.triangles.size());
    state.counters["watertight"] = topo.watertight() ? 1.0 : 0.0;
    state.counters["oriented"] = topo.consistentlyOriented() ? 1.0 : 0.0;
    state.counters["euler"] = double(topo.eulerCharacteristic());
}

GridPtr afterLargeStroke(int div, bool renormalize, openvdb::CoordBBox* touched) {
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, 1.0 / div, 3.0);
    Placement a, b;
    a.t = {0, 0, 0.9};
    b.t = {0.3, 0.2, 1.5};
    const Sweep sweep{{{std::make_shared<EllipsoidShape>(0.4), 0.5, {a, b}}}};
    AdvectOptions options;
    options.renormalize = renormalize;
    const AdvectStats stats = advectSegment(*g, SweepSegment(sweep, 0), options);
    if (touched) *touched = stats.touched;
    return g;
}

GridPtr timedOnCopies(benchmark::State& state, const Grid& start,
                      const std::function<void(Grid&)>& run) {
    GridPtr g;
    for (auto _ : state) {
        state.PauseTiming();
        g = start.deepCopy();
        state.ResumeTiming();
        run(*g);
    }
    return g;
}

benchmark::internal::Benchmark* add(const std::string& name,
                                    std::function<void(benchmark::State&)> fn, int iterations) {
    return benchmark::RegisterBenchmark(name.c_str(), fn)
        ->Iterations(iterations)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
}

namespace {

// Keeps every run next to the console output, for the ratios and the CSV.
class Collector : public benchmark::ConsoleReporter {
  public:
    void ReportRuns(const std::vector<Run>& runs) override {
        ConsoleReporter::ReportRuns(runs);
        for (const Run& r : runs)
            if (r.run_type == Run::RT_Iteration) runs_.push_back(r);
    }
    const std::vector<Run>& runs() const { return runs_; }

  private:
    std::vector<Run> runs_;
};

struct Name {
    std::string group, item, method;
};

Name split(const std::string& name) {
    Name n;
    std::istringstream in(name);
    std::getline(in, n.group, '/');
    std::getline(in, n.item, '/');
    std::getline(in, n.method, '/');
    return n;
}

// The OpenVDB tool each group is measured against.
std::string referenceOf(const std::string& group) {
    if (group == "advect" || group == "enright") return "openvdb_LevelSetAdvection";
    if (group == "renorm") return "openvdb_sdfToSdf";
    if (group == "mesh") return "openvdb_volumeToMesh";
    if (group == "threads") return "threads_1";
    return "";
}

std::string shell(const std::string& command) {
    std::string out;
    if (FILE* p = popen(command.c_str(), "r")) {
        char buf[256];
        while (std::fgets(buf, sizeof buf, p))
            out += buf;
        pclose(p);
    }
    while (!out.empty() && (out.back() == '\n' || out.back() == ' '))
        out.pop_back();
    return out;
}

std::string cpuModel() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    return "unknown";
}

std::string csvQuote(std::string s) {
    for (char& c : s)
        if (c == ',') c = ';';
    return s;
}

} // namespace
} // namespace sweepers::bench

int main(int argc, char** argv) {
    using namespace sweepers::bench;
    sweepers::keepFreedMemory(); // as the executables do
    std::string csvPath = "sweepers-bench.csv";
    std::vector<char*> rest;
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        if (a.rfind("--sizes=", 0) == 0) {
            std::vector<int> sizes;
            std::istringstream in(a.substr(8));
            for (std::string s; std::getline(in, s, ',');) {
                char* end = nullptr;
                const long v = std::strtol(s.c_str(), &end, 10);
                if (end == s.c_str() || *end != '\0' || v < 8 || v > 1024) {
                    std::fprintf(stderr, "sweepers-bench: --sizes wants divisions of the unit "
                                         "radius between 8 and 1024, like 64,128\n");
                    return 2;
                }
                sizes.push_back(int(v));
            }
            setVoxelDivisions(sizes);
        } else if (a.rfind("--csv=", 0) == 0) {
            csvPath = a.substr(6);
        } else {
            rest.push_back(argv[i]);
        }
    }
    int n = int(rest.size());
    benchmark::Initialize(&n, rest.data());
    if (benchmark::ReportUnrecognizedArguments(n, rest.data())) return 2;

    registerDragBenchmarks();
    registerScaleBenchmarks();
    registerThreadBenchmarks();
    registerAdvectBenchmarks();
    registerRenormalizeBenchmarks();
    registerMeshBenchmarks();
    registerEnrightBenchmarks();
    registerBrushBenchmarks();

    Collector collector;
    benchmark::RunSpecifiedBenchmarks(&collector);

    // Speed-ups against the OpenVDB reference of each group and case.
    std::map<std::string, double> timeOf;
    for (const auto& r : collector.runs()) {
        const Name n = split(r.benchmark_name());
        timeOf[n.group + "/" + n.item + "/" + n.method] = r.GetAdjustedRealTime();
    }
    std::printf("\n%-8s %-22s %-32s %12s %12s %9s\n", "group", "case", "method", "ms",
                "reference ms", "speed-up");
    std::map<std::string, double> speedUp;
    for (const auto& r : collector.runs()) {
        const Name n = split(r.benchmark_name());
        const std::string ref = referenceOf(n.group);
        if (ref.empty() || n.method == ref) continue;
        const auto it = timeOf.find(n.group + "/" + n.item + "/" + ref);
        if (it == timeOf.end()) continue;
        const double ours = r.GetAdjustedRealTime();
        speedUp[r.benchmark_name()] = it->second / ours;
        std::printf("%-8s %-22s %-32s %12.1f %12.1f %8.2fx\n", n.group.c_str(), n.item.c_str(),
                    n.method.c_str(), ours, it->second, it->second / ours);
    }

    // Every figure, appended to the CSV with the commit and the machine.
    const bool fresh = !std::ifstream(csvPath).good();
    std::ofstream csv(csvPath, std::ios::app);
    csv.precision(10);
    if (!csv) {
        std::fprintf(stderr, "sweepers-bench: cannot write %s\n", csvPath.c_str());
        return 1;
    }
    if (fresh) csv << "date,commit,cpu,threads,group,case,method,metric,value\n";
    const std::string src = SWEEPERS_SOURCE_DIR;
    std::string commit = shell("git -C '" + src + "' rev-parse --short HEAD 2>/dev/null");
    if (commit.empty()) commit = "unknown";
    if (!shell("git -C '" + src + "' status --porcelain --untracked-files=no 2>/dev/null").empty())
        commit += "+dirty";
    char date[32];
    const std::time_t now = std::time(nullptr);
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    const std::string prefix = std::string(date) + "," + commit + "," + csvQuote(cpuModel()) + "," +
                               std::to_string(std::thread::hardware_concurrency()) + ",";
    for (const auto& r : collector.runs()) {
        const Name n = split(r.benchmark_name());
        const std::string row = prefix + n.group + "," + n.item + "," + n.method + ",";
        if (r.error_occurred) {
            csv << row << "error," << csvQuote(r.error_message) << "\n";
            continue;
        }
        csv << row << "time_ms," << r.GetAdjustedRealTime() << "\n";
        if (const auto s = speedUp.find(r.benchmark_name()); s != speedUp.end())
            csv << row << (n.group == "threads" ? "speedup_vs_one_thread," : "speedup_vs_openvdb,")
                << s->second << "\n";
        for (const auto& [key, counter] : r.counters)
            csv << row << key << "," << counter.value << "\n";
    }
    std::printf("\nfigures appended to %s (commit %s)\n", csvPath.c_str(), commit.c_str());
    benchmark::Shutdown();
    return 0;
}
