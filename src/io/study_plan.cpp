// SPDX-License-Identifier: Apache-2.0
#include "io/study_plan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>
#include <unistd.h>
#include <xxhash.h>

#include "core/memory.h"
#include "core/stopwatch.h"
#include "io/atomic_file.h"
#include "io/baked_tool.h"
#include "io/mesh_file.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "io/study_files.h"
#include "io/vdb_file.h"
#include "vdb/parallel.h"

namespace sweepers {

namespace {

using nlohmann::json;

constexpr const char* kPlanFormat = "sweepers study plan 1";
constexpr const char* kResultFormat = "sweepers study result 1";

// What a run holds before it has a grid: the program, its libraries and thread stacks.
constexpr double kRunBaseMb = 64.0;

// Running time relative to the default engine: the cubic samples 64 values where the
// corrected trilinear takes 32 near the surface and 8 elsewhere; resampling at every sub-step
// renormalizes as often.
double variantCost(StudyVariant v) {
    switch (v) {
    case StudyVariant::Cubic:
    case StudyVariant::PerSubStep:
        return 2.0;
    case StudyVariant::Corrected:
    case StudyVariant::Trilinear:
    case StudyVariant::FirstOrder:
        break;
    }
    return 1.0;
}

class Digest {
  public:
    Digest() : state_(XXH3_createState()) {
        if (!state_) throw std::bad_alloc();
        XXH3_64bits_reset(state_);
    }
    ~Digest() { XXH3_freeState(state_); }
    Digest(const Digest&) = delete;
    Digest& operator=(const Digest&) = delete;
    Digest& add(const std::string& text) {
        // The length first: "ab" + "c" and "a" + "bc" differ.
        const std::uint64_t n = text.size();
        XXH3_64bits_update(state_, &n, sizeof n);
        XXH3_64bits_update(state_, text.data(), text.size());
        return *this;
    }
    Digest& addFile(const std::string& path) {
        requireRegularFile(path);
        std::ifstream in(path, std::ios::binary);
        if (!in) throw FileError(path + ": cannot read it");
        std::vector<char> buffer(1 << 20);
        while (in) {
            in.read(buffer.data(), std::streamsize(buffer.size()));
            XXH3_64bits_update(state_, buffer.data(), std::size_t(in.gcount()));
        }
        if (in.bad()) throw FileError(path + ": cannot read it");
        return *this;
    }
    std::string hex() const {
        char out[17];
        std::snprintf(out, sizeof out, "%016llx",
                      static_cast<unsigned long long>(XXH3_64bits_digest(state_)));
        return out;
    }

  private:
    XXH3_state_t* state_;
};

// A double written so that it reads back exactly (a hexadecimal float).
std::string exact(double v) {
    char out[40];
    std::snprintf(out, sizeof out, "%a", v);
    return out;
}

std::string absolutePath(const std::string& path) {
    return std::filesystem::absolute(path).lexically_normal().string();
}

std::string hostName() {
    char name[256] = {};
    if (::gethostname(name, sizeof name - 1) != 0) return "unknown";
    return name;
}

std::string planPath(const std::string& dir) {
    return dir + "/plan.json";
}

std::string resultPath(const StudyPlan& plan, const PlannedRun& run) {
    return runDirectory(plan, run) + "/result.json";
}

StudyRow plannedRow(const StudyPlan& plan, const PlannedRun& run) {
    StudyRow row;
    row.script = plan.scripts[run.script].name;
    row.variant = variantName(run.variant);
    row.voxelSize = run.voxelSize;
    return row;
}

json readJsonFile(const std::string& path) {
    requireRegularFile(path, kMostTextBytes, "a study's file");
    std::ifstream in(path);
    if (!in) throw FileError(path + ": cannot read it");
    try {
        return json::parse(in);
    } catch (const json::exception&) {
        throw FileError(path + ": not a JSON file");
    }
}

// What a script's runs are made of: its text and every file it reads.
std::string scriptDigest(StrokeScript& script, const std::string& text, const std::string& base) {
    Digest digest;
    digest.add(text);
    forEachScriptFile(script, [&](std::string& input) {
        if (input.empty()) return;
        digest.add(input).addFile(resolveAgainst(input, base));
    });
    return digest.hex();
}

} // namespace

StudyPlan planStudy(const std::vector<std::string>& scripts, const std::vector<double>& voxelSizes,
                    const std::vector<StudyVariant>& variants, const std::string& dir, bool force) {
    StudyPlan plan;
    plan.dir = absolutePath(dir);
    plan.version = SWEEPERS_VERSION;
    plan.force = force;
    std::map<std::string, int> seen;
    for (const std::string& file : scripts) {
        StudyScript s;
        s.path = absolutePath(file);
        std::string text;
        StrokeScript script = readStrokeScript(file, &text);
        for (const double h : voxelSizes)
            requireBuildableStart(script, h, force); // the limits apply holds the script to
        s.digest = scriptDigest(script, text, directoryOf(s.path));
        const std::string stem = std::filesystem::path(file).stem().string();
        const int n = ++seen[stem];
        s.name = n == 1 ? stem : stem + "-" + std::to_string(n);
        plan.scripts.push_back(s);
    }
    for (std::size_t k = 0; k < plan.scripts.size(); ++k)
        for (const double h : voxelSizes)
            for (const StudyVariant v : variants) {
                PlannedRun run;
                run.script = k;
                run.voxelSize = h;
                run.variant = v;
                run.id = studyRunId(plannedRow(plan, run));
                run.digest = Digest()
                                 .add(plan.version)
                                 .add(plan.scripts[k].digest)
                                 .add(exact(h))
                                 .add(variantName(v))
                                 .hex();
                plan.runs.push_back(run);
            }
    return plan;
}

void writeStudyPlan(const StudyPlan& plan) {
    nlohmann::ordered_json scripts = nlohmann::ordered_json::array(),
                           runs = nlohmann::ordered_json::array();
    for (const StudyScript& s : plan.scripts)
        scripts.push_back({{"name", s.name}, {"path", s.path}, {"digest", s.digest}});
    for (const PlannedRun& r : plan.runs) {
        nlohmann::ordered_json estimate = {
            {"memory_mb", r.memoryMb > 0.0 ? nlohmann::ordered_json(std::ceil(r.memoryMb))
                                           : nlohmann::ordered_json()},
            {"seconds",
             r.seconds > 0.0 ? nlohmann::ordered_json(r.seconds) : nlohmann::ordered_json()},
            {"threads", r.threads},
            {"basis", r.basis}};
        runs.push_back({{"id", r.id},
                        {"script", plan.scripts[r.script].name},
                        {"voxel_size", r.voxelSize},
                        {"variant", variantName(r.variant)},
                        {"digest", r.digest},
                        {"estimate", estimate}});
    }
    const nlohmann::ordered_json out = {{"format", kPlanFormat},
                                        {"version", plan.version},
                                        {"force", plan.force},
                                        {"keep", keptName(plan.outputs)},
                                        {"half", plan.outputs.half},
                                        {"scripts", scripts},
                                        {"runs", runs}};
    writeTextAtomically(planPath(plan.dir), out.dump(2) + "\n");
}

StudyPlan readStudyPlan(const std::string& dir) {
    const std::string path = planPath(absolutePath(dir));
    if (!std::filesystem::exists(path))
        throw FileError(dir +
                        ": no study plan there (plan.json); plan one with "
                        "sweepers-cli study SCRIPT... -o " +
                        dir);
    const json j = readJsonFile(path);
    const auto bad = [&](const std::string& why) {
        return FileError(path + ": " + why + " (plan the study again)");
    };
    if (!j.is_object() || j.value("format", "") != kPlanFormat)
        throw bad("not a study plan of this version");
    StudyPlan plan;
    plan.dir = absolutePath(dir);
    try {
        plan.version = j.at("version").get<std::string>();
        plan.force = j.at("force").get<bool>();
        // (Plans written before --keep and --half kept both, at full precision.)
        const auto kept = parseKept(j.value("keep", std::string("both")));
        if (!kept) throw bad("'keep' is not one of both, grids, meshes, none");
        plan.outputs = *kept;
        plan.outputs.half = j.value("half", false);
        std::map<std::string, std::size_t> byName;
        for (const json& s : j.at("scripts")) {
            byName[s.at("name").get<std::string>()] = plan.scripts.size();
            plan.scripts.push_back({s.at("name").get<std::string>(),
                                    s.at("path").get<std::string>(),
                                    s.at("digest").get<std::string>()});
        }
        for (const json& r : j.at("runs")) {
            PlannedRun run;
            run.id = r.at("id").get<std::string>();
            const auto script = byName.find(r.at("script").get<std::string>());
            const auto variant = parseVariant(r.at("variant").get<std::string>());
            run.voxelSize = r.at("voxel_size").get<double>();
            if (script == byName.end() || !variant || !(run.voxelSize > 0.0))
                throw bad("run " + run.id + " is not one of a study");
            run.script = script->second;
            run.variant = *variant;
            // An id names the run's directory under runs/: only the one its fields make.
            if (run.id != studyRunId(plannedRow(plan, run)))
                throw bad("run " + run.id + " is not one of a study");
            run.digest = r.at("digest").get<std::string>();
            const json& e = r.at("estimate");
            run.memoryMb = e.at("memory_mb").is_number() ? e.at("memory_mb").get<double>() : 0.0;
            run.seconds = e.at("seconds").is_number() ? e.at("seconds").get<double>() : 0.0;
            run.threads = e.at("threads").get<int>();
            run.basis = e.at("basis").get<std::string>();
            plan.runs.push_back(run);
        }
    } catch (const json::exception&) {
        throw bad("not a study plan of this version");
    }
    if (plan.version != SWEEPERS_VERSION)
        throw FileError(path + ": planned by sweepers " + plan.version + ", not by this " +
                        SWEEPERS_VERSION + " (plan the study again)");
    return plan;
}

const PlannedRun& findRun(const StudyPlan& plan, const std::string& id) {
    for (const PlannedRun& r : plan.runs)
        if (r.id == id) return r;
    std::string ids;
    for (const PlannedRun& r : plan.runs)
        ids += (ids.empty() ? "" : ", ") + r.id;
    throw FileError(plan.dir + ": the study has no run '" + id + "' (its runs: " + ids + ")");
}

std::optional<StudyOutputs> parseKept(const std::string& keep) {
    StudyOutputs out;
    if (keep == "both") return out;
    if (keep != "grids" && keep != "meshes" && keep != "none") return std::nullopt;
    out.grids = keep == "grids";
    out.meshes = keep == "meshes";
    return out;
}

std::string keptName(const StudyOutputs& outputs) {
    if (outputs.grids) return outputs.meshes ? "both" : "grids";
    return outputs.meshes ? "meshes" : "none";
}

std::string runDirectory(const StudyPlan& plan, const PlannedRun& run) {
    return plan.dir + "/runs/" + run.id;
}

std::optional<StudyRow> readRunResult(const StudyPlan& plan, const PlannedRun& run) {
    const std::string path = resultPath(plan, run);
    if (!std::filesystem::exists(path)) return std::nullopt;
    // A result that cannot be read is no result: the run runs again and replaces it.
    try {
        const json j = readJsonFile(path);
        if (j.value("format", "") != kResultFormat || j.value("digest", "") != run.digest)
            return std::nullopt;
        StudyRow row = studyRowFromJson(j.at("row"), path);
        if (row.voxelSize != run.voxelSize || row.variant != variantName(run.variant))
            return std::nullopt;
        return row;
    } catch (const std::exception&) {
        return std::nullopt;
    }
}

bool runIsDone(const StudyPlan& plan, const PlannedRun& run) {
    const std::optional<StudyRow> row = readRunResult(plan, run);
    return row && row->failure.empty();
}

StudyRow executeStudyRun(const StudyPlan& plan, const PlannedRun& run, Interrupter* interrupter,
                         const Progress& progress) {
    const std::string dir = runDirectory(plan, run);
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw FileError(dir + ": cannot create the run's directory (" + ec.message() + ")");
    const StudyScript& source = plan.scripts[run.script];
    const auto started = Clock::now();
    StudyRow row = plannedRow(plan, run);
    row.host = hostName();
    row.threads = int(loopThreads());
    std::optional<StudyRun> done;
    try {
        // The script as it is now must be the one planned: a result says what it was made of.
        std::string text;
        StrokeScript script = readStrokeScript(source.path, &text);
        if (scriptDigest(script, text, directoryOf(source.path)) != source.digest)
            throw ScriptError(source.path +
                              ": changed since the study was planned (plan the study again)");
        const GridPtr start =
            makeStartGrid(script, directoryOf(source.path), run.voxelSize, interrupter, plan.force);
        if (plan.outputs.half)
            if (const std::string why = halfPrecisionProblem(run.voxelSize, halfWidthOf(*start));
                !why.empty())
                throw ScriptError("--half: " + why);
        done = runStudyCase(start, script.strokes, exactStart(script, start), run.variant,
                            interrupter, progress);
        // Both files are written before either is put in place; a file the plan does not keep
        // is removed, so a run's directory holds what its plan says, whatever ran there before.
        const std::string gridPath = dir + "/grid.vdb", meshPath = dir + "/mesh.ply";
        std::optional<AtomicWrite> vdb, mesh;
        LevelSetWriteOptions precision;
        precision.half = plan.outputs.half;
        if (plan.outputs.grids) vdb.emplace(prepareLevelSet(*done->grid, gridPath, precision));
        if (plan.outputs.meshes) mesh.emplace(prepareMesh(done->mesh, meshPath));
        for (const auto& [kept, path] :
             {std::pair{plan.outputs.grids, gridPath}, std::pair{plan.outputs.meshes, meshPath}})
            if (!kept && !std::filesystem::remove(path, ec) && ec)
                throw FileError(path + ": cannot remove what the plan no longer keeps (" +
                                ec.message() + ")");
        if (vdb) vdb->commit();
        if (mesh) mesh->commit();
        // What a job running it needs: measuring and above all writing the files can take
        // more memory than sculpting did.
        done->row.peakRssMb = std::max(done->row.peakRssMb, peakResidentBytes() / double(1 << 20));
        done->row.runSeconds = secondsSince(started);
        const std::string host = row.host;
        const int threads = row.threads;
        row = done->row;
        // The size planned, which the grid was made at (its transform may hold it an ulp
        // off): results are matched to runs by it.
        row.voxelSize = run.voxelSize;
        row.script = source.name;
        row.host = host;
        row.threads = threads;
    } catch (const Cancelled&) {
        throw;
    } catch (const std::exception& e) {
        row.failure = e.what();
    }
    const json result = {{"format", kResultFormat},
                         {"id", run.id},
                         {"digest", run.digest},
                         {"version", plan.version},
                         {"row", studyRowJson(row, true)}};
    writeTextAtomically(resultPath(plan, run), result.dump(2) + "\n");
    return row;
}

void estimateStudyRuns(StudyPlan& plan, int threads) {
    for (std::size_t k = 0; k < plan.scripts.size(); ++k) {
        // The script's finished runs, one per voxel size (the first variant that finished
        // there): their sculpting as the default engine's, and their measuring.
        struct Measured {
            StudyRow row;
            std::string id;
            double sculpt, measure, rest; // rest: building the start and writing the files
        };
        std::vector<Measured> measured;
        for (const PlannedRun& r : plan.runs) {
            if (r.script != k) continue;
            const std::optional<StudyRow> row = readRunResult(plan, r);
            if (!row || !row->failure.empty()) continue;
            if (std::any_of(measured.begin(), measured.end(),
                            [&](const Measured& m) { return m.row.voxelSize == row->voxelSize; }))
                continue;
            measured.push_back(
                {*row, r.id, row->wallSeconds / variantCost(r.variant), row->measureSeconds,
                 std::max(0.0, row->runSeconds - row->wallSeconds - row->measureSeconds)});
        }
        // A run's time is its sculpting and its measuring. Sculpting grows as the band's
        // voxels (1/h^2) times the sub-steps, which some strokes take per voxel (up to
        // 1/h^3); measuring as the voxels and crossings (1/h^2) times the history's
        // deformations that reach them, fewer for each as the voxels shrink. Each exponent is
        // fitted to the two finest runs where there are two, within [2, 3]; 3, an upper
        // bound, where there is one. The rest (the start built, the files written) grows as
        // the voxels.
        std::sort(measured.begin(), measured.end(), [](const Measured& a, const Measured& b) {
            return a.row.voxelSize > b.row.voxelSize;
        });
        double sculptExponent = 3.0, measureExponent = 3.0;
        if (measured.size() >= 2) {
            const Measured& coarse = measured[measured.size() - 2];
            const Measured& fine = measured.back();
            const double halvings = std::log(coarse.row.voxelSize / fine.row.voxelSize);
            const auto fitted = [&](double a, double b) {
                return a > 0.0 && b > 0.0 ? std::clamp(std::log(b / a) / halvings, 2.0, 3.0) : 3.0;
            };
            sculptExponent = fitted(coarse.sculpt, fine.sculpt);
            measureExponent = fitted(coarse.measure, fine.measure);
        }
        // Memory grows with the band's voxels by what each voxel costs a run (the grid, the
        // sampler's copies, the mesh, the reference's signs): fitted to the two finest runs
        // once the finer one's grid holds a third of its memory (below, the program's own
        // memory hides what a voxel costs), never under kRunBytesPerVoxel before.
        double bytesPerVoxel = kRunBytesPerVoxel;
        if (measured.size() >= 2) {
            const StudyRow& coarse = measured[measured.size() - 2].row;
            const StudyRow& fine = measured.back().row;
            const double grown = double(fine.activeVoxels) - double(coarse.activeVoxels);
            const double fitted =
                grown > 0.0 ? (fine.peakRssMb - coarse.peakRssMb) * double(1 << 20) / grown : 0.0;
            bytesPerVoxel = fine.peakRssMb >= 1.5 * kRunBaseMb && fitted > 0.0
                                ? fitted
                                : std::max(fitted, kRunBytesPerVoxel);
        }
        std::optional<StrokeScript> script;
        for (PlannedRun& r : plan.runs) {
            if (r.script != k) continue;
            r.threads = threads;
            if (!measured.empty()) {
                // Scaled from the finest measured run at least as coarse as this one (or
                // the coarsest, for a run coarser than all).
                const Measured* from = &measured.front();
                for (const Measured& m : measured)
                    if (m.row.voxelSize >= r.voxelSize) from = &m;
                const StudyRow& b = from->row;
                const double scale = b.voxelSize / r.voxelSize;
                const double voxels = double(b.activeVoxels) * scale * scale;
                r.memoryMb = b.peakRssMb + std::max(0.0, voxels - double(b.activeVoxels)) *
                                               bytesPerVoxel / double(1 << 20);
                r.seconds =
                    (from->sculpt * std::pow(scale, sculptExponent) * variantCost(r.variant) +
                     from->measure * std::pow(scale, measureExponent) +
                     from->rest * scale * scale) *
                    std::max(1.0, double(b.threads) / double(threads));
                r.basis = "measured run " + from->id;
                continue;
            }
            // Nothing has run: the start's band, for a sphere (a file's area is not known
            // before it is read at that voxel size).
            if (!script) script = readStrokeScript(plan.scripts[k].path);
            const GridSpec& grid = script->grid;
            double voxels = 0.0;
            if (script->start.kind == StartShape::Kind::Sphere)
                voxels = 4.0 * M_PI * script->start.radius * script->start.radius * 2.0 *
                         grid.halfWidth / (r.voxelSize * r.voxelSize);
            r.memoryMb = kRunBaseMb + voxels * kRunBytesPerVoxel / double(1 << 20);
            r.seconds = 0.0;
            r.basis = "start band (no run finished yet)";
        }
    }
}

StudyResults collectStudyResults(const StudyPlan& plan) {
    StudyResults out;
    for (const PlannedRun& run : plan.runs) {
        std::optional<StudyRow> row = readRunResult(plan, run);
        if (!row) {
            out.missing.push_back(plannedRow(plan, run));
            out.missingIds.push_back(run.id);
            continue;
        }
        row->script = plan.scripts[run.script].name;
        if (!row->failure.empty()) out.failedIds.push_back(run.id);
        out.rows.push_back(*row);
    }
    fillOrders(out.rows);
    return out;
}

void writeStudyTable(const StudyPlan& plan, const StudyResults& results) {
    writeTextAtomically(plan.dir + "/study.csv", studyCsv(results.rows));
}

std::string mergeStudy(const StudyPlan& plan, const StudyResults& results) {
    writeStudyTable(plan, results);
    writeTextAtomically(plan.dir + "/report.md", studyReport(results.rows, results.missing));
    try {
        writeStudyPlots(results.rows, plan.dir);
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

} // namespace sweepers
