// SPDX-License-Identifier: Apache-2.0
// sweepers-cli: the command-line front end. Every failure prints one line on stderr,
// exits non-zero and leaves no output file behind. The exit codes (docs/cli.md): 0 done,
// 1 input refused or the work failed, 2 a usage error, 3 a study that finished with runs
// failed (or without its plots), 130 interrupted.
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <unistd.h>

#include "cli/check_command.h"
#include "cli/command.h"
#include "cli/progress.h"
#include "cli/study_command.h"
#include "core/format.h"
#include "core/install_paths.h"
#include "core/limits.h"
#include "core/memory.h"
#include "io/atomic_file.h"
#include "io/film_files.h"
#include "io/mesh_file.h"
#include "io/session_journal.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "io/study_files.h"
#include "io/vdb_file.h"
#include "levelset/create.h"
#include "levelset/measure.h"
#include "levelset/peer_check.h"
#include "mesh/marching_cubes.h"
#include "sculpt/film.h"
#include "sculpt/sculptor.h"

namespace sweepers::cli {

Output gOut;
FlagInterrupter gStop;

void printJson(const nlohmann::json& j) {
    std::cout << j.dump(2) << "\n";
}

} // namespace sweepers::cli

namespace {

using namespace sweepers;
using namespace sweepers::cli;
using nlohmann::json;

extern "C" void onStopSignal(int) {
    gStop.interrupt();
}

json vec(const Eigen::Vector3d& v) {
    return json::array({v.x(), v.y(), v.z()});
}

// An option's number: the whole text, NaN where it is none.
double numberIn(const std::string& text) {
    try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used == text.size()) return v;
    } catch (const std::exception&) {
    }
    return std::nan("");
}

// A positive finite number, at most `most`, said in words (CLI11's own range check prints
// its bounds in seventeen digits).
CLI::Validator positiveNumber(double most = std::numeric_limits<double>::max()) {
    return CLI::Validator(
        [most](std::string& text) -> std::string {
            const double v = numberIn(text);
            if (v > 0.0 && v <= most) return "";
            return "must be a positive number" +
                   (most < std::numeric_limits<double>::max() ? " of at most " + formatNumber(most)
                                                              : std::string()) +
                   ", not " + text;
        },
        "POSITIVE");
}

// A number within core/limits.h's range, as a script's numbers are.
CLI::Validator scriptNumber() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            if (std::abs(numberIn(text)) <= kLargestNumber) return "";
            return "must be a number within 1e5 of zero, not " + text;
        },
        "NUMBER");
}

// An error: one line on stderr and, with --json, the same on stdout as {"error": ..., "exit":
// N}, so that a program reading stdout always gets one object (docs/cli.md).
int failWith(int code, const std::string& message) {
    std::cerr << "sweepers-cli: " << message << "\n";
    if (gOut.json) printJson({{"error", message}, {"exit", code}});
    return code;
}

// Fails early, before any long work, when an output cannot be written.
void requireWritable(const std::string& path) {
    const std::string dir = directoryOf(path);
    if (::access(dir.c_str(), W_OK) != 0)
        throw std::runtime_error(path + ": cannot write there (" + dir +
                                 " is not a writable directory)");
}

json infoJson(const LevelSetMeasures& m) {
    return {{"voxel_size", m.voxelSize},
            {"half_width", m.halfWidth},
            {"active_voxels", m.activeVoxels},
            {"leaf_nodes", m.leafNodes},
            {"memory_bytes", m.memoryBytes},
            {"bbox", {vec(m.bounds.min), vec(m.bounds.max)}},
            {"volume", m.volume},
            {"area", m.area},
            {"euler_characteristic", m.eulerCharacteristic},
            {"euler_characteristic_curvature", m.curvatureEuler},
            {"genus", m.genus},
            {"components", m.components}};
}

// Reads the level set a command works on; when the file holds several and none was named,
// says which one it took and how to take another.
GridPtr readChosenLevelSet(const std::string& path, const std::string& gridName) {
    const LevelSetFile file = readLevelSetFile(path, gridName);
    if (gridName.empty() && file.levelSets > 1)
        gOut.say(path + " holds " + std::to_string(file.levelSets) + " level sets; using '" +
                 file.name + "' (choose with --grid NAME)");
    return file.grid;
}

int runInfo(const std::string& path, const std::string& gridName) {
    const LevelSetFile file = readLevelSetFile(path, gridName);
    const GridPtr grid = file.grid;
    const LevelSetMeasures m = measureLevelSet(*grid);
    // The marching-cubes surface: its enclosed volume is exact for that surface, where
    // LevelSetMeasure's smeared integrals drift by a few tenths of a percent.
    const TriangleMesh mesh = meshLevelSet(*grid);
    const double meshVolume = enclosedVolume(mesh);
    const PeerCheck peer = peerCheck(*grid);
    if (gOut.json) {
        json j = infoJson(m);
        j["file"] = path;
        j["grid"] = file.name;
        j["grids_in_file"] = file.grids;
        j["mesh_volume"] = meshVolume;
        j["mesh_triangles"] = mesh.triangles.size();
        j["openvdb_check"] = peer.message;
        j["eikonal_outliers"] = peer.eikonal;
        j["eikonal_outliers_on_thin_features"] = peer.eikonalThin;
        j["thin_feature_voxels"] = peer.thinVoxels;
        j["thin_feature_bbox"] = peer.thinBox.empty()
                                     ? json(nullptr)
                                     : json{vec(peer.thinBox.min), vec(peer.thinBox.max)};
        j["eikonal_outliers_elsewhere_bbox"] =
            peer.elsewhereBox.empty()
                ? json(nullptr)
                : json{vec(peer.elsewhereBox.min), vec(peer.elsewhereBox.max)};
        std::cout << j.dump(2) << "\n";
        return 0;
    }
    char bbox[160] = "empty (no active voxels)";
    if (m.activeVoxels > 0)
        std::snprintf(bbox, sizeof bbox, "[%g %g %g] - [%g %g %g]", m.bounds.min.x(),
                      m.bounds.min.y(), m.bounds.min.z(), m.bounds.max.x(), m.bounds.max.y(),
                      m.bounds.max.z());
    std::printf("%s, grid '%s'\n", path.c_str(), file.name.c_str());
    if (file.grids.size() > 1) {
        std::printf("  the file holds %zu grids:", file.grids.size());
        for (const std::string& g : file.grids)
            std::printf("%s %s", &g == &file.grids.front() ? "" : ",", g.c_str());
        std::printf("\n");
    }
    std::printf("  voxel size %g, half-width %g voxels\n  %zu active voxels in %zu leaves, "
                "%.1f MiB\n  bbox %s\n  volume %.6g, area %.6g\n"
                "  Euler characteristic %d (LevelSetMeasure's curvature integral: %d), genus %d, "
                "%zu connected component(s)\n",
                m.voxelSize, m.halfWidth, m.activeVoxels, m.leafNodes, m.memoryBytes / 1048576.0,
                bbox, m.volume, m.area, m.eulerCharacteristic, m.curvatureEuler, m.genus,
                m.components);
    std::printf("  marching-cubes surface: %zu triangles, enclosed volume %.6g\n",
                mesh.triangles.size(), meshVolume);
    std::printf("  OpenVDB's checkLevelSet: %s\n",
                peer.message.empty() ? "no complaint" : peer.message.c_str());
    if (peer.eikonal > 0)
        std::printf("    its gradient test refuses %zu of the %zu voxels next to the surface; %zu "
                    "of them lie on features finer than its stencil reads\n",
                    peer.eikonal, peer.surfaceVoxels, peer.eikonalThin);
    if (peer.eikonal > peer.eikonalThin)
        std::printf("    the other %zu lie in [%g %g %g] - [%g %g %g]\n",
                    peer.eikonal - peer.eikonalThin, peer.elsewhereBox.min.x(),
                    peer.elsewhereBox.min.y(), peer.elsewhereBox.min.z(), peer.elsewhereBox.max.x(),
                    peer.elsewhereBox.max.y(), peer.elsewhereBox.max.z());
    if (peer.thinVoxels > 0)
        std::printf("  thin features (two surfaces or a ridge of the distance within 3 voxels, a "
                    "crease, or a thinner one across the stencil): %zu voxels next to the "
                    "surface, in [%g %g %g] - [%g %g %g]\n",
                    peer.thinVoxels, peer.thinBox.min.x(), peer.thinBox.min.y(),
                    peer.thinBox.min.z(), peer.thinBox.max.x(), peer.thinBox.max.y(),
                    peer.thinBox.max.z());
    return 0;
}

void reportMeshWritten(const std::string& path, const TriangleMesh& mesh) {
    gOut.say("wrote " + path + ": " + std::to_string(mesh.positions.size()) + " vertices, " +
             std::to_string(mesh.triangles.size()) + " triangles");
}

json meshJson(const std::string& path, const TriangleMesh& mesh) {
    return {
        {"path", path}, {"vertices", mesh.positions.size()}, {"triangles", mesh.triangles.size()}};
}

// The measures a --json report gives of a grid written: volume, area and topology.
json measuresJson(const Grid& grid) {
    const LevelSetMeasures m = measureLevelSet(grid);
    return {{"voxel_size", m.voxelSize},
            {"active_voxels", m.activeVoxels},
            {"volume", m.volume},
            {"area", m.area},
            {"topology",
             {{"euler_characteristic", m.eulerCharacteristic},
              {"genus", m.genus},
              {"components", m.components}}}};
}

// --voxel-size, when given: a positive finite number (0 is not "not given").
void requireVoxelSizeOption(double h, bool given) {
    if (given && !(h > 0.0 && std::isfinite(h)))
        throw UsageError("--voxel-size must be a positive number, not " + formatNumber(h));
}

// The surface as exported: y up as the modeler shows it, or turned so that z is up.
TriangleMesh exportedMesh(const Grid& grid, const std::string& up) {
    TriangleMesh mesh = meshLevelSet(grid);
    return up == "z" ? zUp(std::move(mesh)) : mesh;
}

void exportMesh(const Grid& grid, const std::string& path, const std::string& up) {
    const TriangleMesh mesh = exportedMesh(grid, up);
    writeMesh(mesh, path);
    reportMeshWritten(path, mesh);
}

// --half, refused before any stroke runs when the grid's values would not survive it.
void requireHalfFits(bool half, const Grid& grid) {
    if (!half) return;
    if (const std::string why = halfPrecisionProblem(grid.voxelSize()[0], halfWidthOf(grid));
        !why.empty())
        throw UsageError("--half: " + why);
}

struct ApplyArgs {
    std::string script, output, mesh, up = "y";
    double voxelSize = 0.0; // 0: the script's
    bool voxelSizeGiven = false;
    bool perSubStep = false, firstOrder = false, stats = false, cubic = false, trilinear = false,
         force = false, half = false;
};

int runApply(const ApplyArgs& a) {
    requireVoxelSizeOption(a.voxelSize, a.voxelSizeGiven);
    const StrokeScript script = readStrokeScript(a.script);
    if (!a.mesh.empty()) requireMeshPath(a.mesh);
    requireWritable(a.output);
    if (!a.mesh.empty()) requireWritable(a.mesh);

    AdvectOptions options;
    options.resampleEachSubStep = a.perSubStep;
    options.renormalization = a.firstOrder ? UpwindOrder::First : UpwindOrder::Second;
    options.sampling = a.cubic       ? Sampling::MonotoneCubic
                       : a.trilinear ? Sampling::Trilinear
                                     : Sampling::Corrected;
    options.interrupter = &gStop;
    Sculptor sculptor(makeStartGrid(script, directoryOf(a.script), a.voxelSize, &gStop, a.force),
                      options);
    requireHalfFits(a.half, sculptor.grid());
    const Grid& grid = sculptor.grid();
    // The volumes are only for the closing line and the report, and each walks the whole
    // band, which on one thread is a noticeable share of a short script: skipped when
    // nothing will show them.
    const bool report = !gOut.quiet || gOut.json;
    const double before = report ? levelSetVolume(grid) : 0.0;
    if (a.stats) sculptor.startMeshing();
    const double meshBefore = a.stats ? sculptor.mesher().enclosedVolume() : 0.0;
    const auto wallStart = Clock::now();
    std::vector<SegmentReport> reports;
    {
        ProgressLine progress(gOut.progress(), "applying " + a.script, "segment");
        reports = applyStrokes(sculptor, script.strokes, [&](std::size_t done, std::size_t all) {
            progress.update(done, all);
        });
    }
    pollInterrupt(&gStop);
    if (a.stats) {
        std::fprintf(stderr, "mesh volume before: %.7f\n", meshBefore);
        std::fprintf(stderr,
                     "stroke segment steps interface widened reach  grow_ms sample_ms renorm_ms "
                     "mesh_ms serial_ms leaves mesh_volume  visited copied flooded\n");
        for (const auto& r : reports)
            std::fprintf(
                stderr,
                "%6zu %7zu %5d %9zu %7.1f %5d %8.1f %9.1f %9.1f %7.1f %9.2f %6zu %11.7f %9zu "
                "%6zu %7zu\n",
                r.stroke, r.segment, r.stats.subSteps, r.stats.interfaceVoxels, r.stats.widenedTo,
                r.stats.sampledReach, 1e3 * r.stats.growSeconds, 1e3 * r.stats.sampleSeconds,
                1e3 * r.stats.renormalizeSeconds, 1e3 * r.meshSeconds, 1e3 * r.serialSeconds(),
                r.remeshedLeaves, r.meshVolume, r.stats.voxelsVisited, r.stats.leavesCopied,
                r.stats.leavesFlooded);
        // Where the time goes, phase by phase (mean over the segments): all of it, and the
        // part during which one thread worked while the others waited.
        if (!reports.empty()) {
            std::string line = "per segment, mean ms (serial):";
            const double n = double(reports.size());
            for (std::size_t k = 0; k < kAdvectPhases.size(); ++k) {
                double wall = 0.0, serial = 0.0;
                for (const auto& r : reports) {
                    wall += r.stats.phases[k].seconds;
                    serial += r.stats.phases[k].serialSeconds;
                }
                char part[96];
                std::snprintf(part, sizeof part, " %s %.2f (%.2f)", kAdvectPhases[k],
                              1e3 * wall / n, 1e3 * serial / n);
                line += part;
            }
            double wall = 0.0, serial = 0.0, all = 0.0, allSerial = 0.0;
            for (const auto& r : reports) {
                wall += r.meshSeconds;
                serial += r.meshSerialSeconds;
                all += r.seconds + r.meshSeconds;
                allSerial += r.serialSeconds();
            }
            char part[160];
            std::snprintf(part, sizeof part,
                          " mesh %.2f (%.2f); segment %.2f (%.2f), serial fraction %.3f",
                          1e3 * wall / n, 1e3 * serial / n, 1e3 * all / n, 1e3 * allSerial / n,
                          all > 0.0 ? allSerial / all : 0.0);
            std::fprintf(stderr, "%s%s\n", line.c_str(), part);
        }
    }
    double adv = 0, ren = 0, grow = 0;
    for (const auto& r : reports) {
        adv += r.stats.sampleSeconds;
        ren += r.stats.renormalizeSeconds;
        grow += r.stats.growSeconds;
    }
    // Both files are written before either replaces its old version: a failed mesh write
    // leaves no new grid behind.
    LevelSetWriteOptions written;
    written.half = a.half;
    AtomicWrite vdb = prepareLevelSet(grid, a.output, written);
    std::optional<AtomicWrite> meshFile;
    TriangleMesh mesh;
    if (!a.mesh.empty()) {
        mesh = exportedMesh(grid, a.up);
        meshFile.emplace(prepareMesh(mesh, a.mesh));
    }
    vdb.commit();
    if (meshFile) meshFile->commit();
    const double wall = secondsSince(wallStart);
    const double after = report ? levelSetVolume(grid) : 0.0;
    char line[256];
    std::snprintf(line, sizeof line,
                  ": %zu segments (band growth %.3f s, sampling %.3f s, "
                  "renormalization %.3f s), volume %.6g -> %.6g (%+.3f%%)",
                  reports.size(), grow, adv, ren, before, after, 100.0 * (after - before) / before);
    gOut.say("wrote " + a.output + line);
    if (meshFile) reportMeshWritten(a.mesh, mesh);
    if (gOut.json) {
        json j = measuresJson(grid);
        j["script"] = a.script;
        j["output"] = a.output;
        j["mesh"] = meshFile ? meshJson(a.mesh, mesh) : json(nullptr);
        j["segments"] = reports.size();
        if (a.stats) {
            // The steps run, in the rows check prints for its plan (the same function), each
            // with what running it took.
            json steps = json::array();
            for (const SegmentReport& r : reports) {
                steps.push_back(stepJson(r.stroke, r.step));
                steps.back()["ran"] = {{"sub_steps", r.stats.subSteps}, {"seconds", r.seconds}};
            }
            j["deformations"] = steps;
        }
        j["volume_before"] = before;
        j["volume_change_pct"] = 100.0 * (after - before) / before;
        j["timings"] = {{"wall_s", wall},
                        {"band_growth_s", grow},
                        {"sampling_s", adv},
                        {"renormalization_s", ren}};
        json files = json::array({a.output});
        if (meshFile) files.push_back(a.mesh);
        j["files"] = files;
        printJson(j);
    }
    return kDone;
}

// Rebuilds the document of a modeler session that ended in a crash, as the modeler's
// --recover does, and writes it; the session itself is left as it is.
int runRecover(const std::string& where, const std::string& output, const std::string& script) {
    requireWritable(output);
    if (!script.empty()) requireWritable(script);
    const std::string dir = sessionToRecover(where.empty() ? defaultSessionRoot() : where);
    const JournalState state = readJournal(dir);
    const RecoveryStart start = recoveryStart(state, &gStop);
    Sculptor sculptor(start.grid);
    applyStrokes(sculptor,
                 std::vector<Stroke>(state.script.strokes.begin() + std::ptrdiff_t(start.strokes),
                                     state.script.strokes.end()));
    pollInterrupt(&gStop);
    AtomicWrite vdb = prepareLevelSet(sculptor.grid(), output);
    std::optional<AtomicWrite> scriptFile;
    if (!script.empty()) {
        const std::string text =
            formatStrokeScript(withAbsoluteFiles(state.script, state.scriptDir));
        scriptFile.emplace(script, [&](std::ostream& out) { out << text; });
    }
    vdb.commit();
    if (scriptFile) scriptFile->commit();
    gOut.say(dir + ": " + describeRecovery(state, start));
    return kDone;
}

// A film's bounds: beyond them a typo (--fps 1e9) would plan more frames than fit in memory.
constexpr double kMostFps = 1000.0;
constexpr std::size_t kMostFrames = 1000000;

struct AnimateArgs {
    std::string script, output, mesh, frames, fog, up = "y";
    double fps = 24.0, secondsPerSegment = 0.25, voxelSize = 0.0;
    bool voxelSizeGiven = false, force = false, half = false;
};

// "A-B" or "A", within 1..count.
std::pair<std::size_t, std::size_t> parseFrameRange(const std::string& text, std::size_t count) {
    if (text.empty()) return {1, count};
    const std::string all = "1-" + std::to_string(count);
    std::size_t a = 0, b = 0;
    try {
        std::size_t used = 0;
        a = std::stoul(text, &used);
        b = a;
        if (used < text.size()) {
            if (text[used] != '-') throw std::invalid_argument("");
            std::size_t more = 0;
            b = std::stoul(text.substr(used + 1), &more);
            if (used + 1 + more != text.size()) throw std::invalid_argument("");
        }
    } catch (const std::exception&) {
        throw UsageError("--frames: '" + text + "' is not a frame range such as " + all);
    }
    if (a < 1 || a > b || b > count)
        throw UsageError("--frames: " + text + " is not within the film's frames " + all);
    return {a, b};
}

// Plays a script as a film (sculpt/film.h) and writes one VDB per frame, each atomically,
// so an interrupted film resumes: a frame on disk made of the same things (frameDigests),
// at the same time, frame rate and voxel size is kept, so an edit rewrites only the frames
// it changes.
int runAnimate(const AnimateArgs& a) {
    requireVoxelSizeOption(a.voxelSize, a.voxelSizeGiven);
    std::string text; // the script as parsed: what the frames are made of
    const StrokeScript script = readStrokeScript(a.script, &text);
    FilmTiming timing;
    timing.fps = a.fps;
    timing.secondsPerSegment = a.secondsPerSegment;
    double seconds = 0.0;
    for (const double d : strokeDurations(script, timing))
        seconds += d;
    if (!(seconds * timing.fps <= double(kMostFrames)))
        throw UsageError("the film would have " + formatNumber(std::ceil(seconds * timing.fps)) +
                         " frames (" + formatNumber(seconds) + " s at " + formatNumber(timing.fps) +
                         " fps); a film has at most " + std::to_string(kMostFrames));
    if (a.fog == "surface") // the level set's name (markAsDocument)
        throw UsageError("--fog: '" + a.fog +
                         "' is the level set's own name; give the fog another");
    const std::size_t count = filmFrameCount(seconds, timing.fps);
    // (Plain variables: lambdas below capture them, which C++17 forbids for bindings.)
    const std::pair<std::size_t, std::size_t> range = parseFrameRange(a.frames, count);
    const std::size_t first = range.first, last = range.second;
    // The frames' directories are made as a study's is.
    auto frameDirectory = [&](const std::string& pattern) {
        checkFramePattern(pattern);
        const std::string path = framePath(pattern, first);
        std::error_code ec;
        std::filesystem::create_directories(directoryOf(path), ec);
        if (ec)
            throw std::runtime_error(path + ": cannot create its directory (" + ec.message() + ")");
        requireWritable(path);
    };
    frameDirectory(a.output);
    if (!a.mesh.empty()) {
        requireMeshPath(framePath(a.mesh, first));
        frameDirectory(a.mesh);
    }

    AdvectOptions options;
    options.interrupter = &gStop;
    Sculptor sculptor(makeStartGrid(script, directoryOf(a.script), a.voxelSize, &gStop, a.force),
                      options);
    requireHalfFits(a.half, sculptor.grid());
    const double h = sculptor.grid().voxelSize()[0];
    // A frame is made of its fog's name and, when asked, its half-float values too: a film
    // played again with another choice rewrites its frames rather than keeping them.
    const FrameFileOptions frameFiles{a.fog, a.half};
    const std::vector<std::string> digests =
        frameDigests(text, script, timing, a.half ? a.fog + "\nhalf-float values" : a.fog);
    auto stampOf = [&](std::size_t n) {
        return FrameStamp{int(n), filmFrameTime(n, seconds, timing.fps), timing.fps, digests[n]};
    };
    // Frames on disk made of the same things are kept; anything else in their place is
    // refused, unless --force overwrites it, before any work starts.
    std::vector<char> kept(last + 1, 0);
    std::size_t keptCount = 0;
    for (std::size_t n = first; n <= last; ++n) {
        const std::string path = framePath(a.output, n);
        if (!std::filesystem::exists(path)) continue;
        const std::optional<FrameStamp> on = readFrameStamp(path);
        const FrameStamp want = stampOf(n);
        if (!on || on->frame != want.frame || on->time != want.time || on->fps != want.fps ||
            on->script != want.script || on->voxelSize != h) {
            if (a.force) continue;
            throw std::runtime_error(path + ": not frame " + std::to_string(n) +
                                     " of this film (another script, timing, voxel size, fog or "
                                     "precision); "
                                     "--force overwrites it");
        }
        kept[n] = a.mesh.empty() || std::filesystem::exists(framePath(a.mesh, n));
        keptCount += kept[n];
    }
    std::size_t written = 0;
    json files = json::array();
    try {
        ProgressLine progress(gOut.progress(), "animating " + a.script, "frame");
        playFilm(
            sculptor, script, timing, first, last,
            [&](std::size_t n, double, const Grid& grid) {
                AtomicWrite vdb =
                    prepareFrame(grid, stampOf(n), framePath(a.output, n), frameFiles);
                std::optional<AtomicWrite> meshFile;
                if (!a.mesh.empty())
                    meshFile.emplace(prepareMesh(exportedMesh(grid, a.up), framePath(a.mesh, n)));
                vdb.commit();
                if (meshFile) meshFile->commit();
                ++written;
            },
            [&](std::size_t n) { return !kept[n]; },
            [&](std::size_t done, std::size_t all) { progress.update(done, all); });
    } catch (const Cancelled&) {
        std::fprintf(stderr,
                     "sweepers-cli: interrupted; the frames written are kept (the same command "
                     "resumes the film)\n");
        return kInterrupted;
    }
    char line[160];
    std::snprintf(line, sizeof line, "wrote frames %zu-%zu of %zu (%.4g s at %.4g fps) to ", first,
                  last, count, seconds, timing.fps);
    gOut.say(line + a.output +
             (keptCount ? ", " + std::to_string(keptCount) + " kept from before" : ""));
    if (gOut.json) {
        for (std::size_t n = first; n <= last; ++n) {
            files.push_back(framePath(a.output, n));
            if (!a.mesh.empty()) files.push_back(framePath(a.mesh, n));
        }
        printJson({{"script", a.script},
                   {"frames", {{"first", first}, {"last", last}, {"count", count}}},
                   {"fps", timing.fps},
                   {"seconds", seconds},
                   {"voxel_size", h},
                   {"written", written},
                   {"kept", keptCount},
                   {"fog", a.fog.empty() ? json(nullptr) : json(a.fog)},
                   {"files", files}});
    }
    return kDone;
}
} // namespace

static int run(int argc, char** argv) {
    CLI::App app{"sweepers-cli: sculpt narrow-band level sets with sweepers"};
    app.set_version_flag("--version", "sweepers-cli " SWEEPERS_VERSION);
    const ProgramPlaces places = programPlaces();
    app.footer("Examples: " + places.examples + " (sweepers-cli apply " + places.examples +
               "/horn.json -o horn.vdb)\nGuides: " + places.guides +
               "/README.md and docs/ beside it (cli.md, stroke-scripts.md, studies.md)");
    app.require_subcommand(1);
    int threads = 0;
    app.add_option("--threads", threads, "Worker threads (default: all cores)")
        ->check(CLI::Range(1, 1024));

    // -q and --json: on the program and on each command, wherever the user puts them.
    const auto quietFlag = [](CLI::App* on) {
        on->add_flag("-q,--quiet", gOut.quiet, "Print nothing but errors");
    };
    const auto jsonFlag = [](CLI::App* on, const std::string& what) {
        on->add_flag("--json", gOut.json, "Print " + what + " as one JSON object on stdout");
    };
    quietFlag(&app);
    // The limits (core/limits.h), on the program and on each command too.
    double maxMemoryGb = 0.0, maxWork = 0.0;
    const auto limitOptions = [&](CLI::App* on) {
        on->add_option("--max-memory", maxMemoryGb,
                       "Refuse work estimated to need more memory, in GB (default: half the "
                       "memory available)")
            ->check(positiveNumber());
        on->add_option("--max-work", maxWork,
                       "Refuse a stroke estimated to take more voxel updates (default 2e9)")
            ->check(positiveNumber());
    };
    limitOptions(&app);

    std::string path, output;
    CheckArgs checkArgs;
    CLI::App* check = app.add_subcommand("check", "Validate a stroke script and show its plan");
    check->add_option("script", checkArgs.script, "Stroke script (JSON)")->required();
    check
        ->add_option("--voxel-size", checkArgs.voxelSize,
                     "Plan at this voxel size, as apply --voxel-size runs (default: the script's)")
        ->check(positiveNumber());
    jsonFlag(check, "the plan");

    double radius = 1.0, voxelSize = 0.02, halfWidth = 3.0;
    std::vector<double> center{0, 0, 0};
    CLI::App* create = app.add_subcommand("new", "Write a sphere level set");
    create->add_option("-o,--output", output, "Output .vdb")->required();
    create->add_option("--radius", radius, "Sphere radius")->check(positiveNumber());
    create->add_option("--center", center, "Sphere centre")->expected(3)->check(scriptNumber());
    create->add_option("--voxel-size", voxelSize, "Voxel size")->check(positiveNumber());
    create->add_option("--half-width", halfWidth, "Band half-width in voxels")
        ->check(CLI::Range(2.0, 64.0));
    bool force = false;
    create->add_flag("--force", force,
                     "Build the sphere even when it seems to need more memory than is free");

    ApplyArgs applyArgs;
    CLI::App* apply = app.add_subcommand("apply", "Apply a stroke script and write the result");
    apply->add_option("script", applyArgs.script, "Stroke script (JSON)")->required();
    apply->add_option("-o,--output", applyArgs.output, "Output .vdb")->required();
    CLI::Option* applyVoxelSize =
        apply->add_option("--voxel-size", applyArgs.voxelSize, "Override the script's voxel size");
    apply->add_option("--mesh", applyArgs.mesh, "Also export the surface (.obj, .ply, .stl)");
    apply->add_flag("--half", applyArgs.half, kHalfHelp);
    apply
        ->add_option("--up", applyArgs.up,
                     "The mesh's up axis: y (as shown) or z (Blender's "
                     "PLY and STL importers, CAD tools)")
        ->check(CLI::IsMember({"y", "z"}));
    apply->add_flag("--resample-each-substep", applyArgs.perSubStep,
                    "Resample after every sub-step (the thesis's 5.3.4; blurrier)");
    apply->add_flag("--first-order", applyArgs.firstOrder, "First-order fast marching");
    auto* cubic = apply->add_flag(
        "--monotone-cubic", applyArgs.cubic,
        "Resample with the monotone cubic of appendix C.1 instead of corrected trilinear");
    apply
        ->add_flag("--trilinear", applyArgs.trilinear,
                   "Resample trilinearly without the correction (the thesis's 5.3.2)")
        ->excludes(cubic);
    jsonFlag(apply, "what was measured and written");
    apply->add_flag("--force", applyArgs.force,
                    "Build the start shape even when it seems to need more memory than is free");
    apply->add_flag("--stats", applyArgs.stats,
                    "Print a table of per-segment timings (band growth, sampling, "
                    "renormalization, incremental re-meshing)");
    // All CLI options are also available for --threads placement after the subcommand.
    apply->add_option("--threads", threads, "Worker threads")->check(CLI::Range(1, 1024));

    CLI::App* info = app.add_subcommand("info", "Describe a level-set VDB file");
    info->add_option("file", path, "Level-set .vdb")->required();
    jsonFlag(info, "the description");
    std::string gridName;
    info->add_option("--grid", gridName,
                     "The level set to describe, by name (default: the first usable one)");

    CLI::App* mesh = app.add_subcommand("mesh", "Export the surface of a level-set VDB file");
    mesh->add_option("file", path, "Level-set .vdb")->required();
    mesh->add_option("-o,--output", output, "Output mesh (.obj, .ply, .stl)")->required();
    mesh->add_option("--grid", gridName,
                     "The level set to mesh, by name (default: the first usable one)");
    std::string up = "y";
    mesh->add_option("--up", up,
                     "Up axis: y (as shown) or z (Blender's PLY and STL importers, "
                     "CAD tools)")
        ->check(CLI::IsMember({"y", "z"}));

    std::string scriptOut;
    CLI::App* recover = app.add_subcommand(
        "recover", "Rebuild the document of a modeler session that ended in a crash");
    recover->add_option("session", path,
                        "A session directory, or a directory of sessions (the newest interrupted "
                        "one is taken; default: where the modeler keeps them)");
    recover->add_option("-o,--output", output, "Output .vdb")->required();
    recover->add_option("--script", scriptOut, "Also write the recovered stroke script (.json)");

    StudyArgs studyArgs;
    studyArgs.threads = &threads;
    CLI::App* study = addStudyCommand(app, studyArgs);
    jsonFlag(study, "every run's row and the files written");

    AnimateArgs animateArgs;
    CLI::App* animate = app.add_subcommand(
        "animate", "Play a stroke script as a film: one level set per frame (a VDB sequence)");
    animate->add_option("script", animateArgs.script, "Stroke script (JSON)")->required();
    animate
        ->add_option("-o,--output", animateArgs.output,
                     "Frame files, the frame number in place of the '#' run "
                     "(for example frames/shape_####.vdb)")
        ->required();
    animate->add_option("--fps", animateArgs.fps, "Frames per second (default 24, at most 1000)")
        ->check(positiveNumber(kMostFps));
    animate
        ->add_option("--seconds-per-segment", animateArgs.secondsPerSegment,
                     "Duration of a path segment of a stroke without a duration "
                     "(default 0.25)")
        ->check(positiveNumber());
    animate->add_option("--frames", animateArgs.frames, "Only these frames: A-B or A");
    animate->add_option("--mesh", animateArgs.mesh,
                        "Also a mesh per frame (.ply, .obj or .stl, with a '#' run)");
    animate->add_option("--up", animateArgs.up, "Up axis of the meshes (y or z, default y)")
        ->check(CLI::IsMember({"y", "z"}));
    animate
        ->add_option("--fog", animateArgs.fog,
                     "Also a fog volume of this name beside the level set (default: density)")
        ->expected(0, 1)
        ->default_str("density");
    animate->add_flag("--half", animateArgs.half, kHalfHelp);
    CLI::Option* animateVoxelSize = animate->add_option("--voxel-size", animateArgs.voxelSize,
                                                        "Override the script's voxel size");
    jsonFlag(animate, "the frames and files written");
    animate->add_flag("--force", animateArgs.force,
                      "Overwrite frames of another film; build the start even when it seems to "
                      "need more memory than is free");
    animate->add_option("--threads", threads, "Worker threads")->check(CLI::Range(1, 1024));

    // The docs name the examples as $(sweepers-cli examples)/horn.json, so that one command
    // works in a checkout and after an install.
    CLI::App* examples = app.add_subcommand(
        "examples", "Print the folder of the example stroke scripts (data/ in a checkout)");

    for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; })) {
        quietFlag(command);
        limitOptions(command);
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version are not errors; anything else CLI11 refuses is a usage error.
        const int code = app.exit(e);
        if (code == 0) return kDone;
        // (CLI11 stops at the error: --json may lie beyond it.)
        for (int i = 1; i < argc; ++i)
            gOut.json = gOut.json || std::string(argv[i]) == "--json";
        if (gOut.json) printJson({{"error", e.what()}, {"exit", int(kUsage)}});
        return kUsage;
    }
    setLimits({maxMemoryGb * 1e9, maxWork});
    applyArgs.voxelSizeGiven = applyVoxelSize->count() > 0;
    animateArgs.voxelSizeGiven = animateVoxelSize->count() > 0;
    std::signal(SIGINT, onStopSignal);
    std::signal(SIGTERM, onStopSignal);
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      std::size_t(threads));
    try {
        if (*examples) {
            if (!std::filesystem::is_directory(places.examples))
                throw FileError("the examples are not installed at " + places.examples);
            std::cout << places.examples << "\n";
            return kDone;
        }
        if (*check) return runCheck(checkArgs);
        if (*info) return runInfo(path, gridName);
        if (*apply) return runApply(applyArgs);
        if (*recover) return runRecover(path, output, scriptOut);
        if (*study) return runStudy(studyArgs);
        if (*animate) return runAnimate(animateArgs);
        if (*create) {
            requireSphereSize(radius, voxelSize);
            requireWritable(output);
            requireMemoryForBand(4.0 * M_PI * radius * radius, voxelSize, halfWidth,
                                 kSphereBytesPerVoxel, force);
            const GridPtr g =
                makeSphere({center[0], center[1], center[2]}, radius, voxelSize, halfWidth);
            writeLevelSet(*g, output);
            return kDone;
        }
        if (*mesh) {
            requireMeshPath(output);
            requireWritable(output);
            exportMesh(*readChosenLevelSet(path, gridName), output, up);
            return kDone;
        }
    } catch (const Cancelled&) {
        // The shell's code for a command ended by SIGINT.
        return failWith(kInterrupted, "interrupted; nothing was written");
    } catch (const UsageError& e) {
        return failWith(kUsage, e.what());
    } catch (const std::exception& e) {
        return failWith(kFailed, e.what());
    }
    return kDone;
}

int main(int argc, char** argv) {
    sweepers::keepFreedMemory();
    // What run does not catch itself (running out of memory while setting up).
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "sweepers-cli: %s\n", e.what());
        return kFailed;
    }
}
