// SPDX-License-Identifier: Apache-2.0
// Histories nobody wrote by hand (random_history.h): every one must hold the properties a
// history promises (docs/engine.md, "What a history guarantees"). A failing history is cut
// to the fewest strokes that still fail and written out as a script, to become a fixed
// regression test once fixed (kept in tests/histories/, run by FixedHistories below).
//
// CI runs a coarse set (SWEEPERS_COARSE_TESTS: 30 histories of 3 or 4 strokes at 1/32 to
// 1/36, fewer pinches and strangles, compared with one thread only); by hand, any number
// from any seed, of 4 to 12 strokes at 1/32 to 1/80:
//     SWEEPERS_HISTORIES=200 SWEEPERS_HISTORY_SEED=1 build/tests/history_tests
// A shrunk failure is written into $SWEEPERS_HISTORY_OUT (default: the working directory).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "app/sculpt_controller.h"
#include "app/session.h"
#include "coarse.h"
#include "document/document.h"
#include "grids.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "io/vdb_file.h"
#include "levelset/band.h"
#include "levelset/create.h"
#include "levelset/measure.h"
#include "levelset/peer_check.h"
#include "mesh/marching_cubes.h"
#include "mesh/triangle_mesh.h"
#include "random_gestures.h"
#include "random_history.h"
#include "replay.h"
#include "scratch_dir.h"

using namespace sweepers;
using nlohmann::json;

namespace {

std::size_t envCount(const char* name, std::size_t fallback) {
    const char* v = std::getenv(name);
    return v && *v ? std::size_t(std::strtoul(v, nullptr, 10)) : fallback;
}

// The properties, in the order they are checked.
const std::vector<std::string> kProperties = {"valid",    "runs",   "undo",    "redo", "band",
                                              "topology", "volume", "threads", "peer", "journal"};
// The most a volume-keeping stroke (swirl, fluid) may change the volume by, in voxel layers
// over the surface a segment (docs/stroke-scripts.md).
constexpr double kVolumeLayers = 0.03;

struct Failure {
    std::string property, detail;
};

// Applies a history and checks every property; the first failure of each is kept.
class HistoryCheck {
  public:
    HistoryCheck(const json& history, std::string dir) : history_(history), dir_(std::move(dir)) {}

    std::vector<Failure> run() {
        StrokeScript script;
        try {
            script = loadStrokeScript(history_.dump(), "history", dir_);
        } catch (const std::exception& e) {
            return {{"valid", e.what()}};
        }
        try {
            check(script);
        } catch (const std::exception& e) {
            fail("runs", e.what());
        }
        return failures_;
    }

  private:
    void check(const StrokeScript& script) {
        // Stroke by stroke in a document, as the modeler applies them: each undone and done
        // again, the band checked, the topology kept where it must be.
        StrokeScript start = script;
        start.strokes.clear();
        Document doc(start, dir_);
        // The crash journal the modeler keeps of the same edits, with a checkpoint every
        // two strokes (what a recovery replays from).
        test::ScratchDir sessions;
        SessionOptions so;
        so.root = sessions.path.string();
        so.checkpointStrokes = 2;
        auto session = std::make_unique<Session>(so);
        session->follow(doc);
        for (std::size_t i = 0; i < script.strokes.size(); ++i) {
            const Stroke& stroke = script.strokes[i];
            const GridPtr before = doc.grid().deepCopy();
            const int eulerBefore = topologicalEulerCharacteristic(doc.grid());
            doc.beginEdit();
            const SegmentReport last = doc.applyStroke(stroke);
            doc.endEdit();
            const GridPtr after = doc.grid().deepCopy();
            doc.undo();
            if (const std::size_t d = test::differingBits(doc.grid(), *before))
                fail("undo", at(i) + std::to_string(d) + " voxels differ");
            doc.redo();
            if (const std::size_t d = test::differingBits(doc.grid(), *after))
                fail("redo", at(i) + std::to_string(d) + " voxels differ");
            const BandReport band = checkBand(doc.grid());
            if (!band.vdbCheck.empty() || band.bandHoles || band.beyondBand)
                fail("band", at(i) + band.vdbCheck + " holes " + std::to_string(band.bandHoles) +
                                 " beyond " + std::to_string(band.beyondBand));
            if (keepsVolume(stroke)) {
                // In voxel layers over the surface, per segment: what resampling may shave off
                // or add at each step.
                const TriangleMesh a = meshLevelSet(*before), b = meshLevelSet(doc.grid());
                const double h = doc.grid().voxelSize()[0], area = surfaceArea(a);
                const double layers =
                    (enclosedVolume(b) - enclosedVolume(a)) / (h * area) / double(last.segment + 1);
                std::printf("[ volume ] %s: %+.3g voxel layers a segment (%zu segments)\n",
                            history_["strokes"][i].dump().c_str(), layers, last.segment + 1);
                if (std::abs(layers) > kVolumeLayers)
                    fail("volume", at(i) + std::to_string(layers) +
                                       " voxel layers over the surface a segment");
            }
            const int euler = topologicalEulerCharacteristic(doc.grid());
            if (euler != eulerBefore && !changesTopology(stroke))
                fail("topology", at(i) + "Euler characteristic " + std::to_string(eulerBefore) +
                                     " -> " + std::to_string(euler));
        }
        // The journal, left on disk as a crash leaves it, recovers the same grid.
        session->flush();
        const std::string journalError = session->takeError(), sessionDir = session->dir();
        doc.setHistoryListener(nullptr);
        session.reset();
        if (!journalError.empty()) {
            fail("journal", journalError);
        } else {
            Adoption adopt;
            const std::unique_ptr<Document> recovered = recoverDocument(sessionDir, adopt);
            if (const std::size_t d = test::differingBits(recovered->grid(), doc.grid()))
                fail("journal", "the recovered grid: " + std::to_string(d) + " voxels differ");
        }
        // The same history in one go, on 1 and 3 threads: the same grid, to the bit (the
        // coarse set, on 1 only: the document ran on the machine's threads).
        for (const int threads : {1, 3}) {
            if (threads == 3 && test::coarse()) continue;
            const tbb::global_control most(tbb::global_control::max_allowed_parallelism,
                                           std::size_t(threads));
            tbb::task_arena arena(threads);
            GridPtr grid;
            arena.execute([&] { grid = applyScript(script, dir_); });
            if (const std::size_t d = test::differingBits(*grid, doc.grid()))
                fail("threads",
                     std::to_string(threads) + " threads: " + std::to_string(d) + " voxels differ");
        }
        const PeerCheck peer = peerCheck(doc.grid());
        if (peer.eikonal > peer.eikonalThin)
            fail("peer", std::to_string(peer.eikonal - peer.eikonalThin) + " of " +
                             std::to_string(peer.eikonal) + " refused voxels on no thin feature");
    }

    void fail(const std::string& property, const std::string& detail) {
        for (const Failure& f : failures_)
            if (f.property == property) return;
        failures_.push_back({property, detail});
    }
    static std::string at(std::size_t stroke) { return "stroke " + std::to_string(stroke) + ": "; }
    static bool keepsVolume(const Stroke& s) {
        return std::holds_alternative<SwirlStroke>(s) || std::holds_alternative<FluidStroke>(s);
    }
    // The strokes that change the topology on purpose (a flow's field is not a sweeper).
    static bool changesTopology(const Stroke& s) {
        return std::holds_alternative<PinchStroke>(s) ||
               std::holds_alternative<StrangleStroke>(s) || std::holds_alternative<FlowStroke>(s);
    }

    json history_;
    std::string dir_;
    std::vector<Failure> failures_;
};

// The properties every history holds today. The engine does not hold the other two on every
// history yet (docs/engine.md, "What a history guarantees"): they are measured and printed,
// and asserted with SWEEPERS_HISTORY_STRICT=1.
bool asserted(const std::string& property) {
    return property != "topology" && property != "peer";
}

bool breaks(const std::vector<Failure>& failures, const std::string& property) {
    return std::any_of(failures.begin(), failures.end(),
                       [&](const Failure& f) { return f.property == property; });
}

// The history cut to the fewest strokes that still break `property` (one stroke taken away at
// a time, as long as one can be).
json shrink(json history, const std::string& property, const std::string& dir) {
    for (bool cut = true; cut;) {
        cut = false;
        for (std::size_t i = 0; i < history["strokes"].size() && history["strokes"].size() > 1;) {
            json fewer = history;
            fewer["strokes"].erase(fewer["strokes"].begin() + std::ptrdiff_t(i));
            if (breaks(HistoryCheck(fewer, dir).run(), property)) {
                history = std::move(fewer); // the same place now holds the next stroke
                cut = true;
            } else {
                ++i;
            }
        }
    }
    return history;
}

// The start files the histories may name, made once.
struct StartFiles {
    test::ScratchDir scratch;
    std::string vdb, mesh;
    // In a scratch directory removed after, or in `into`.
    explicit StartFiles(double voxelSize, const std::filesystem::path& into = {}) {
        const std::filesystem::path dir = into.empty() ? scratch.path : into;
        // An ellipsoid as a level set, and a rounded box as a mesh (its edges are creases
        // the grid does not resolve: the report must say so).
        const int n = int(std::ceil(1.3 / voxelSize));
        // (Scaled by its smallest semi-axis: a distance nowhere too long, renormalized when
        // read.)
        const GridPtr ellipsoid = test::gridFromSdf(
            [](const Eigen::Vector3d& p) {
                const Eigen::Vector3d q(p.x() / 1.1, p.y(), p.z() / 0.85);
                return (q.norm() - 1.0) * 0.85;
            },
            voxelSize, 3.0, openvdb::CoordBBox::createCube(openvdb::Coord(-n), 2 * n));
        vdb = dir / "ellipsoid.vdb";
        writeLevelSet(*ellipsoid, vdb);
        mesh = dir / "box.obj";
        std::ofstream obj(mesh);
        const double s = 0.8;
        for (int k = 0; k < 8; ++k)
            obj << "v " << (k & 1 ? s : -s) << ' ' << (k & 2 ? s : -s) << ' ' << (k & 4 ? s : -s)
                << '\n';
        // Faces wound outwards (1-based).
        const int faces[12][3] = {{1, 3, 2}, {2, 3, 4}, {5, 6, 7}, {6, 8, 7}, {1, 2, 5}, {2, 6, 5},
                                  {3, 7, 4}, {4, 7, 8}, {1, 5, 3}, {3, 5, 7}, {2, 4, 6}, {4, 8, 6}};
        for (const auto& f : faces)
            obj << "f " << f[0] << ' ' << f[1] << ' ' << f[2] << '\n';
    }
};

// The histories' options: the CI set's (coarse) or the full one.
test::HistoryOptions optionsFor(bool coarse) {
    test::HistoryOptions options;
    if (coarse) {
        options.coarsest = 32;
        options.finest = 36;
        options.fewestStrokes = 3;
        options.mostStrokes = 4;
        options.tearShare = 0.02;
    }
    options.vdbVoxelSize = 2.0 / (options.coarsest + options.finest);
    return options;
}

} // namespace

// (Outside the anonymous namespace: the tests GoogleTest derives from it are not in it.)
// Six shards of the histories, which CTest runs side by side (five each in CI: under the
// sanitizers none nears its timeout).
class RandomHistories : public ::testing::TestWithParam<int> {};
constexpr int kShards = 6;

TEST_P(RandomHistories, HoldEveryProperty) {
    const bool coarse = test::coarse();
    const std::size_t all = envCount("SWEEPERS_HISTORIES", 30);
    const std::size_t first = all * std::size_t(GetParam()) / kShards,
                      count = all * std::size_t(GetParam() + 1) / kShards - first;
    const unsigned seed = unsigned(envCount("SWEEPERS_HISTORY_SEED", 1) + first);
    const bool strict = envCount("SWEEPERS_HISTORY_STRICT", 0) != 0;
    test::HistoryOptions options = optionsFor(coarse);
    const StartFiles starts(options.vdbVoxelSize);
    options.vdbStart = starts.vdb;
    options.meshStart = starts.mesh;
    const char* out = std::getenv("SWEEPERS_HISTORY_OUT");
    std::map<std::string, std::size_t> held;
    for (std::size_t i = 0; i < count; ++i) {
        const unsigned s = seed + unsigned(i);
        const json history = test::HistoryGenerator(s, options).script();
        const std::vector<Failure> failures = HistoryCheck(history, "").run();
        std::string said;
        for (const Failure& f : failures)
            said += "; " + f.property + " fails: " + f.detail;
        std::printf("[ history ] seed %u: %zu strokes at 1/%g%s\n", s, history["strokes"].size(),
                    1.0 / history["grid"]["voxel_size"].get<double>(),
                    said.empty() ? ": holds" : said.c_str());
        std::fflush(stdout);
        for (const std::string& p : kProperties)
            held[p] += !breaks(failures, p);
        for (const Failure& f : failures) {
            if (!strict && !asserted(f.property)) continue;
            const json shrunk = shrink(history, f.property, "");
            const std::string path = std::string(out && *out ? out : ".") + "/history_" +
                                     std::to_string(s) + "_" + f.property + ".json";
            std::ofstream(path) << shrunk.dump(2) << '\n';
            ADD_FAILURE() << "seed " << s << " breaks " << f.property << " (" << f.detail
                          << "); shrunk to " << shrunk["strokes"].size() << " strokes in " << path;
            break; // one shrink a history: each costs many runs
        }
    }
    std::printf("[ histories ] %zu from seed %u; each property held by:", count, seed);
    for (const std::string& p : kProperties)
        std::printf(" %s %zu", p.c_str(), held[p]);
    std::printf("\n");
}

INSTANTIATE_TEST_SUITE_P(Shard, RandomHistories, ::testing::Range(0, kShards));

// The CI set's first histories as scripts, with their start files, in
// $SWEEPERS_HISTORY_SCRIPTS (history_<seed>.json): the Python module's test applies them
// through a Sculptor (tests/python). Run by that test only (--gtest_also_run_disabled_tests).
TEST(RandomHistories, DISABLED_WriteScripts) {
    const char* out = std::getenv("SWEEPERS_HISTORY_SCRIPTS");
    ASSERT_TRUE(out && *out) << "SWEEPERS_HISTORY_SCRIPTS names no directory";
    test::HistoryOptions options = optionsFor(true);
    const StartFiles starts(options.vdbVoxelSize, out);
    options.vdbStart = starts.vdb;
    options.meshStart = starts.mesh;
    const unsigned seed = unsigned(envCount("SWEEPERS_HISTORY_SEED", 1));
    for (std::size_t i = 0; i < envCount("SWEEPERS_HISTORIES", 6); ++i) {
        const unsigned s = seed + unsigned(i);
        std::ofstream(std::string(out) + "/history_" + std::to_string(s) + ".json")
            << test::HistoryGenerator(s, options).script().dump(2) << '\n';
    }
}

// The histories the generator found failing, shrunk, and fixed since: each holds the
// property it was shrunk for (its file name's last word) and every property asserted above.
TEST(FixedHistories, HoldWhatTheyOnceBroke) {
    const std::filesystem::path dir = std::filesystem::path(SWEEPERS_APP_TEST_DIR) / "../histories";
    std::size_t n = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().extension() != ".json") continue;
        ++n;
        const std::string name = entry.path().stem().string();
        const std::string property = name.substr(name.rfind('_') + 1);
        ASSERT_NE(std::find(kProperties.begin(), kProperties.end(), property), kProperties.end())
            << name;
        std::ifstream in(entry.path());
        const json history = json::parse(in);
        for (const Failure& f : HistoryCheck(history, dir.string()).run())
            EXPECT_TRUE(f.property != property && !asserted(f.property))
                << name << " breaks " << f.property << ": " << f.detail;
    }
    EXPECT_GT(n, 0u);
}

// The modeler's hands on random input (random_gestures.h): whatever the drags, keys, undos and
// cancels, the script the modeler records applies, as `sweepers-cli apply` applies it, to the
// grid the modeler shows, to the bit; every stroke undone gives back the start, and redone, the
// same grid again. A failing case is written out as its events (replayable in the window with
// --replay-input) and the script it recorded. By hand: SWEEPERS_GESTURE_HISTORIES=N.
TEST(RandomGestures, TheRecordedScriptIsWhatTheModelerSculpted) {
    const std::size_t count = envCount("SWEEPERS_GESTURE_HISTORIES", test::coarse() ? 6 : 12);
    const unsigned seed = unsigned(envCount("SWEEPERS_HISTORY_SEED", 1));
    const char* out = std::getenv("SWEEPERS_HISTORY_OUT");
    std::size_t strokes = 0;
    for (std::size_t i = 0; i < count; ++i) {
        const unsigned s = seed + unsigned(i);
        const InputReplay replay = test::GestureGenerator(s).replay();
        Document doc(Document::sphereScript(1.0 / 32), ".");
        const GridPtr start = doc.grid().deepCopy();
        SculptController ctl(/*waitEachPiece=*/true);
        ctl.setViewport(replay.width, replay.height);
        ctl.setDocument(&doc);
        ctl.frameView();
        replayEvents(ctl, replay.events);
        doc.endEdit();
        const std::string said = ctl.takeMessage();
        std::vector<std::string> failures;
        const StrokeScript recorded =
            loadStrokeScript(formatStrokeScript(doc.script()), "recorded gestures");
        if (const std::size_t d = test::differingBits(*applyScript(recorded, "."), doc.grid()))
            failures.push_back("the recorded script applies to a grid " + std::to_string(d) +
                               " voxels off");
        const GridPtr sculpted = doc.grid().deepCopy();
        std::size_t undone = 0;
        for (; doc.canUndo(); ++undone)
            doc.undo();
        if (const std::size_t d = test::differingBits(doc.grid(), *start))
            failures.push_back("undone: " + std::to_string(d) + " voxels off the start");
        for (std::size_t k = 0; k < undone; ++k)
            doc.redo();
        if (const std::size_t d = test::differingBits(doc.grid(), *sculpted))
            failures.push_back("redone: " + std::to_string(d) + " voxels off");
        strokes += recorded.strokes.size();
        std::printf("[ gestures ] seed %u: %zu events, %zu strokes recorded%s%s%s\n", s,
                    replay.events.size(), recorded.strokes.size(),
                    said.empty() ? "" : " (said: ", said.c_str(), said.empty() ? "" : ")");
        if (failures.empty()) continue;
        const std::string stem =
            std::string(out && *out ? out : ".") + "/gestures_" + std::to_string(s);
        std::ofstream(stem + "_events.json") << test::replayJson(replay).dump(1) << '\n';
        std::ofstream(stem + "_recorded.json") << formatStrokeScript(doc.script());
        for (const std::string& f : failures)
            ADD_FAILURE() << "gesture seed " << s << ": " << f << " (written to " << stem
                          << "_*.json)";
    }
    // The input must sculpt: most gestures press on the shape.
    EXPECT_GT(strokes, count);
}
