// SPDX-License-Identifier: Apache-2.0
// A study's runs submitted to Slurm (study --slurm): a job array per voxel size, coarsest
// first and each after the one before, so that at most --max-running runs run at once and
// each array asks for its own runs' memory and time; and a merge job after them all.
// DIR and the program must be on a filesystem the cluster's nodes share.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "io/study_plan.h"
#include "levelset/interrupt.h"

namespace sweepers::cli {

struct SlurmOptions {
    int maxRunning = 0;  // %K throttle; 0 for none
    int cpusPerTask = 1; // the threads of each run
    std::string partition, account;
    std::vector<std::string> sbatchArgs; // passed on as they are
};

// Throws std::runtime_error, in one line, when sbatch (or, to wait, scontrol) is not here.
void requireSlurm(bool wait);

struct SlurmSubmission {
    std::vector<std::string> arrays; // job ids, coarsest voxel size first
    std::string merge;
};

// Throws std::runtime_error when the study's previous submission still has jobs queued or
// running (running its runs twice would race for their results).
void requireNoActiveSubmission(const StudyPlan& plan);

// What a submission writes and asks sbatch for, made from the plan alone (no cluster, no
// file): runs.sbatch, merge.sbatch, and one job array per voxel size, coarsest first, with its
// runs (indices into plan.runs) and the sbatch arguments that ask for their largest memory
// and time. `program` is the sweepers-cli the jobs run.
struct SlurmScripts {
    std::string runs, merge;
    struct Array {
        double voxelSize = 0.0;
        std::vector<std::size_t> runs;
        int memoryMb = 0, minutes = 0; // minutes 0: the partition's limit
        // --array, --mem and --time (the dependency on the array before is added when
        // submitted: it names that array's job id).
        std::vector<std::string> args;
    };
    std::vector<Array> arrays;
};
SlurmScripts slurmScripts(const StudyPlan& plan, const std::vector<std::size_t>& pending,
                          const SlurmOptions& options, const std::string& program);

// Writes DIR/slurm/runs.sbatch and DIR/slurm/merge.sbatch for the `pending` runs (indices
// into plan.runs) and submits them; records the job ids in DIR/slurm/jobs.json.
SlurmSubmission submitStudy(const StudyPlan& plan, const std::vector<std::size_t>& pending,
                            const SlurmOptions& options);

// Waits until job `id` has left the queue or ended; `onPoll` is called between polls.
// Throws Cancelled when `interrupter` stops the wait (the jobs keep running).
void waitForJob(const std::string& id, Interrupter* interrupter,
                const std::function<void()>& onPoll = {});

// The state Slurm gives the job (COMPLETED, FAILED, ...), or "" when it no longer knows it.
std::string jobState(const std::string& id);

} // namespace sweepers::cli
