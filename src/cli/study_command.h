// SPDX-License-Identifier: Apache-2.0
// sweepers-cli study: a grid-resolution study planned as independent runs
// (io/study_plan.h), run here one after another or several at once (--jobs), or submitted
// to Slurm (--slurm), and merged into one table, report and set of plots.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace sweepers::cli {

struct StudyArgs {
    std::vector<std::string> scripts;
    std::string dir, voxelSizes = "1/32,1/64,1/128,1/256", variants = "corrected";
    bool force = false;
    // What each run keeps on disk (empty: the plan's, both for a new one) and whether its
    // grid is written at half precision (once given, the plan keeps it).
    std::string keep;
    bool half = false;
    bool stats = false; // print the measure's phases per run
    int jobs = 1;
    int* threads = nullptr; // the program's --threads (0: all cores)
    // One step of a study: plan only, list the runs without a result, run one, merge.
    bool planOnly = false, list = false, merge = false;
    std::string run;
    // Slurm.
    bool slurm = false, wait = false;
    int maxRunning = 0;
    std::string partition, account;
    std::vector<std::string> sbatchArgs;
};

// The study command and its options, on `app`.
CLI::App* addStudyCommand(CLI::App& app, StudyArgs& args);

int runStudy(const StudyArgs& args);

} // namespace sweepers::cli
