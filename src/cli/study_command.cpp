// SPDX-License-Identifier: Apache-2.0
#include "cli/study_command.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "cli/child_process.h"
#include "cli/command.h"
#include "cli/slurm.h"
#include "core/format.h"
#include "core/limits.h"
#include "io/atomic_file.h"
#include "io/study_files.h"
#include "io/study_plan.h"

namespace sweepers::cli {

namespace {

using nlohmann::json;

// "1/32,1/64,0.01": voxel sizes as decimals or 1/N, coarsest first.
std::vector<double> parseVoxelSizes(const std::string& list) {
    std::vector<double> sizes;
    std::stringstream in(list);
    std::string item;
    while (std::getline(in, item, ',')) {
        const std::string bad =
            "--voxel-sizes: '" + item + "' is not a voxel size (a decimal such as 0.02, or 1/N)";
        const bool fraction = item.rfind("1/", 0) == 0;
        const std::string digits = fraction ? item.substr(2) : item;
        std::size_t used = 0;
        double v = 0.0;
        try {
            v = std::stod(digits, &used);
        } catch (const std::exception&) {
            throw UsageError(bad);
        }
        if (used != digits.size() || !std::isfinite(v)) throw UsageError(bad);
        if (v <= 0.0) throw UsageError("--voxel-sizes: '" + item + "' is not a positive size");
        const double h = fraction ? 1.0 / v : v;
        if (std::find(sizes.begin(), sizes.end(), h) != sizes.end())
            throw UsageError("--voxel-sizes: '" + item + "' is given twice");
        sizes.push_back(h);
    }
    if (sizes.empty()) throw UsageError("--voxel-sizes: no voxel size given");
    std::sort(sizes.begin(), sizes.end(), std::greater<>());
    return sizes;
}

std::vector<StudyVariant> parseVariants(const std::string& list) {
    std::vector<StudyVariant> out;
    std::stringstream in(list);
    std::string item;
    while (std::getline(in, item, ',')) {
        const auto v = parseVariant(item);
        if (!v)
            throw UsageError("--variants: unknown variant '" + item + "' (" + variantNames() + ")");
        if (std::find(out.begin(), out.end(), *v) == out.end()) out.push_back(*v);
    }
    if (out.empty()) throw UsageError("--variants: no variant given");
    return out;
}

int totalThreads(const StudyArgs& a) {
    if (a.threads && *a.threads > 0) return *a.threads;
    return int(std::max(1u, std::thread::hardware_concurrency()));
}

// --keep and --half, given, replace what the plan keeps for the runs still to run.
void applyOutputs(const StudyArgs& a, StudyPlan& plan) {
    if (!a.keep.empty()) {
        const std::optional<StudyOutputs> kept = parseKept(a.keep);
        if (!kept)
            throw UsageError("--keep: '" + a.keep + "' is not one of both, grids, meshes, none");
        plan.outputs.grids = kept->grids;
        plan.outputs.meshes = kept->meshes;
    }
    if (a.half) plan.outputs.half = true;
}

// The plan of the scripts given (checked before anything is written), or the plan already
// in the directory when none is given.
StudyPlan makePlan(const StudyArgs& a) {
    if (a.scripts.empty()) {
        if (!std::filesystem::exists(a.dir + "/plan.json"))
            throw UsageError("study: no script given, and " + a.dir +
                             " holds no study to go on with (plan.json)");
        StudyPlan plan = readStudyPlan(a.dir);
        applyOutputs(a, plan);
        return plan;
    }
    const std::vector<double> sizes = parseVoxelSizes(a.voxelSizes);
    const std::vector<StudyVariant> variants = parseVariants(a.variants);
    StudyPlan plan = planStudy(a.scripts, sizes, variants, a.dir, a.force);
    applyOutputs(a, plan);
    std::error_code ec;
    std::filesystem::create_directories(a.dir, ec);
    if (ec)
        throw std::runtime_error(a.dir + ": cannot create the study directory (" + ec.message() +
                                 ")");
    if (::access(a.dir.c_str(), W_OK) != 0)
        throw std::runtime_error(a.dir + ": cannot write there (not a writable directory)");
    return plan;
}

std::string runLine(const StudyRow& row) {
    if (!row.failure.empty()) return ": failed: " + row.failure;
    char line[128];
    std::snprintf(line, sizeof line, ": done in %.2f s (measured in %.2f s), RMS error %.3g voxels",
                  row.wallSeconds, row.measureSeconds, row.error.rms / row.voxelSize);
    return line;
}

std::string joined(const std::vector<std::string>& items) {
    std::string out;
    for (const std::string& s : items)
        out += (out.empty() ? "" : ", ") + s;
    return out;
}

// The closing lines of a study, its --json object and its exit code: done when every run
// finished and the plots were drawn.
// study --stats: where each run's measuring went, phase by phase.
void printMeasurePhases(const StudyResults& results) {
    std::fprintf(stderr, "%-36s %8s %8s %8s %9s %9s %10s %9s %10s\n",
                 "measured in seconds:", "wall", "measure", "grid", "voxels", "crossings",
                 "(count)", "vertices", "(count)");
    for (const StudyRow& r : results.rows) {
        if (!r.failure.empty()) continue;
        const InterfaceError::Phases& p = r.error.phases;
        const std::string run = r.script + " " + r.variant + " " + formatNumber(r.voxelSize);
        std::fprintf(stderr, "%-36s %8.2f %8.2f %8.2f %9.2f %9.2f %10zu %9.2f %10zu\n", run.c_str(),
                     r.wallSeconds, r.measureSeconds, r.gridMeasureSeconds, p.voxels, p.crossings,
                     p.crossingCount, p.vertices, p.vertexCount);
    }
}

int finishStudy(const StudyArgs& a, const StudyPlan& plan, const StudyResults& results,
                std::size_t reused, const std::string& plotsError,
                const json& extra = json::object()) {
    if (a.stats) printMeasurePhases(results);
    const std::string csv = plan.dir + "/study.csv", report = plan.dir + "/report.md";
    const std::size_t failed = results.failedIds.size(), missing = results.missingIds.size();
    gOut.say("wrote " + csv + " and " + report + ": " + std::to_string(results.rows.size()) +
             " runs (" + std::to_string(reused) + " reused from before, " + std::to_string(failed) +
             " failed" + (missing ? ", " + std::to_string(missing) + " without a result" : "") +
             ")");
    if (!plotsError.empty()) std::fprintf(stderr, "sweepers-cli: %s\n", plotsError.c_str());
    if (failed > 0)
        std::fprintf(stderr, "sweepers-cli: %zu of %zu runs failed (%s); see %s\n", failed,
                     plan.runs.size(), joined(results.failedIds).c_str(), report.c_str());
    if (missing > 0)
        std::fprintf(stderr,
                     "sweepers-cli: %zu of %zu runs have no result (%s); the same command "
                     "runs them\n",
                     missing, plan.runs.size(), joined(results.missingIds).c_str());
    if (gOut.json) {
        json files = json::array();
        for (const PlannedRun& r : plan.runs)
            if (runIsDone(plan, r))
                for (const char* name : {"/grid.vdb", "/mesh.ply"})
                    if (const std::string f = runDirectory(plan, r) + name;
                        std::filesystem::exists(f))
                        files.push_back(f);
        if (plotsError.empty())
            for (const char* f : {"convergence.gp", "convergence.png", "convergence.svg"})
                files.push_back(plan.dir + "/" + f);
        files.push_back(csv);
        files.push_back(report);
        json scripts = json::array();
        for (const StudyScript& s : plan.scripts)
            scripts.push_back(s.path);
        json out = {{"script", plan.scripts.front().path},
                    {"scripts", scripts},
                    {"dir", plan.dir},
                    {"plan", plan.dir + "/plan.json"},
                    {"csv", csv},
                    {"report", report},
                    {"runs", studyJson(results.rows)},
                    {"reused", reused},
                    {"failed", results.failedIds},
                    {"missing", results.missingIds},
                    {"plots_error", plotsError.empty() ? json(nullptr) : json(plotsError)},
                    {"files", files}};
        out.update(extra);
        printJson(out);
    }
    return failed == 0 && missing == 0 && plotsError.empty() ? kDone : kPartlyDone;
}

// One run in this process, its segments shown as `mode` says.
StudyRow runHere(const StudyPlan& plan, const PlannedRun& run, const std::string& which,
                 ProgressMode mode) {
    ProgressLine segments(mode, which, "segment");
    return executeStudyRun(plan, run, &gStop,
                           [&](std::size_t i, std::size_t n) { segments.update(i, n); });
}

// Within a study's own line per run, a run's segments only as a bar on a terminal.
ProgressMode segmentsMode(const ProgressLine& runs) {
    return runs.mode() == ProgressMode::Terminal ? ProgressMode::Terminal : ProgressMode::Quiet;
}

struct Child {
    pid_t pid;
    std::size_t index;
};

// The runs of `pending` here, `jobs` at a time, each in a process of its own with its share
// of the threads (so each measures its own peak memory, and a run that crashes takes no
// other with it), its errors in runs/ID/run.log.
void runSideBySide(const StudyPlan& plan, const std::vector<std::size_t>& pending, int jobs,
                   int threads, const std::function<void(std::size_t, const std::string&)>& said) {
    const std::string program = thisProgram();
    std::vector<Child> running;
    std::size_t next = 0;
    bool stopping = false;
    while (next < pending.size() || !running.empty()) {
        if (gStop.wasInterrupted() && !stopping) {
            stopping = true;
            for (const Child& c : running)
                ::kill(c.pid, SIGTERM);
        }
        while (!stopping && next < pending.size() && int(running.size()) < jobs) {
            const PlannedRun& run = plan.runs[pending[next]];
            const std::string dir = runDirectory(plan, run);
            std::filesystem::create_directories(dir);
            std::vector<std::string> args = {program, "study",     "-q",
                                             "-o",    plan.dir,    "--run",
                                             run.id,  "--threads", std::to_string(threads)};
            // The limits this process was given, the runs too.
            if (limits().memoryBytes > 0.0)
                args.insert(args.end(),
                            {"--max-memory", formatPrecise(limits().memoryBytes / 1e9)});
            if (limits().work > 0.0)
                args.insert(args.end(), {"--max-work", formatPrecise(limits().work)});
            running.push_back({startProgram(args, dir + "/run.log"), pending[next]});
            ++next;
        }
        if (stopping && next < pending.size()) next = pending.size();
        bool ended = false;
        for (auto it = running.begin(); it != running.end();) {
            const int status = waitProgram(it->pid, false);
            if (status < 0) {
                ++it;
                continue;
            }
            ended = true;
            const PlannedRun& run = plan.runs[it->index];
            const std::optional<StudyRow> row = readRunResult(plan, run);
            if (row)
                said(it->index, runLine(*row));
            else if (!stopping)
                said(it->index, ": ended without a result (exit status " + std::to_string(status) +
                                    "); see " + runDirectory(plan, run) + "/run.log");
            // A run that said nothing leaves no log.
            const std::string log = runDirectory(plan, run) + "/run.log";
            std::error_code ec;
            if (std::filesystem::file_size(log, ec) == 0 && !ec) std::filesystem::remove(log, ec);
            it = running.erase(it);
        }
        if (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    pollInterrupt(&gStop);
}

int runLocally(const StudyArgs& a, StudyPlan& plan) {
    const int jobs = std::max(1, a.jobs);
    const int threads = std::max(1, totalThreads(a) / jobs);
    estimateStudyRuns(plan, threads);
    writeStudyPlan(plan);
    std::vector<std::size_t> pending;
    for (std::size_t i = 0; i < plan.runs.size(); ++i)
        if (!runIsDone(plan, plan.runs[i])) pending.push_back(i);
    const std::size_t total = plan.runs.size(), reused = total - pending.size();
    // A line per finished run wherever stderr goes; the segments of the run in progress only
    // as a bar on a terminal (and only when one run runs at a time).
    ProgressLine progress(gOut.progress(), "study", "run");
    progress.setLinesEachTenth(false);
    const auto which = [&](std::size_t i) {
        return "study: run " + std::to_string(i + 1) + " / " + std::to_string(total) + " (" +
               plan.runs[i].id + ")";
    };
    for (std::size_t i = 0; i < total; ++i)
        if (std::find(pending.begin(), pending.end(), i) == pending.end())
            progress.print(which(i) + ": kept from before");
    try {
        if (jobs == 1) {
            for (const std::size_t i : pending) {
                const StudyRow row = runHere(plan, plan.runs[i], which(i), segmentsMode(progress));
                progress.print(which(i) + runLine(row));
                writeStudyTable(plan, collectStudyResults(plan));
            }
        } else {
            runSideBySide(plan, pending, jobs, threads, [&](std::size_t i, const std::string& s) {
                progress.print(which(i) + s);
                writeStudyTable(plan, collectStudyResults(plan));
            });
        }
    } catch (const Cancelled&) {
        // The finished runs are on disk already: say so, rather than "nothing was written".
        const StudyResults results = collectStudyResults(plan);
        writeStudyTable(plan, results);
        std::fprintf(stderr,
                     "sweepers-cli: interrupted after %zu of %zu runs; they are in %s/study.csv "
                     "(the same command resumes the study)\n",
                     results.rows.size(), total, plan.dir.c_str());
        return kInterrupted;
    }
    const StudyResults results = collectStudyResults(plan);
    const std::string plotsError = mergeStudy(plan, results);
    return finishStudy(a, plan, results, reused, plotsError);
}

// --run ID: one run of a planned study, as a Slurm task or another machine runs it.
int runOne(const StudyArgs& a) {
    const StudyPlan plan = readStudyPlan(a.dir);
    const PlannedRun& run = findRun(plan, a.run);
    const StudyRow row = runHere(plan, run, "study: " + run.id, gOut.progress());
    if (gOut.json)
        printJson({{"run", run.id}, {"dir", runDirectory(plan, run)}, {"row", studyRowJson(row)}});
    if (!row.failure.empty()) {
        std::fprintf(stderr, "sweepers-cli: run %s failed: %s\n", run.id.c_str(),
                     row.failure.c_str());
        return kFailed;
    }
    gOut.say("wrote " + runDirectory(plan, run) + runLine(row));
    return kDone;
}

// --list: the runs without a result, one id a line, for other tools to run.
int listRuns(const StudyPlan& plan) {
    json pending = json::array(), done = json::array();
    for (const PlannedRun& r : plan.runs)
        (runIsDone(plan, r) ? done : pending).push_back(r.id);
    if (gOut.json) {
        printJson({{"dir", plan.dir}, {"pending", pending}, {"done", done}});
        return kDone;
    }
    for (const auto& id : pending)
        std::printf("%s\n", id.get<std::string>().c_str());
    return kDone;
}

int submitToSlurm(const StudyArgs& a, StudyPlan& plan) {
    requireNoActiveSubmission(plan);
    std::size_t reused = 0;
    for (const PlannedRun& r : plan.runs)
        reused += runIsDone(plan, r) ? 1 : 0;
    // The others' memory and time are scaled from the runs of their script that finished:
    // the first run of its coarsest voxel size runs here first where none has, and of the
    // next coarsest too where a finer one remains (two sizes fit how time grows; one gives
    // only an upper bound).
    ProgressLine progress(gOut.progress(), "study", "run");
    progress.setLinesEachTenth(false);
    for (std::size_t k = 0; k < plan.scripts.size(); ++k) {
        std::vector<std::size_t> sizes; // the first run of each voxel size, coarsest first
        for (std::size_t i = 0; i < plan.runs.size(); ++i)
            if (plan.runs[i].script == k &&
                std::none_of(sizes.begin(), sizes.end(), [&](std::size_t p) {
                    return plan.runs[p].voxelSize == plan.runs[i].voxelSize;
                }))
                sizes.push_back(i);
        const std::vector<std::size_t> pilots(
            sizes.begin(), sizes.begin() + std::ptrdiff_t(std::min<std::size_t>(
                                               sizes.size() >= 3 ? 2 : 1, sizes.size())));
        for (const std::size_t p : pilots) {
            const PlannedRun& pilot = plan.runs[p];
            const bool measured =
                std::any_of(plan.runs.begin(), plan.runs.end(), [&](const auto& r) {
                    return r.script == k && r.voxelSize == pilot.voxelSize && runIsDone(plan, r);
                });
            if (measured) continue;
            const std::string which = "study: " + pilot.id + " (here, to estimate the others)";
            progress.print(which + runLine(runHere(plan, pilot, which, segmentsMode(progress))));
        }
    }
    SlurmOptions o;
    o.maxRunning = a.maxRunning;
    o.cpusPerTask = a.threads && *a.threads > 0 ? *a.threads : 1;
    o.partition = a.partition;
    o.account = a.account;
    o.sbatchArgs = a.sbatchArgs;
    estimateStudyRuns(plan, o.cpusPerTask);
    writeStudyPlan(plan);
    std::vector<std::size_t> pending;
    json pendingIds = json::array();
    for (std::size_t i = 0; i < plan.runs.size(); ++i)
        if (!runIsDone(plan, plan.runs[i])) {
            pending.push_back(i);
            pendingIds.push_back(plan.runs[i].id);
        }
    if (pending.empty()) {
        gOut.say("study: every run has a result; merging them here");
        const StudyResults results = collectStudyResults(plan);
        return finishStudy(a, plan, results, reused, mergeStudy(plan, results));
    }
    const auto submitted = std::filesystem::file_time_type::clock::now();
    const SlurmSubmission jobs = submitStudy(plan, pending, o);
    gOut.say("study: submitted " + std::to_string(pending.size()) + " of " +
             std::to_string(plan.runs.size()) + " runs as job arrays " + joined(jobs.arrays) +
             " (one per voxel size, each after the one before) and the merge as job " + jobs.merge +
             "; logs in " + plan.dir + "/slurm/logs");
    const json ids = {{"arrays", jobs.arrays}, {"merge", jobs.merge}, {"submitted", pendingIds}};
    if (!a.wait) {
        if (gOut.json) {
            json out = ids;
            out["dir"] = plan.dir;
            out["plan"] = plan.dir + "/plan.json";
            printJson(out);
        } else {
            std::printf("arrays %s\nmerge %s\n", joined(jobs.arrays).c_str(), jobs.merge.c_str());
        }
        return kDone;
    }
    {
        ProgressLine waiting(gOut.progress(), "study: waiting for Slurm", "run");
        waiting.setLinesEachTenth(false);
        try {
            waitForJob(jobs.merge, &gStop, [&] {
                const StudyResults now = collectStudyResults(plan);
                waiting.update(now.rows.size() - (plan.runs.size() - pending.size()),
                               pending.size());
            });
        } catch (const Cancelled&) {
            std::fprintf(stderr,
                         "sweepers-cli: stopped waiting; the jobs go on (scancel %s %s stops "
                         "them)\n",
                         joined(jobs.arrays).c_str(), jobs.merge.c_str());
            return kInterrupted;
        }
    }
    const std::string report = plan.dir + "/report.md";
    std::error_code ec;
    const auto written = std::filesystem::last_write_time(report, ec);
    if (ec || written < submitted)
        throw std::runtime_error(
            "the merge job " + jobs.merge + " wrote no report (" +
            (jobState(jobs.merge).empty() ? std::string("it has ended") : jobState(jobs.merge)) +
            "); see " + plan.dir + "/slurm/logs/merge_" + jobs.merge + ".out");
    const StudyResults results = collectStudyResults(plan);
    const bool plotted = std::filesystem::exists(plan.dir + "/convergence.png");
    return finishStudy(a, plan, results, reused, plotted ? "" : "plots: the merge job drew none",
                       ids);
}

} // namespace

CLI::App* addStudyCommand(CLI::App& app, StudyArgs& a) {
    CLI::App* study = app.add_subcommand(
        "study", "Apply scripts at several voxel sizes and variants, measured against the "
                 "exact shape their history defines: here, or as Slurm jobs");
    study->add_option("scripts", a.scripts,
                      "Stroke scripts (JSON); none to go on with the study in the directory");
    study->add_option("-o,--output", a.dir, "Study directory")->required();
    study->add_option("--voxel-sizes", a.voxelSizes,
                      "Voxel sizes, decimals or 1/N (default 1/32,1/64,1/128,1/256)");
    study->add_option("--variants", a.variants,
                      variantNames() + " (default " + variantName(StudyVariant::Corrected) + ")");
    study->add_flag("--force", a.force,
                    "Build start shapes even when they seem to need more memory than is free");
    CLI::Option* keep =
        study->add_option("--keep", a.keep,
                          "What each run keeps beside its result: both (default), grids, meshes or "
                          "none");
    CLI::Option* half = study->add_flag("--half", a.half, kHalfHelp);
    study->add_flag("--stats", a.stats,
                    "Print where each run's measuring went: the grid's measures, the reference at "
                    "the voxels, at the crossings between them and along the vertex normals");
    study->add_option("--jobs", a.jobs, "Runs at once here, the threads split between them")
        ->check(CLI::Range(1, 1024));
    study->add_option("--threads", *a.threads, "Worker threads (with --slurm: of each run)")
        ->check(CLI::Range(1, 1024));
    CLI::Option* planOnly =
        study->add_flag("--plan-only", a.planOnly, "Write the plan (plan.json) and stop");
    CLI::Option* list =
        study->add_flag("--list", a.list, "Print the ids of the runs without a result, one a line");
    CLI::Option* run =
        study->add_option("--run", a.run, "Run one run of the plan in the directory, by id")
            ->check(CLI::Validator(
                [](std::string& id) {
                    return id.empty() ? "needs a run's id (--list prints them)" : std::string();
                },
                "ID"));
    CLI::Option* merge = study->add_flag(
        "--merge", a.merge, "Merge the results in the directory into the table, report, plots");
    CLI::Option* slurm =
        study->add_flag("--slurm", a.slurm, "Submit the runs without a result to Slurm");
    study->add_flag("--wait", a.wait, "With --slurm: wait for the study to finish")->needs(slurm);
    study->add_option("--max-running", a.maxRunning, "With --slurm: at most K runs at once")
        ->needs(slurm)
        ->check(CLI::Range(1, 100000));
    study->add_option("--partition", a.partition, "With --slurm: the partition")->needs(slurm);
    study->add_option("--account", a.account, "With --slurm: the account")->needs(slurm);
    study
        ->add_option("--sbatch-arg", a.sbatchArgs,
                     "With --slurm: an sbatch option for every job (repeatable), "
                     "such as --sbatch-arg=--qos=long")
        ->needs(slurm);
    for (CLI::Option* one : {run, merge, slurm})
        for (CLI::Option* other : {run, merge, slurm, planOnly, list})
            if (one != other) one->excludes(other);
    // A run and a merge do what the plan in the directory says.
    for (CLI::Option* output : {keep, half})
        for (CLI::Option* step : {run, merge})
            output->excludes(step);
    return study;
}

int runStudy(const StudyArgs& a) {
    if (!a.run.empty()) return runOne(a);
    if (a.merge) {
        const StudyPlan plan = readStudyPlan(a.dir);
        const StudyResults results = collectStudyResults(plan);
        return finishStudy(a, plan, results, 0, mergeStudy(plan, results));
    }
    if (a.slurm) requireSlurm(a.wait); // before anything is planned or run
    StudyPlan plan = makePlan(a);
    if (a.planOnly || a.list) {
        estimateStudyRuns(plan, totalThreads(a));
        writeStudyPlan(plan);
        if (a.list) return listRuns(plan);
        gOut.say("wrote " + plan.dir + "/plan.json: " + std::to_string(plan.runs.size()) + " runs");
        return kDone;
    }
    return a.slurm ? submitToSlurm(a, plan) : runLocally(a, plan);
}

} // namespace sweepers::cli
