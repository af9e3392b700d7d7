// SPDX-License-Identifier: Apache-2.0
// sweepers: the interactive modeler.
#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "app/input_replay.h"
#include "app/modeler.h"
#include "core/install_paths.h"
#include "core/limits.h"
#include "core/memory.h"
#include "io/stroke_script.h"

namespace {

// What the command line sets: the modeler's options and what is turned into them.
struct CommandLine {
    sweepers::ModelerOptions options;
    std::string script, size;
    int threads = 0;
    double undoMb = 512;
    // As sweepers-cli's: a stroke past them is refused, its message in the status line.
    double maxMemoryGb = 0.0, maxWork = 0.0;
};

void addOptions(CLI::App& app, CommandLine& c) {
    app.set_version_flag("--version", "sweepers " SWEEPERS_VERSION);
    const sweepers::ProgramPlaces places = sweepers::programPlaces();
    app.footer("Examples: " + places.examples + " (sweepers " + places.examples +
               "/horn.json)\nGuides: " + places.guides +
               "/README.md and docs/ beside it (modeler.md for every key)");
    app.add_option("file", c.options.open, "a .vdb level set or a stroke script (.json) to open");
    app.add_option("--script", c.script, "a stroke script to open (same as giving it as file)");
    app.add_option("--voxel-size", c.options.voxelSize, "voxel size of a new sphere")
        ->check(CLI::PositiveNumber);
    app.add_option("--size", c.size,
                   "window size WIDTHxHEIGHT (default 1280x800, or the window a replay file "
                   "names)");
    app.add_option("--screenshot", c.options.screenshot, "render one frame to this PNG and exit");
    app.add_option("--replay-input", c.options.replayInput,
                   "replay recorded mouse and keyboard events (JSON), then exit");
    app.add_option("--save", c.options.saveVdb, "write the level set here when the window closes");
    app.add_flag("--half", c.options.saveHalf,
                 "save level sets (--save, --save-frame, the Save button) with 16-bit float "
                 "values: files a third smaller");
    app.add_option("--save-script", c.options.saveScript,
                   "write the recorded stroke script here when the window closes");
    app.add_flag("--replay-live", c.options.replayLive,
                 "replay at frame pace, not waiting for the sculpting (events are coalesced as "
                 "when a user drags)");
    app.add_option("--record-frames", c.options.recordFrames,
                   "play the history as a film (24 fps, a quarter second per path segment) and "
                   "write each frame as DIR/frame_0001.png ..., then exit");
    app.add_option("--save-frame", c.options.saveFrame,
                   "write the frame the timeline shows (.vdb, or a mesh) when the window closes");
    app.add_flag("--hide-ui", c.options.hideUi, "draw no panels");
    app.add_option("--look", c.options.look,
                   "how the surface looks: clay (lit, the default) or a matcap: glossy, "
                   "red-wax, normals")
        ->check(CLI::IsMember({"clay", "glossy", "red-wax", "normals"}));
    app.add_flag("--latency-report", c.options.latencyReport,
                 "print stroke latency (drag event to mesh on screen) by stage at exit");
    app.add_option("--latency-csv", c.options.latencyCsv,
                   "write every segment's latency by stage (ms) to this CSV at exit");
    app.add_option("--session-dir", c.options.sessionDir,
                   "where sessions are kept for crash recovery (default "
                   "$XDG_STATE_HOME/sweepers/sessions; replays and screenshots keep none "
                   "unless this is given)");
    app.add_flag("--recover", c.options.recover,
                 "rebuild the document of the last session that ended in a crash, without "
                 "asking");
    app.add_option("--checkpoint-every", c.options.checkpointStrokes,
                   "save a checkpoint of the grid every N strokes (default 20)")
        ->check(CLI::Range(1, 1000000));
    app.add_option("--undo-budget", c.undoMb,
                   "memory kept for undo, in MB (default 512); older edits are undone by "
                   "replaying the history from a checkpoint")
        ->check(CLI::Range(0.0, 1e7));
    app.add_option("--threads", c.threads, "worker threads (default: all cores)")
        ->check(CLI::Range(1, 1024));
    app.add_option("--max-memory", c.maxMemoryGb,
                   "refuse a stroke estimated to need more memory, in GB (default: half the "
                   "memory available)")
        ->check(CLI::PositiveNumber);
    app.add_option("--max-work", c.maxWork,
                   "refuse a stroke estimated to take more voxel updates (default 2e9)")
        ->check(CLI::PositiveNumber);
}

// --size WIDTHxHEIGHT.
void takeSize(CommandLine& c) {
    sweepers::ModelerOptions& o = c.options;
    const std::string& size = c.size;
    if (size.empty()) return;
    int w = 0, h = 0;
    char x = 0, extra = 0;
    using sweepers::kLargestWindow, sweepers::kSmallestWindow;
    if (std::sscanf(size.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' ||
        std::min(w, h) < kSmallestWindow || std::max(w, h) > kLargestWindow)
        throw std::runtime_error("--size wants WIDTHxHEIGHT between " +
                                 std::to_string(kSmallestWindow) + " and " +
                                 std::to_string(kLargestWindow) + ", like 800x600");
    o.width = w;
    o.height = h;
}

// --replay-input, read before the window opens: its clicks belong to the window it names.
void takeReplay(CommandLine& c) {
    sweepers::ModelerOptions& o = c.options;
    if (o.replayInput.empty()) return;
    o.replay = sweepers::readInputReplay(o.replayInput);
    const int w = o.replay.width, h = o.replay.height;
    if (w > 0 && c.size.empty()) {
        o.width = w;
        o.height = h;
    } else if (w > 0 && (w != o.width || h != o.height)) {
        std::fprintf(stderr,
                     "sweepers: %s was recorded in a %dx%d window; in this %dx%d one "
                     "its clicks land elsewhere\n",
                     o.replayInput.c_str(), w, h, o.width, o.height);
    }
}

} // namespace

static int run(int argc, char** argv) {
    CommandLine c;
    c.options.argv0 = argv[0];
    CLI::App app{"Sweepers: sculpt a level set with swept space deformations"};
    addOptions(app, c);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // As sweepers-cli: --help and --version are not errors, anything else is a usage
        // error (exit 2).
        return app.exit(e) == 0 ? 0 : 2;
    }
    sweepers::ModelerOptions& o = c.options;
    o.undoBudgetBytes = std::size_t(c.undoMb * 1024 * 1024);
    sweepers::setLimits({c.maxMemoryGb * 1e9, c.maxWork});
    try {
        if (!c.script.empty()) {
            if (!o.open.empty()) throw std::runtime_error("give either a file or --script");
            o.open = c.script;
        }
        takeSize(c);
        takeReplay(c);
        std::unique_ptr<tbb::global_control> limit;
        if (c.threads > 0)
            limit = std::make_unique<tbb::global_control>(
                tbb::global_control::max_allowed_parallelism, c.threads);
        return sweepers::runModeler(o);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "sweepers: %s\n", e.what());
        return 1;
    }
}

int main(int argc, char** argv) {
    sweepers::keepFreedMemory();
    // What run does not catch itself (running out of memory while setting up).
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "sweepers: %s\n", e.what());
        return 1;
    }
}
