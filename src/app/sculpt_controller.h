// SPDX-License-Identifier: Apache-2.0
// The modeler's input logic without a window: mouse, key and wheel events in (window
// pixels, origin top left), camera moves and sculpting out. A drag on the shape is its tool's
// gesture (app/gestures.h), and each piece of sculpting (a sweep segment, a swirl ring, a
// dab of clay, a dab of smoothing) runs on a worker thread while the window keeps drawing;
// moves that arrive meanwhile coalesce into the next piece. The modeler feeds it GLFW's
// events; tests feed it replay files and read the recorded script, with no window at all.
#pragma once

#include <array>
#include <chrono>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "app/camera.h"
#include "app/gestures.h"
#include "app/input_replay.h"
#include "app/tool_settings.h"
#include "core/stopwatch.h"
#include "document/document.h"
#include "levelset/interrupt.h"

namespace sweepers {

enum class DragKind { None, Sculpt, Orbit, Pan };

// What a key asks of the window beyond the controller's own state.
enum class KeyAction { None, Save, Cancel };

class SculptController {
  public:
    // waitEachPiece: every piece of sculpting is finished, on the caller's thread, before the
    // next event is taken (replays and tests: deterministic); otherwise pieces run on a
    // worker thread and events coalesce while one runs.
    explicit SculptController(bool waitEachPiece = false) : waitEach_(waitEachPiece) {}
    ~SculptController() { wait(); }

    // The document sculpted (not owned); no work may be running when it changes.
    void setDocument(Document* doc);
    Document* document() const { return doc_; }
    // The window's size in the pixels events are given in.
    void setViewport(int width, int height);

    // --- events -----------------------------------------------------------------------
    // button: 0 left, 1 right, 2 middle. Shift with the left button smooths whatever the
    // tool; Ctrl inverts the tool (inflate deflates, twist turns back, grab and swirl pull
    // the other way, clay takes away).
    void onButton(int button, bool press, double x, double y, bool shift, bool ctrl = false);
    void onMove(double x, double y);
    void onScroll(double dy, bool ctrl);
    KeyAction onKey(int key, bool ctrl, bool shift);
    // A replayed event (all but drops, which open files: the window's job).
    void dispatch(const InputEvent& e);

    // Once per frame (and at a drag's release): takes finished work and starts the next
    // piece of a drag.
    void step();
    // Called by step() between taking finished work and starting the next piece, when no
    // work runs and the document may be read: the window takes the mesh of the piece just
    // finished there (during a drag the next piece starts at once, and the mesher is the
    // worker's again until it ends).
    void setIdle(std::function<void()> idle) { idle_ = std::move(idle); }
    // Replays take the next frame's events only when this is true (see waitEachPiece).
    bool readyForEvents() const { return !busy() || !waitEach_; }
    bool busy() const { return work_.valid(); }
    void wait() const {
        if (work_.valid()) work_.wait();
    }
    // Asks the running piece to stop: the document goes back to before the drag.
    void cancel() { stop_.interrupt(); }

    // --- what the window shows --------------------------------------------------------
    OrbitCamera& camera() { return camera_; }
    const OrbitCamera& camera() const { return camera_; }
    ToolSettings& settings() { return settings_; }
    const ToolSettings& settings() const { return settings_; }
    DragKind drag() const { return drag_; }
    // F or Shift-F in progress: what the mouse sets, and where its circle is drawn.
    Sizing sizing() const { return sizing_ ? sizing_->what() : Sizing::None; }
    // Where the tool is drawn: during a drag its current placement, else under the cursor.
    std::optional<glm::dvec3> toolCentre() const;
    // The surface point under a window pixel.
    std::optional<glm::dvec3> pick(double x, double y) const;
    // Line segments (pairs of ends) that show the symmetry around the tool at `centre`: a
    // circle of the tool's radius, facing the view, at each radial and mirror copy.
    std::vector<glm::dvec3> symmetryPreview(const glm::dvec3& centre) const;
    // During a pinch or strangle drag: the stroke the release will apply, as it stands.
    std::optional<Stroke> topologyStroke() const;
    // Grab and twist with the shape of a .vdb level set or a closed mesh (a mesh is sampled
    // at the document's voxel size); throws saying why a file cannot be a tool.
    void useToolFile(const std::string& path);
    // Back to the ball.
    void useBall();
    // Off: a left drag turns the view wherever it starts and no tool is drawn (the
    // modeler's timeline shows another grid than the document's).
    void setSculpting(bool on) { sculpting_ = on; }
    // Looks at the whole shape.
    void frameView();
    double volume() const { return volume_; }

    // A finished piece of sculpting: its report and when its first event arrived.
    struct Finished {
        SegmentReport report;
        Clock::time_point since;
    };
    std::optional<Finished> takeFinished() { return std::exchange(finished_, std::nullopt); }
    // A message for the user (a failed or cancelled piece), once.
    std::string takeMessage() { return std::exchange(message_, std::string()); }

  private:
    // What the drag's gesture may use: tools() to read, working() to launch pieces too.
    GestureTools tools() const;
    GestureTools working();
    void launch(std::function<SegmentReport()> task);
    void collect();
    // The radial symmetry the panel sets (about an axis through the origin).
    RadialSymmetry radial() const;
    void pressOnShape(bool smooth, bool ctrl, const glm::dvec3& at);
    void finishDrag();
    void stopDrag(); // without finishing: the drag ends where it failed

    Document* doc_ = nullptr;
    bool waitEach_ = false, sculpting_ = true;
    std::function<void()> idle_;
    int width_ = 1, height_ = 1;
    OrbitCamera camera_;
    ToolSettings settings_;
    DragKind drag_ = DragKind::None;
    std::unique_ptr<Gesture> gesture_; // of the sculpting drag in progress
    std::optional<ToolSizing> sizing_; // F or Shift-F in progress
    // A move not yet sculpted (and since when), the release waiting for the last piece.
    bool pending_ = false, releasing_ = false;
    double lastX_ = 0, lastY_ = 0, cursorX_ = -1, cursorY_ = -1;
    Clock::time_point pendingSince_, workSince_;
    std::future<SegmentReport> work_;
    FlagInterrupter stop_;
    std::optional<Finished> finished_;
    std::string message_;
    double volume_ = 0.0;
};

// What the modeler draws of a pinch or a strangle before it is applied, as line segments
// (pairs of ends): the needles from their start to where they meet and the circle of the
// hole; the strangling circle, its axis and the gap. Empty for other strokes.
std::vector<glm::dvec3> strokePreview(const Stroke& stroke);

// Hands recorded events over frame by frame, as the modeler's loop and replayEvents both do:
// a frame's events go out only when the controller takes events (see waitEachPiece), and
// the frame count moves on only then, so a replay waits for each piece of sculpting.
class ReplayClock {
  public:
    explicit ReplayClock(std::vector<InputEvent> events);
    // Before the frame's step: its events, one by one, to `dispatch`.
    void deliver(const SculptController& controller,
                 const std::function<void(const InputEvent&)>& dispatch);
    // After the frame's step.
    void endFrame(const SculptController& controller);
    // Every event delivered, and a frame more.
    bool over() const { return frame_ >= lastFrame_; }
    // Frames past the end (a drag never released keeps a replay going).
    int overtime() const { return frame_ - lastFrame_; }

  private:
    std::vector<InputEvent> events_;
    std::size_t next_ = 0;
    int frame_ = 0, lastFrame_ = 1;
};

// Replays events through a controller without a window, frame by frame as the modeler
// does (events of a frame, then one step; drops are skipped), until every piece is done.
void replayEvents(SculptController& controller, const std::vector<InputEvent>& events);

} // namespace sweepers
