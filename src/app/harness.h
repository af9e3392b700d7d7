// SPDX-License-Identifier: Apache-2.0
// The modeler driven from outside, for tests and batch use (ModelerOptions names each part):
// replayed input, the film's frames recorded one by one, a screenshot, the files written when
// the window closes, and the latency of every sculpted segment from its drag event to its
// mesh on screen, by stage. The window calls it at fixed points of its loop; nothing of it
// is in the window's own state.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "app/modeler.h"

namespace sweepers {

class ModelerHarness {
  public:
    explicit ModelerHarness(const ModelerOptions& options);

    // Whether the window runs by itself (a replay, a screenshot or recorded frames) and
    // closes when it is done.
    bool batch() const { return batch_; }

    // Before the frame's step, when no job runs: the replayed events due.
    void deliver(Modeler& m);
    // A finished piece of sculpting: measured when the frame that shows its mesh is on screen.
    void finished(const SculptController::Finished& piece) { measuring_ = piece; }
    // After the frame is drawn, before the swap: with nothing left to replay, the film's
    // frames are recorded, the screenshot taken and the window closed; the replay's frame ends.
    void afterDraw(Modeler& m, bool working);
    // After the swap: the latency of the segment this frame shows, the frame's time.
    void afterSwap(Modeler& m, Clock::time_point frameStart, Clock::time_point drawStart,
                   bool idle);
    // When the window has closed: the reports and the files asked for.
    void finish(Modeler& m) const;

  private:
    void batchStep(Modeler& m);
    void reportLatency(const Modeler& m) const;
    void writeLatencyCsv(const std::string& path) const;

    const ModelerOptions& opt_;
    bool batch_;
    ReplayClock replay_;
    std::size_t recordNext_ = 0; // --record-frames: the next frame to write (0: not begun)
    std::optional<SculptController::Finished> measuring_;
    // Per segment: advect, renorm, mesh, upload, draw (+ swap, finish) and total, in ms, and
    // how many mesh bricks its frame uploaded.
    std::vector<std::array<double, 7>> latencies_;
    std::vector<double> idleFrames_;
};

// The frame in the back buffer, written as a PNG.
void screenshot(GLFWwindow* window, const std::string& path);

} // namespace sweepers
