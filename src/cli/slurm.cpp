// SPDX-License-Identifier: Apache-2.0
#include "cli/slurm.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli/child_process.h"
#include "io/atomic_file.h"
#include "io/study_files.h"

namespace sweepers::cli {

namespace {

using nlohmann::json;

// What a run asks Slurm for beyond its estimate: its memory and time are scaled from one
// coarse run, and a run that outgrows its request is killed.
constexpr double kMemoryMargin = 1.5, kMemoryExtraMb = 256.0;
constexpr double kTimeMargin = 2.0, kTimeExtraMinutes = 5.0;
// The merge reads the results and draws the plots.
constexpr int kMergeMemoryMb = 1024, kMergeMinutes = 15;

std::string slurmDir(const StudyPlan& plan) {
    return plan.dir + "/slurm";
}

// A word for bash, in single quotes.
std::string shellWord(const std::string& s) {
    std::string out = "'";
    for (const char c : s)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

int memoryRequestMb(const PlannedRun& r) {
    return int(std::ceil(r.memoryMb * kMemoryMargin + kMemoryExtraMb));
}

// Minutes, or 0 when nothing is known (the partition's limit then applies).
int timeRequestMinutes(const PlannedRun& r) {
    if (!(r.seconds > 0.0)) return 0;
    return int(std::ceil(r.seconds * kTimeMargin / 60.0 + kTimeExtraMinutes));
}

std::string arraySpec(const std::vector<std::size_t>& indices, int maxRunning) {
    std::string spec;
    for (const std::size_t i : indices)
        spec += (spec.empty() ? "" : ",") + std::to_string(i);
    if (maxRunning > 0) spec += "%" + std::to_string(maxRunning);
    return spec;
}

// The lines every job of the study shares: name, account, partition, the user's own.
std::string commonDirectives(const SlurmOptions& o) {
    std::ostringstream out;
    if (!o.partition.empty()) out << "#SBATCH --partition=" << o.partition << "\n";
    if (!o.account.empty()) out << "#SBATCH --account=" << o.account << "\n";
    for (const std::string& a : o.sbatchArgs)
        out << "#SBATCH " << a << "\n";
    return out.str();
}

// sbatch --parsable: "ID" or "ID;CLUSTER".
std::string submit(const std::vector<std::string>& args) {
    std::vector<std::string> argv = {"sbatch", "--parsable"};
    argv.insert(argv.end(), args.begin(), args.end());
    const ProgramOutput r = runProgram(argv);
    std::string id = r.out.substr(0, r.out.find_first_of(";\n"));
    if (r.status != 0 || id.empty()) {
        std::string why = r.err.empty() ? r.out : r.err;
        while (!why.empty() && (why.back() == '\n' || why.back() == '\r'))
            why.pop_back();
        std::replace(why.begin(), why.end(), '\n', ' ');
        throw std::runtime_error("sbatch refused the study's jobs: " + why);
    }
    return id;
}

std::string jobsPath(const StudyPlan& plan) {
    return slurmDir(plan) + "/jobs.json";
}

} // namespace

void requireSlurm(bool wait) {
    if (!onPath("sbatch"))
        throw std::runtime_error("--slurm: sbatch is not installed here (Debian: slurm-client) or "
                                 "not on the PATH; submit from a machine of the cluster");
    if (wait && !onPath("scontrol"))
        throw std::runtime_error("--wait: scontrol is not installed here (Debian: slurm-client) "
                                 "or not on the PATH");
}

void requireNoActiveSubmission(const StudyPlan& plan) {
    std::ifstream in(jobsPath(plan));
    if (!in) return;
    std::vector<std::string> ids;
    try {
        const json j = json::parse(in);
        for (const json& a : j.at("arrays"))
            ids.push_back(a.at("job").get<std::string>());
        ids.push_back(j.at("merge").get<std::string>());
    } catch (const json::exception&) {
        return; // not ours to read: nothing known to be queued
    }
    std::string list;
    for (const std::string& id : ids)
        list += (list.empty() ? "" : ",") + id;
    // squeue fails when it knows none of them (they ended long enough ago to be forgotten).
    const ProgramOutput r = runProgram({"squeue", "-h", "-o", "%A", "-j", list});
    if (r.status != 0 || r.out.find_first_not_of(" \n") == std::string::npos) return;
    throw std::runtime_error("jobs of this study's last submission (" + list +
                             ") are still queued or running; wait for them, or cancel them "
                             "with scancel " +
                             list + ", then submit again");
}

SlurmScripts slurmScripts(const StudyPlan& plan, const std::vector<std::size_t>& pending,
                          const SlurmOptions& options, const std::string& program) {
    const std::string dir = slurmDir(plan), logs = dir + "/logs";
    SlurmScripts out;
    // Tiers of one voxel size each, coarsest first; each asks for its largest run.
    std::map<double, std::vector<std::size_t>, std::greater<>> tiers;
    int memoryAll = 0, minutesAll = 0;
    for (const std::size_t i : pending) {
        tiers[plan.runs[i].voxelSize].push_back(i);
        memoryAll = std::max(memoryAll, memoryRequestMb(plan.runs[i]));
        minutesAll = std::max(minutesAll, timeRequestMinutes(plan.runs[i]));
    }

    std::ostringstream runs;
    runs << "#!/bin/bash\n"
         << "# The runs of the grid-resolution study in " << plan.dir << " as a Slurm job\n"
         << "# array: task N runs the plan's run N (plan.json). Written by sweepers-cli study\n"
         << "# --slurm, which submits it once per voxel size, coarsest first and each after\n"
         << "# the one before, with that size's memory and time on sbatch's command line. As it\n"
         << "# stands it runs every run that had no result, with the largest request:\n"
         << "#   sbatch " << dir << "/runs.sbatch\n"
         << "#SBATCH --job-name=sweepers-study\n"
         << "#SBATCH --output=" << logs << "/%A_%a.out\n"
         << "#SBATCH --cpus-per-task=" << options.cpusPerTask << "\n"
         << "#SBATCH --array=" << arraySpec(pending, options.maxRunning) << "\n"
         << "#SBATCH --mem=" << memoryAll << "M\n";
    if (minutesAll > 0) runs << "#SBATCH --time=" << minutesAll << "\n";
    runs << commonDirectives(options) << "runs=(";
    for (const std::size_t i : pending)
        runs << " [" << i << "]=" << shellWord(plan.runs[i].id);
    runs << " )\n"
         << "exec " << shellWord(program) << " study -o " << shellWord(plan.dir)
         << " --run \"${runs[$SLURM_ARRAY_TASK_ID]}\" --threads \"${SLURM_CPUS_PER_TASK:-1}\"\n";
    out.runs = runs.str();

    std::ostringstream merge;
    merge << "#!/bin/bash\n"
          << "# Merges the results of the study in " << plan.dir << " into study.csv,\n"
          << "# report.md and the plots, once its runs have ended (sweepers-cli study --slurm\n"
          << "# submits it after them with --dependency=afterany).\n"
          << "#SBATCH --job-name=sweepers-merge\n"
          << "#SBATCH --output=" << logs << "/merge_%j.out\n"
          << "#SBATCH --cpus-per-task=1\n"
          << "#SBATCH --mem=" << kMergeMemoryMb << "M\n"
          << "#SBATCH --time=" << kMergeMinutes << "\n"
          << commonDirectives(options) << "exec " << shellWord(program) << " study -o "
          << shellWord(plan.dir) << " --merge\n";
    out.merge = merge.str();

    for (const auto& [h, indices] : tiers) {
        SlurmScripts::Array array;
        array.voxelSize = h;
        array.runs = indices;
        for (const std::size_t i : indices) {
            array.memoryMb = std::max(array.memoryMb, memoryRequestMb(plan.runs[i]));
            array.minutes = std::max(array.minutes, timeRequestMinutes(plan.runs[i]));
        }
        array.args = {"--array=" + arraySpec(indices, options.maxRunning),
                      "--mem=" + std::to_string(array.memoryMb) + "M"};
        if (array.minutes > 0) array.args.push_back("--time=" + std::to_string(array.minutes));
        out.arrays.push_back(array);
    }
    return out;
}

SlurmSubmission submitStudy(const StudyPlan& plan, const std::vector<std::size_t>& pending,
                            const SlurmOptions& options) {
    const std::string dir = slurmDir(plan), logs = dir + "/logs";
    std::error_code ec;
    std::filesystem::create_directories(logs, ec);
    if (ec) throw std::runtime_error(logs + ": cannot create it (" + ec.message() + ")");
    const SlurmScripts scripts = slurmScripts(plan, pending, options, thisProgram());
    writeTextAtomically(dir + "/runs.sbatch", scripts.runs);
    writeTextAtomically(dir + "/merge.sbatch", scripts.merge);

    SlurmSubmission out;
    json arrays = json::array();
    for (const SlurmScripts::Array& array : scripts.arrays) {
        std::vector<std::string> args = array.args;
        if (!out.arrays.empty()) args.push_back("--dependency=afterany:" + out.arrays.back());
        args.push_back(dir + "/runs.sbatch");
        out.arrays.push_back(submit(args));
        json ids = json::array();
        for (const std::size_t i : array.runs)
            ids.push_back(plan.runs[i].id);
        arrays.push_back({{"job", out.arrays.back()},
                          {"voxel_size", array.voxelSize},
                          {"mem_mb", array.memoryMb},
                          {"time_minutes", array.minutes},
                          {"runs", ids}});
    }
    std::string after = "afterany";
    for (const std::string& id : out.arrays)
        after += ":" + id;
    out.merge =
        submit({"--dependency=" + after, "--kill-on-invalid-dep=no", dir + "/merge.sbatch"});
    writeTextAtomically(jobsPath(plan),
                        json({{"arrays", arrays}, {"merge", out.merge}}).dump(2) + "\n");
    return out;
}

std::string jobState(const std::string& id) {
    const ProgramOutput r = runProgram({"scontrol", "show", "job", "-o", id});
    if (r.status != 0) return "";
    const std::size_t at = r.out.find("JobState=");
    if (at == std::string::npos) return "";
    const std::size_t from = at + 9;
    return r.out.substr(from, r.out.find_first_of(" \n", from) - from);
}

void waitForJob(const std::string& id, Interrupter* interrupter,
                const std::function<void()>& onPoll) {
    for (;;) {
        const std::string state = jobState(id);
        if (state.empty() || (state != "PENDING" && state != "RUNNING" && state != "CONFIGURING" &&
                              state != "COMPLETING" && state != "SUSPENDED" &&
                              state != "REQUEUED" && state != "RESIZING"))
            return;
        if (onPoll) onPoll();
        // A short sleep in slices, so that Ctrl-C is answered at once.
        for (int k = 0; k < 20; ++k) {
            pollInterrupt(interrupter);
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
    }
}

} // namespace sweepers::cli
