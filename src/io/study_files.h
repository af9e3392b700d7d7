// SPDX-License-Identifier: Apache-2.0
// The files of a grid-resolution study: DIR/study.csv (one row per run, the columns below),
// DIR/report.md (the tables and the observed orders, for reading at a glance) and the
// convergence plots; each run's row is also kept as JSON in its result file
// (io/study_plan.h), from which the table is made.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "study/study.h"

namespace sweepers {

// script, variant, voxel_size, wall_s, advect_s, renorm_s, mesh_s, peak_rss_mb,
// active_voxels, volume, volume_change_pct, area, euler, genus, components, err_mean,
// err_rms, err_max, err_rms_voxels, sign_flips, order_rms, volume_ref, volume_err,
// order_volume, ref_euler, ref_genus, ref_components, err_samples, unmatched, threads, host,
// failure
std::string studyCsv(const std::vector<StudyRow>& rows);
// A row as a JSON object keyed by those columns: numbers as numbers, a cell the table
// leaves empty (a failed run's measures, the coarsest run's order) as null. With
// `allDigits`, every digit of a double and the whole run's time and measuring phases beside
// them (a run's result file); else as the table rounds them.
nlohmann::json studyRowJson(const StudyRow& row, bool allDigits = false);
// The rows as an array of those objects, as the table rounds them.
nlohmann::json studyJson(const std::vector<StudyRow>& rows);
// The row a JSON object of studyRowJson holds. Throws FileError, with `where` and what is
// wrong, for one that is not such an object.
StudyRow studyRowFromJson(const nlohmann::json& row, const std::string& where);

// The scripts of the rows, in the order they first appear.
std::vector<std::string> studyScripts(const std::vector<StudyRow>& rows);

// The report: a table per script of the runs that have a result (done or failed), the runs
// in `missing` (planned, without a result) named, and where each run ran.
std::string studyReport(const std::vector<StudyRow>& rows, const std::vector<StudyRow>& missing);

// DIR/convergence.gp, and from it DIR/convergence.png and DIR/convergence.svg drawn by
// gnuplot: per script, the RMS error against the voxel size per variant (log-log, with
// slope-1 and slope-2 guides), the volume error against the exact shape, the time and each
// run's peak memory against the voxel size.
// Each file is written atomically. Throws std::runtime_error when gnuplot cannot draw them
// (for example when it is not installed).
void writeStudyPlots(const std::vector<StudyRow>& rows, const std::string& dir);

// The run's name within its script: <variant>_<N> with N = 1 / voxel size when that is
// whole (trilinear_64), else the voxel size itself (trilinear_0.03).
std::string studyRunName(const StudyRow& row);
// The run's id within the study: <script>-<name> (twisted_limb-trilinear_64).
std::string studyRunId(const StudyRow& row);

} // namespace sweepers
