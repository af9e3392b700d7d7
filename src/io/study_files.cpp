// SPDX-License-Identifier: Apache-2.0
#include "io/study_files.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>
#include <string_view>

#include <sys/wait.h>
#include <unistd.h>

#include "io/atomic_file.h"
#include "io/vdb_file.h"

namespace sweepers {

namespace {

const char* const kColumns[] = {"script",       "variant",       "voxel_size", "wall_s",
                                "measure_s",    "advect_s",      "renorm_s",   "mesh_s",
                                "peak_rss_mb",  "active_voxels", "volume",     "volume_change_pct",
                                "area",         "euler",         "genus",      "components",
                                "err_mean",     "err_rms",       "err_max",    "err_rms_voxels",
                                "sign_flips",   "order_rms",     "volume_ref", "volume_err",
                                "order_volume", "ref_euler",     "ref_genus",  "ref_components",
                                "err_samples",  "unmatched",     "threads",    "host",
                                "failure"};
constexpr std::size_t kColumnCount = sizeof(kColumns) / sizeof(kColumns[0]);
// The position of a column in kColumns.
std::size_t column(std::string_view name) {
    std::size_t c = 0;
    while (c < kColumnCount && kColumns[c] != name)
        ++c;
    return c;
}
// Bounds of the whole numbers a table may hold (2^53: every integer below is a double).
constexpr double kMaxCount = 9007199254740992.0, kMaxTopology = 2147483647.0;

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

// A count or a topological number of the table: whole, and within [lo, hi] (converting a
// damaged field such as -1, 1e300 or nan to an integer would be undefined).
long long wholeNumber(const std::string& s, const std::string& where, double lo, double hi) {
    const double v = toNumber(s, where);
    if (!(v >= lo && v <= hi) || v != std::floor(v))
        throw FileError(where + ": '" + s + "' is not a whole number from " + number(lo) + " to " +
                        number(hi));
    return static_cast<long long>(v);
}

double voxelsOf(const StudyRow& r) {
    return r.voxelSize > 0.0 ? r.error.rms / r.voxelSize : 0.0;
}

std::string quoted(const std::string& s) {
    std::string out = "\"";
    for (const char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

// The first line gnuplot wrote to `fd` (a file it wrote its warnings and errors to), for a
// failure's message; empty when it wrote none.
std::string firstLineOf(int fd) {
    std::string text(512, '\0');
    const ssize_t n = ::pread(fd, text.data(), text.size(), 0);
    text.resize(n > 0 ? std::size_t(n) : 0);
    return text.substr(0, text.find('\n'));
}

// Runs gnuplot on `script` in `dir` with `terminal` set first; returns what it drew (its
// standard output). Its warnings go to a file of its own, not to the user's terminal: a
// study that draws its plots says nothing of how they were drawn, and one that cannot
// draw them says why in its one line.
std::string runGnuplot(const std::string& dir, const std::string& script,
                       const std::string& terminal) {
    // Built before the fork: the child of a threaded process may not allocate.
    const std::string set = "set terminal " + terminal;
    std::string logName = (std::filesystem::temp_directory_path() / "sweepers-gnuplot-XXXXXX");
    const int log = ::mkstemp(logName.data());
    if (log < 0) throw std::runtime_error("plots: cannot start gnuplot (temporary file)");
    ::unlink(logName.c_str()); // an anonymous file: nothing is left behind, whatever happens
    int out[2];
    if (::pipe(out) != 0) {
        ::close(log);
        throw std::runtime_error("plots: cannot start gnuplot (pipe)");
    }
    const pid_t pid = ::fork();
    if (pid < 0) {
        ::close(out[0]);
        ::close(out[1]);
        ::close(log);
        throw std::runtime_error("plots: cannot start gnuplot (fork)");
    }
    if (pid == 0) {
        ::dup2(log, STDERR_FILENO);
        ::dup2(out[1], STDOUT_FILENO);
        ::close(out[0]);
        ::close(out[1]);
        if (::chdir(dir.c_str()) != 0) ::_exit(126);
        ::execlp("gnuplot", "gnuplot", "-e", set.c_str(), script.c_str(), (char*)nullptr);
        ::_exit(errno == ENOENT ? 127 : 126);
    }
    ::close(out[1]);
    std::string image;
    char buf[65536];
    bool readFailed = false;
    for (;;) {
        const ssize_t n = ::read(out[0], buf, sizeof buf);
        if (n > 0) {
            image.append(buf, std::size_t(n));
        } else if (n == 0 || errno != EINTR) {
            readFailed = n < 0; // a part of the image is not a plot
            break;
        }
    }
    ::close(out[0]);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    const std::string said = firstLineOf(log);
    ::close(log);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
        throw std::runtime_error("plots: gnuplot is not installed (Debian: gnuplot-nox)");
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || image.empty() || readFailed)
        throw std::runtime_error("plots: gnuplot failed on " + dir + "/" + script +
                                 (said.empty() ? "" : " (" + said + ")"));
    return image;
}

} // namespace

void writeStudyPlots(const std::vector<StudyRow>& rows, const std::string& dir) {
    // Per script, one data block per variant (gnuplot breaks a line at every row it skips,
    // and the table interleaves the variants): voxel size, RMS error, volume error (percent
    // of the exact volume), time, peak memory. Then a set of four panels per script.
    const std::vector<std::string> scripts = studyScripts(rows);
    std::ostringstream blocks, panels;
    std::size_t drawn = 0;
    for (std::size_t s = 0; s < scripts.size(); ++s) {
        std::vector<std::string> variants;
        std::set<double> sizes;
        const StudyRow* first = nullptr;
        for (const StudyRow& r : rows)
            if (r.script == scripts[s] && r.failure.empty() &&
                std::find(variants.begin(), variants.end(), r.variant) == variants.end())
                variants.push_back(r.variant);
        const auto block = [&](std::size_t v) {
            return "$s" + std::to_string(s) + "v" + std::to_string(v);
        };
        for (std::size_t v = 0; v < variants.size(); ++v) {
            blocks << block(v) << " << EOD\n";
            for (const StudyRow& r : rows) {
                if (r.script != scripts[s] || !r.failure.empty() || r.variant != variants[v])
                    continue;
                if (!first) first = &r;
                sizes.insert(r.voxelSize);
                blocks << number(r.voxelSize, 17) << " " << number(r.error.rms) << " "
                       << number(100.0 * r.error.volumeError() / r.error.referenceVolume) << " "
                       << number(r.wallSeconds) << " " << number(r.peakRssMb) << "\n";
            }
            blocks << "EOD\n";
        }
        if (!first) {
            // Four empty panels keep the layout: the script's runs all failed.
            panels << "set multiplot next\nset multiplot next\nset multiplot next\n"
                      "set multiplot next\n";
            continue;
        }
        ++drawn;
        // Guides through the first run's error: e = a h and e = b h^2.
        const double h0 = first->voxelSize, e0 = std::max(first->error.rms, 1e-300);
        std::string tics;
        for (const double h : sizes)
            tics += (tics.empty() ? "" : ", ") + quoted("1/" + number(1.0 / h, 6)) + " " +
                    number(h, 17);
        const auto series = [&](int column) {
            std::ostringstream p;
            p << "plot ";
            for (std::size_t v = 0; v < variants.size(); ++v)
                p << (v ? ", " : "") << block(v) << " using 1:" << column
                  << " with linespoints pointtype 7 linecolor " << v + 1 << " title "
                  << quoted(variants[v]);
            return p.str();
        };
        const std::string of = scripts.size() > 1 ? " (" + scripts[s] + ")" : "";
        panels << "set xtics (" << tics << ")\n";
        if (!std::isfinite(first->error.rms)) {
            // No exact reference (a history that smooths): the error panels stay empty.
            panels << "set multiplot next\nset multiplot next\n"
                   << "unset key\nset logscale y\nset ylabel 'seconds'\n"
                   << "set title " << quoted("time" + of + ", no exact reference") << "\n"
                   << series(4) << "\n"
                   << "set ylabel 'MB'\nset title "
                   << quoted("peak resident memory of each run" + of) << "\n"
                   << series(5) << "\n";
            continue;
        }
        panels << "set key bottom right\nset logscale y\n"
               << "set ylabel 'RMS distance to the exact surface'\n"
               << "set title " << quoted("interface error" + of) << "\n"
               << series(2) << ", " << number(e0 / h0, 17) << " * x dashtype 2 linecolor 'gray' "
               << "title 'slope 1', " << number(e0 / (h0 * h0), 17)
               << " * x**2 dashtype 3 linecolor 'black' title 'slope 2'\n"
               << "unset key\nunset logscale y\nset ylabel 'volume error (%)'\n"
               << "set title " << quoted("volume drift from the exact shape" + of)
               << "\nset xzeroaxis\n"
               << series(3) << "\n"
               << "unset xzeroaxis\nset logscale y\nset ylabel 'seconds'\n"
               << "set title " << quoted("time" + of) << "\n"
               << series(4) << "\n"
               << "set ylabel 'MB'\nset title " << quoted("peak resident memory of each run" + of)
               << "\n"
               << series(5) << "\n";
    }
    if (drawn == 0) throw std::runtime_error("plots: no run finished, nothing to draw");
    const std::string height = std::to_string(960 * scripts.size());
    const std::string title =
        "Grid-resolution study" + (scripts.size() == 1 ? " of " + scripts.front() : "");
    std::ostringstream gp;
    gp << "# Drawn by sweepers-cli study; to draw it again:\n"
       << "#   gnuplot -e 'set terminal pngcairo size 1280," << height
       << "' convergence.gp > convergence.png\n"
       << blocks.str() << "set termoption noenhanced\nset multiplot layout " << 2 * scripts.size()
       << ",2 title " << quoted(title) << " noenhanced\n"
       << "set grid\nset logscale x\nset xlabel 'voxel size'\nset format y '%g'\n"
       << panels.str() << "unset multiplot\n";
    writeTextAtomically(dir + "/convergence.gp", gp.str());
    const std::string size = "size 1280," + height;
    const std::string png = runGnuplot(dir, "convergence.gp", "pngcairo " + size);
    const std::string svg = runGnuplot(dir, "convergence.gp", "svg " + size);
    writeTextAtomically(dir + "/convergence.png", png);
    writeTextAtomically(dir + "/convergence.svg", svg);
}

std::string studyRunName(const StudyRow& row) {
    const double n = 1.0 / row.voxelSize;
    if (std::abs(n - std::round(n)) < 1e-9 * n) return row.variant + "_" + number(std::round(n));
    return row.variant + "_" + number(row.voxelSize, 12);
}

std::string studyRunId(const StudyRow& row) {
    return row.script + "-" + studyRunName(row);
}

namespace {

// A row's cells in kColumns' order, as the table writes them (or with every digit a double
// holds, for a run's result file that the table is made from later): a failed run has only
// its script, variant, voxel size, where it ran and its failure.
std::vector<std::string> studyCells(const StudyRow& r, bool allDigits) {
    const bool ran = r.failure.empty();
    const auto num = [&](double v, int digits = 7) {
        return ran ? number(v, allDigits ? 17 : digits) : "";
    };
    const auto count = [&](std::size_t v) { return ran ? std::to_string(v) : ""; };
    const auto integer = [&](int v) { return ran ? std::to_string(v) : ""; };
    // The exact topology's columns stay empty where it is not known.
    const auto known = [&](const std::string& v) {
        return r.referenceTopologyKnown ? v : std::string();
    };
    return {r.script,
            r.variant,
            number(r.voxelSize, 17),
            num(r.wallSeconds),
            num(r.measureSeconds),
            num(r.advectSeconds),
            num(r.renormSeconds),
            num(r.meshSeconds),
            num(r.peakRssMb),
            count(r.activeVoxels),
            num(r.volume, 10),
            num(r.volumeChangePct),
            num(r.area, 10),
            integer(r.euler),
            integer(r.genus),
            count(r.components),
            num(r.error.mean),
            num(r.error.rms),
            num(r.error.max),
            num(voxelsOf(r)),
            count(r.error.signFlips),
            num(r.orderRms, 4),
            num(r.error.referenceVolume, 12),
            num(r.error.volumeError(), 7),
            num(r.orderVolume, 4),
            known(integer(r.referenceEuler)),
            known(integer(r.referenceGenus)),
            known(count(r.referenceComponents)),
            count(r.error.samples),
            count(r.error.unmatched),
            r.threads > 0 ? std::to_string(r.threads) : "",
            r.host,
            r.failure};
}

bool isTextColumn(std::string_view name) {
    return name == "script" || name == "variant" || name == "host" || name == "failure";
}

// A row from its cells in kColumns' order; `where` names them in a refusal.
StudyRow studyRowFromCells(const std::vector<std::string>& f, const std::string& where) {
    const auto at = [&](std::string_view name) -> const std::string& { return f[column(name)]; };
    const auto real = [&](std::string_view name) { return toNumber(at(name), where); };
    const auto whole = [&](std::string_view name, double lo, double hi) {
        return wholeNumber(at(name), where, lo, hi);
    };
    StudyRow r;
    r.script = at("script");
    r.variant = at("variant");
    r.voxelSize = real("voxel_size");
    if (!(r.voxelSize > 0.0) || !std::isfinite(r.voxelSize))
        throw FileError(where + ": '" + at("voxel_size") + "' is not a voxel size");
    r.host = at("host");
    if (!at("threads").empty()) r.threads = int(whole("threads", 1, kMaxTopology));
    r.failure = at("failure");
    if (!r.failure.empty()) return r;
    r.wallSeconds = real("wall_s");
    r.measureSeconds = real("measure_s");
    r.advectSeconds = real("advect_s");
    r.renormSeconds = real("renorm_s");
    r.meshSeconds = real("mesh_s");
    r.peakRssMb = real("peak_rss_mb");
    r.activeVoxels = std::size_t(whole("active_voxels", 0, kMaxCount));
    r.volume = real("volume");
    r.volumeChangePct = real("volume_change_pct");
    r.area = real("area");
    r.euler = int(whole("euler", -kMaxTopology, kMaxTopology));
    r.genus = int(whole("genus", -kMaxTopology, kMaxTopology));
    r.components = std::size_t(whole("components", 0, kMaxCount));
    r.error.mean = real("err_mean");
    r.error.rms = real("err_rms");
    r.error.max = real("err_max");
    r.error.signFlips = std::size_t(whole("sign_flips", 0, kMaxCount));
    r.orderRms = real("order_rms");
    r.error.referenceVolume = real("volume_ref");
    r.error.meshVolume = r.error.referenceVolume + real("volume_err");
    r.orderVolume = real("order_volume");
    r.referenceTopologyKnown = !at("ref_euler").empty();
    if (r.referenceTopologyKnown) {
        r.referenceEuler = int(whole("ref_euler", -kMaxTopology, kMaxTopology));
        r.referenceGenus = int(whole("ref_genus", -kMaxTopology, kMaxTopology));
        r.referenceComponents = std::size_t(whole("ref_components", 0, kMaxCount));
    }
    r.error.samples = std::size_t(whole("err_samples", 0, kMaxCount));
    r.error.unmatched = std::size_t(whole("unmatched", 0, kMaxCount));
    return r;
}

} // namespace

std::string studyCsv(const std::vector<StudyRow>& rows) {
    std::ostringstream out;
    for (std::size_t c = 0; c < kColumnCount; ++c)
        out << (c ? "," : "") << kColumns[c];
    out << "\n";
    for (const StudyRow& r : rows) {
        const std::vector<std::string> cells = studyCells(r, false);
        for (std::size_t c = 0; c < kColumnCount; ++c)
            out << (c ? "," : "") << field(cells[c]);
        out << "\n";
    }
    return out.str();
}

nlohmann::json studyRowJson(const StudyRow& r, bool allDigits) {
    const std::vector<std::string> cells = studyCells(r, allDigits);
    nlohmann::json row = nlohmann::json::object();
    for (std::size_t c = 0; c < kColumnCount; ++c) {
        const std::string& cell = cells[c];
        if (isTextColumn(kColumns[c]))
            row[kColumns[c]] = cell;
        else if (cell.empty() || cell == "nan")
            row[kColumns[c]] = nullptr; // not measured, or no coarser run to compare
        else if (cell.find_first_of(".eEn") == std::string::npos)
            row[kColumns[c]] = std::stoll(cell); // counts and topology stay whole
        else
            row[kColumns[c]] = std::stod(cell);
    }
    // In a run's result, the whole run's time and where measuring's went (study --stats),
    // beside the table's columns (which alone are a row everywhere else).
    if (allDigits && r.failure.empty()) {
        row["run_s"] = r.runSeconds;
        const InterfaceError::Phases& p = r.error.phases;
        row["measure_phases"] = {{"grid_s", r.gridMeasureSeconds}, {"voxels_s", p.voxels},
                                 {"crossings_s", p.crossings},     {"vertices_s", p.vertices},
                                 {"crossings", p.crossingCount},   {"vertices", p.vertexCount}};
    }
    return row;
}

nlohmann::json studyJson(const std::vector<StudyRow>& rows) {
    nlohmann::json out = nlohmann::json::array();
    for (const StudyRow& r : rows)
        out.push_back(studyRowJson(r, false));
    return out;
}

namespace {

// The columns a run that ran may leave without a value: the orders (no coarser run), and
// the errors against the exact reference (a history that smooths has none).
bool notMeasuredIsNan(std::string_view column) {
    static const std::string_view errors[] = {"err_mean",       "err_rms",    "err_max",
                                              "err_rms_voxels", "volume_ref", "volume_err"};
    return column.rfind("order_", 0) == 0 ||
           std::find(std::begin(errors), std::end(errors), column) != std::end(errors);
}

} // namespace

StudyRow studyRowFromJson(const nlohmann::json& j, const std::string& where) {
    if (!j.is_object()) throw FileError(where + ": a study row is not a JSON object");
    std::vector<std::string> cells(kColumnCount);
    for (std::size_t c = 0; c < kColumnCount; ++c) {
        const auto it = j.find(kColumns[c]);
        if (it == j.end())
            throw FileError(where + ": the row has no '" + std::string(kColumns[c]) + "'");
        if (it->is_string() && isTextColumn(kColumns[c]))
            cells[c] = it->get<std::string>();
        else if (it->is_number_integer())
            cells[c] = std::to_string(it->get<long long>());
        else if (it->is_number())
            cells[c] = number(it->get<double>(), 17);
        else if (!it->is_null())
            throw FileError(where + ": '" + std::string(kColumns[c]) + "' is " + it->dump());
        else if (notMeasuredIsNan(kColumns[c]) && j.value("failure", "") == "")
            cells[c] = "nan"; // no coarser run to compare with, or no exact reference
    }
    StudyRow row = studyRowFromCells(cells, where);
    // (Results written before these were kept have none: zeros.) A damaged figure is refused,
    // not trusted: an estimate scaled from it would ask a cluster for anything.
    const auto seconds = [&](const nlohmann::json& in, const char* key) {
        const auto it = in.find(key);
        if (it == in.end()) return 0.0;
        const double v = it->is_number() ? it->get<double>() : -1.0;
        if (!(v >= 0.0 && v <= kMaxCount))
            throw FileError(where + ": '" + key + "' is " + it->dump() + ", not a figure");
        return v;
    };
    const auto count = [&](const nlohmann::json& in, const char* key) {
        const double v = seconds(in, key);
        if (v != std::floor(v)) throw FileError(where + ": '" + key + "' is not a count");
        return std::size_t(v);
    };
    row.runSeconds = seconds(j, "run_s");
    if (const auto p = j.find("measure_phases"); p != j.end()) {
        if (!p->is_object()) throw FileError(where + ": 'measure_phases' is " + p->dump());
        InterfaceError::Phases& phases = row.error.phases;
        row.gridMeasureSeconds = seconds(*p, "grid_s");
        phases.voxels = seconds(*p, "voxels_s");
        phases.crossings = seconds(*p, "crossings_s");
        phases.vertices = seconds(*p, "vertices_s");
        phases.crossingCount = count(*p, "crossings");
        phases.vertexCount = count(*p, "vertices");
    }
    return row;
}

namespace {

std::string tableOf(const std::vector<StudyRow>& rows) {
    const auto changed = [](const StudyRow& r) {
        return r.referenceTopologyKnown &&
               (r.euler != r.referenceEuler || r.genus != r.referenceGenus ||
                r.components != r.referenceComponents);
    };
    const auto topology = [](const StudyRow& r) {
        return "Euler " + std::to_string(r.referenceEuler) + ", genus " +
               std::to_string(r.referenceGenus) + ", " + std::to_string(r.referenceComponents) +
               (r.referenceComponents == 1 ? " component" : " components");
    };
    std::ostringstream out;
    out << "| variant | voxel size | err RMS (voxels) | err max (voxels) | err RMS | order (RMS) "
           "| sign flips | volume error | order (volume) | volume change | Euler | genus "
           "| components | time (s) | measuring (s) |\n"
        << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const StudyRow& r : rows) {
        out << "| " << r.variant << " | 1/" << number(1.0 / r.voxelSize, 6) << " | ";
        if (!r.failure.empty()) {
            out << "failed: " << r.failure << " | | | | | | | | | | | | |\n";
            continue;
        }
        out << number(voxelsOf(r), 3) << " | " << number(r.error.max / r.voxelSize, 3) << " | "
            << number(r.error.rms, 3) << " | "
            << (std::isnan(r.orderRms) ? "" : number(r.orderRms, 3)) << " | " << r.error.signFlips
            << " | " << number(100.0 * r.error.volumeError() / r.error.referenceVolume, 3) << "% | "
            << (std::isnan(r.orderVolume) ? "" : number(r.orderVolume, 3)) << " | "
            << number(r.volumeChangePct, 3) << "% | " << r.euler << " | " << r.genus << " | "
            << r.components << (changed(r) ? " (exact: " + topology(r) + ")" : "") << " | "
            << number(r.wallSeconds, 3) << " | " << number(r.measureSeconds, 3) << " |\n";
    }
    return out.str();
}

} // namespace

std::vector<std::string> studyScripts(const std::vector<StudyRow>& rows) {
    std::vector<std::string> scripts;
    for (const StudyRow& r : rows)
        if (std::find(scripts.begin(), scripts.end(), r.script) == scripts.end())
            scripts.push_back(r.script);
    return scripts;
}

std::string studyReport(const std::vector<StudyRow>& rows, const std::vector<StudyRow>& missing) {
    std::ostringstream out;
    const std::vector<std::string> scripts = studyScripts(rows);
    out << "# Grid-resolution study";
    if (scripts.size() == 1) out << " of " << scripts.front();
    out << "\n\n"
        << "Errors are distances between the result's surface and the exact surface that the "
           "history of inverses defines (both ways: mesh vertices to the exact surface along "
           "their normals, exact crossings on voxel edges to the grid's surface); sign flips "
           "are active voxels on the wrong side of the exact surface. The order p compares "
           "each run with the next coarser one of its variant: "
           "p = log(e_coarse / e_fine) / log(h_coarse / h_fine). The volume error is the signed "
           "volume between the result's mesh and the same mesh with every vertex moved to the "
           "exact surface, in percent of the latter (the exact volume on the result's "
           "tessellation); its order is that of its size. The exact shape keeps the start's "
           "topology, since every sub-step is a fold-over-free deformation of space; where a "
           "run's topology differs, the grid lost a feature thinner than it resolves, and "
           "its components column gives the exact topology. A pinch or a strangle tears space "
           "on purpose, and the exact topology of a history that holds one is not known here: "
           "no run of it is marked.\n\n";
    for (const std::string& script : scripts) {
        std::vector<StudyRow> own;
        for (const StudyRow& r : rows)
            if (r.script == script) own.push_back(r);
        if (scripts.size() > 1) out << "## " << script << "\n\n";
        if (std::any_of(own.begin(), own.end(), [](const StudyRow& r) {
                return r.failure.empty() && std::isnan(r.error.rms);
            }))
            out << "No exact shape stands behind this script: it smooths, and smoothing is not "
                   "a deformation of space. Its errors are not measured (nan).\n\n";
        out << tableOf(own) << "\n";
    }
    if (!missing.empty()) {
        out << "## Runs without a result\n\n"
               "These runs have not finished: they were not run yet, were cancelled or stopped, "
               "or their process ended without writing a result (see the run's log). Running "
               "the study again runs them.\n\n";
        for (const StudyRow& r : missing)
            out << "- " << studyRunId(r) << "\n";
        out << "\n";
    }
    out << "## Where each run ran\n\n"
        << "| run | host | threads | time (s) | measuring (s) | peak memory (MB) | result |\n"
        << "|---|---|---|---|---|---|---|\n";
    for (const StudyRow& r : rows)
        out << "| " << studyRunId(r) << " | " << r.host << " | "
            << (r.threads > 0 ? std::to_string(r.threads) : "") << " | "
            << (r.failure.empty() ? number(r.wallSeconds, 3) : "") << " | "
            << (r.failure.empty() ? number(r.measureSeconds, 3) : "") << " | "
            << (r.failure.empty() ? number(r.peakRssMb, 4) : "") << " | "
            << (r.failure.empty() ? "done" : "failed") << " |\n";
    return out.str();
}

} // namespace sweepers
