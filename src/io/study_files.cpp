#include "io/study_files.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "io/vdb_file.h"

namespace sweepers {

namespace {

const char* const kColumns[] = {
    "variant",     "voxel_size",  "wall_s",         "advect_s",   "renorm_s",
    "mesh_s",      "peak_rss_mb", "active_voxels",  "volume",     "volume_change_pct",
    "area",        "euler",       "genus",          "components", "err_mean",
    "err_rms",     "err_max",     "err_rms_voxels", "sign_flips", "order_rms",
    "err_samples", "unmatched",   "failure"};
constexpr std::size_t kColumnCount = sizeof(kColumns) / sizeof(kColumns[0]);

std::string number(double v, int digits = 7) {
    if (std::isnan(v)) return "nan";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
}

// A field in double quotes when it holds a comma, a quote or a line break.
std::string field(const std::string& s) {
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string out = "\"";
    for (const char c : s) {
        if (c == '"') out += '"';
        out += c == '\n' || c == '\r' ? ' ' : c;
    }
    return out + "\"";
}

std::vector<std::string> splitCsvLine(const std::string& line) {
    std::vector<std::string> out(1);
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quoted) {
            if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
                out.back() += '"';
                ++i;
            } else if (c == '"') {
                quoted = false;
            } else {
                out.back() += c;
            }
        } else if (c == '"') {
            quoted = true;
        } else if (c == ',') {
            out.emplace_back();
        } else {
            out.back() += c;
        }
    }
    return out;
}

double toNumber(const std::string& s, const std::string& where) {
    if (s == "nan") return std::nan("");
    std::size_t used = 0;
    double v = 0.0;
    try {
        v = std::stod(s, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != s.size()) throw FileError(where + ": '" + s + "' is not a number");
    return v;
}

double voxelsOf(const StudyRow& r) {
    return r.voxelSize > 0.0 ? r.error.rms / r.voxelSize : 0.0;
}

} // namespace

std::string studyRunName(const StudyRow& row) {
    const double n = 1.0 / row.voxelSize;
    if (std::abs(n - std::round(n)) < 1e-9 * n) return row.variant + "_" + number(std::round(n));
    return row.variant + "_" + number(row.voxelSize, 12);
}

std::string studyCsv(const std::vector<StudyRow>& rows) {
    std::ostringstream out;
    for (std::size_t c = 0; c < kColumnCount; ++c)
        out << (c ? "," : "") << kColumns[c];
    out << "\n";
    for (const StudyRow& r : rows) {
        const bool ran = r.failure.empty();
        const auto num = [&](double v, int digits = 7) { return ran ? number(v, digits) : ""; };
        const auto count = [&](std::size_t v) { return ran ? std::to_string(v) : ""; };
        const auto integer = [&](int v) { return ran ? std::to_string(v) : ""; };
        out << field(r.variant) << "," << number(r.voxelSize, 17) << "," << num(r.wallSeconds)
            << "," << num(r.advectSeconds) << "," << num(r.renormSeconds) << ","
            << num(r.meshSeconds) << "," << num(r.peakRssMb) << "," << count(r.activeVoxels) << ","
            << num(r.volume, 10) << "," << num(r.volumeChangePct) << "," << num(r.area, 10) << ","
            << integer(r.euler) << "," << integer(r.genus) << "," << count(r.components) << ","
            << num(r.error.mean) << "," << num(r.error.rms) << "," << num(r.error.max) << ","
            << num(voxelsOf(r)) << "," << count(r.error.signFlips) << "," << num(r.orderRms, 4)
            << "," << count(r.error.samples) << "," << count(r.error.unmatched) << ","
            << field(r.failure) << "\n";
    }
    return out.str();
}

std::vector<StudyRow> readStudyCsv(const std::string& path) {
    std::ifstream in(path);
    if (!in) return {};
    std::string line;
    if (!std::getline(in, line) || splitCsvLine(line).size() != kColumnCount ||
        splitCsvLine(line)[0] != kColumns[0])
        throw FileError(path + ": not a study table (its first line is not the header)");
    std::vector<StudyRow> rows;
    for (int n = 2; std::getline(in, line); ++n) {
        if (line.empty()) continue;
        const std::vector<std::string> f = splitCsvLine(line);
        const std::string where = path + ", line " + std::to_string(n);
        if (f.size() != kColumnCount)
            throw FileError(where + ": " + std::to_string(f.size()) + " fields, not " +
                            std::to_string(kColumnCount));
        StudyRow r;
        r.variant = f[0];
        r.voxelSize = toNumber(f[1], where);
        r.failure = f[22];
        if (!r.failure.empty()) {
            rows.push_back(r);
            continue;
        }
        r.wallSeconds = toNumber(f[2], where);
        r.advectSeconds = toNumber(f[3], where);
        r.renormSeconds = toNumber(f[4], where);
        r.meshSeconds = toNumber(f[5], where);
        r.peakRssMb = toNumber(f[6], where);
        r.activeVoxels = std::size_t(toNumber(f[7], where));
        r.volume = toNumber(f[8], where);
        r.volumeChangePct = toNumber(f[9], where);
        r.area = toNumber(f[10], where);
        r.euler = int(toNumber(f[11], where));
        r.genus = int(toNumber(f[12], where));
        r.components = std::size_t(toNumber(f[13], where));
        r.error.mean = toNumber(f[14], where);
        r.error.rms = toNumber(f[15], where);
        r.error.max = toNumber(f[16], where);
        r.error.signFlips = std::size_t(toNumber(f[18], where));
        r.orderRms = toNumber(f[19], where);
        r.error.samples = std::size_t(toNumber(f[20], where));
        r.error.unmatched = std::size_t(toNumber(f[21], where));
        rows.push_back(r);
    }
    return rows;
}

std::string studyReport(const std::vector<StudyRow>& rows, const std::string& script) {
    std::ostringstream out;
    out << "# Grid-resolution study of " << script << "\n\n"
        << "Errors are distances between the result's surface and the exact surface that the "
           "history of inverses defines (both ways: mesh vertices to the exact surface along "
           "their normals, exact crossings on voxel edges to the grid's surface); sign flips "
           "are active voxels on the wrong side of the exact surface. The order p compares "
           "each run with the next coarser one of its variant: "
           "p = log(e_coarse / e_fine) / log(h_coarse / h_fine).\n\n"
        << "| variant | voxel size | err RMS (voxels) | err max (voxels) | err RMS | order (RMS) "
           "| sign flips | volume change | Euler | genus | components | time (s) |\n"
        << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const StudyRow& r : rows) {
        out << "| " << r.variant << " | 1/" << number(1.0 / r.voxelSize, 6) << " | ";
        if (!r.failure.empty()) {
            out << "failed: " << r.failure << " | | | | | | | | | |\n";
            continue;
        }
        out << number(voxelsOf(r), 3) << " | " << number(r.error.max / r.voxelSize, 3) << " | "
            << number(r.error.rms, 3) << " | "
            << (std::isnan(r.orderRms) ? "" : number(r.orderRms, 3)) << " | " << r.error.signFlips
            << " | " << number(r.volumeChangePct, 3) << "% | " << r.euler << " | " << r.genus
            << " | " << r.components << " | " << number(r.wallSeconds, 3) << " |\n";
    }
    return out.str();
}

} // namespace sweepers
