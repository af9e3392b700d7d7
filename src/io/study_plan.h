// SPDX-License-Identifier: Apache-2.0
// A grid-resolution study as a plan of independent runs: one per script x voxel size x
// variant, each run one command that any machine sharing the study's directory can run
// (docs/studies.md). The plan (DIR/plan.json) names every run, what its result depends on
// (a digest of the program's version, its script and the files the script reads, its voxel
// size and variant) and an estimate of its memory and time. A run's result
// (DIR/runs/ID/result.json, beside its grid.vdb and mesh.ply unless the plan keeps only one
// or neither) is written last and
// atomically, so a result on disk is a finished run, and a result whose digest matches the
// plan is not run again. Merging the results gives the study's table, report and plots.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "levelset/interrupt.h"
#include "sculpt/sculptor.h"
#include "study/study.h"

namespace sweepers {

struct StudyScript {
    std::string name;   // unique within the study: the file's stem (a -2 added to repeats)
    std::string path;   // absolute
    std::string digest; // of its text and of every file it reads
};

struct PlannedRun {
    std::string id;         // <script>-<variant>_<N>: also the name of its directory under runs/
    std::size_t script = 0; // in StudyPlan::scripts
    double voxelSize = 0.0;
    StudyVariant variant = StudyVariant::Corrected;
    std::string digest; // of what its result depends on
    // Estimates (0 where there is nothing yet to estimate from): peak resident memory, and
    // wall time at `threads` worker threads; `basis` says what they were scaled from.
    double memoryMb = 0.0, seconds = 0.0;
    int threads = 1;
    std::string basis;
};

// What a run keeps on disk beside its result: its grid and its mesh (study --keep), the grid
// at full or half precision (--half). Its row is the same whatever it keeps.
struct StudyOutputs {
    bool grids = true, meshes = true;
    bool half = false;
};
// "both", "grids", "meshes" or "none", as --keep says it; nullopt for anything else.
std::optional<StudyOutputs> parseKept(const std::string& keep);
std::string keptName(const StudyOutputs& outputs);

struct StudyPlan {
    std::string dir; // absolute
    std::string version;
    std::vector<StudyScript> scripts;
    std::vector<PlannedRun> runs; // script by script, coarsest voxel size first
    bool force = false;           // build starts even when they seem not to fit in memory
    StudyOutputs outputs;
};

// Plans a study of `scripts` at `voxelSizes` (coarsest first) and `variants` in `dir`
// (made absolute). Each script is read and its start checked at every voxel size as apply
// would (throws ScriptError or FileError, naming the script). Estimates are left empty.
StudyPlan planStudy(const std::vector<std::string>& scripts, const std::vector<double>& voxelSizes,
                    const std::vector<StudyVariant>& variants, const std::string& dir, bool force);

// DIR/plan.json, written atomically.
void writeStudyPlan(const StudyPlan& plan);
// The plan in `dir`. Throws FileError, saying what to do, when there is none or it is not
// one this version reads.
StudyPlan readStudyPlan(const std::string& dir);
// The run of that id; throws FileError naming the plan's runs when there is none.
const PlannedRun& findRun(const StudyPlan& plan, const std::string& id);

// DIR/runs/ID.
std::string runDirectory(const StudyPlan& plan, const PlannedRun& run);
// The run's result when it has one made from what the plan says (its digest matches): a
// finished run, or one that failed (its row's failure says why). nullopt otherwise.
std::optional<StudyRow> readRunResult(const StudyPlan& plan, const PlannedRun& run);
// Whether the run has a result without a failure.
bool runIsDone(const StudyPlan& plan, const PlannedRun& run);

// Runs one run with the process's worker threads and writes its result, and its grid and
// mesh as the plan's outputs say.
// A run that fails writes a result that says why, and is returned with that failure.
// Throws Cancelled, writing nothing, when `interrupter` stops it.
StudyRow executeStudyRun(const StudyPlan& plan, const PlannedRun& run,
                         Interrupter* interrupter = nullptr, const Progress& progress = {});

// Fills every run's estimate for a run at `threads` worker threads: scaled from the
// finished runs of its script (the band's voxels grow as 1/h^2; the time as fitted to the
// two finest finished runs, within 1/h^2 to 1/h^3, or as 1/h^3 from one), or where none
// has finished, the memory from the start's band alone.
void estimateStudyRuns(StudyPlan& plan, int threads);

// What the results of a study hold, in the plan's order: the rows of runs with a result
// (done or failed; orders filled in) and the runs without one.
struct StudyResults {
    std::vector<StudyRow> rows;
    std::vector<StudyRow> missing; // script, variant and voxel size only
    std::vector<std::string> failedIds, missingIds;
    std::size_t done() const { return rows.size() - failedIds.size(); }
};
StudyResults collectStudyResults(const StudyPlan& plan);

// DIR/study.csv from the results.
void writeStudyTable(const StudyPlan& plan, const StudyResults& results);
// DIR/study.csv, DIR/report.md and the plots (io/study_files.h). Returns why the plots could
// not be drawn (empty when they were): the table and report stand without them.
std::string mergeStudy(const StudyPlan& plan, const StudyResults& results);

} // namespace sweepers
