// The files of a grid-resolution study: DIR/study.csv (one row per run, the columns
// below) and DIR/report.md (the table and the observed orders, for reading at a glance).
// The CSV is also what an interrupted study resumes from.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "study/study.h"

namespace sweepers {

// variant, voxel_size, wall_s, advect_s, renorm_s, mesh_s, peak_rss_mb, active_voxels,
// volume, volume_change_pct, area, euler, genus, components, err_mean, err_rms, err_max,
// err_rms_voxels, sign_flips, order_rms, volume_ref, volume_err, order_volume, ref_euler,
// ref_genus, ref_components, err_samples, unmatched, failure
std::string studyCsv(const std::vector<StudyRow>& rows);
// The same rows as JSON objects keyed by those columns: numbers as numbers, a cell the
// table leaves empty (a failed run's measures, the coarsest run's order) as null.
nlohmann::json studyJson(const std::vector<StudyRow>& rows);
// Rows of a study.csv; a missing file has none. Throws FileError for a file that is not one.
std::vector<StudyRow> readStudyCsv(const std::string& path);
std::string studyReport(const std::vector<StudyRow>& rows, const std::string& script);

// DIR/convergence.gp, and from it DIR/convergence.png and DIR/convergence.svg drawn by
// gnuplot: the RMS error against the voxel size per variant (log-log, with slope-1 and
// slope-2 guides), the volume error against the exact shape, the time and each run's peak
// memory against the voxel size.
// Each file is written atomically. Throws std::runtime_error when gnuplot cannot draw them
// (for example when it is not installed).
void writeStudyPlots(const std::vector<StudyRow>& rows, const std::string& dir,
                     const std::string& script);

// The run's file stem: <variant>_<N> with N = 1 / voxel size when that is whole
// (trilinear_64), else the voxel size itself (trilinear_0.03).
std::string studyRunName(const StudyRow& row);

} // namespace sweepers
