// SPDX-License-Identifier: Apache-2.0
// The interactive modeler: a GLFW window over a Document, sculpted with the mouse.
#pragma once

#include <cstddef>
#include <string>

#include "app/input_replay.h"

namespace sweepers {

struct ModelerOptions {
    std::string open; // a .vdb or a stroke script (.json); empty: a unit sphere
    double voxelSize = 1.0 / 64;
    int width = 1280, height = 800;
    std::string screenshot;  // render, write this PNG and exit (after the replay, if any)
    std::string replayInput; // events to replay; the window closes after the last one
    InputReplay replay;      // ... as read from that file
    bool replayLive = false; // replay at frame pace, not waiting for the sculpting
    std::string saveVdb;     // written when the window closes (for tests and batch use)
    std::string saveScript;  // the recorded stroke script, written when the window closes
    // The history played as a film (the timeline): one PNG per frame written here
    // (frame_0001.png, ...), after the replay if any, then the window closes.
    std::string recordFrames;
    std::string saveFrame;      // the frame the timeline shows, written when the window closes
    bool hideUi = false;        // no panels (clean screenshots)
    std::string look = "clay";  // how the surface looks at first (SurfaceLook's names)
    bool latencyReport = false; // print per-segment latency by stage when the window closes
    std::string latencyCsv;     // ... and write every segment's figures here (ms)
    // Crash safety (app/session.h): where sessions are kept (empty: the default place, and
    // no session at all for batch runs: replays and screenshots); recover the newest
    // interrupted session without asking; a checkpoint every this many strokes.
    std::string sessionDir;
    bool recover = false;
    std::size_t checkpointStrokes = 20;
    // Memory for undo blocks; older edits are undone by replay.
    std::size_t undoBudgetBytes = std::size_t(512) << 20;
    std::string argv0;
};

// Runs until the window closes; returns the process exit code. Errors before the window
// opens (bad file, no display) are thrown as std::runtime_error.
int runModeler(const ModelerOptions& options);

} // namespace sweepers
