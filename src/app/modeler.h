// SPDX-License-Identifier: Apache-2.0
// The interactive modeler: a GLFW window over a Document, sculpted with the mouse. Its loop
// (Modeler::run) polls input, steps the sculpting, draws the scene and the panels
// (app/panels.h) and swaps; long work runs as a job (app/job.h); what input does to the
// document and the camera is the sculpt controller's (app/sculpt_controller.h); tests and
// batch runs drive it from outside (app/harness.h).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "app/gl_renderer.h"
#include "app/input_replay.h"
#include "app/job.h"
#include "app/panels.h"
#include "app/sculpt_controller.h"
#include "app/session.h"
#include "app/timeline.h"
#include "core/stopwatch.h"
#include "document/document.h"

struct GLFWwindow;

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
    bool saveHalf = false;   // level sets saved with 16-bit float values (the panel's box)
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

class ModelerHarness;

class Modeler {
  public:
    Modeler(const ModelerOptions& options, GLFWwindow* window, ModelerHarness& harness);
    // Until the window closes: poll, step, draw, swap. Returns the process exit code.
    int run();

    // Input or a change of the window (any of GLFW's callbacks): frames are drawn again.
    void wake() { woken_ = true; }
    // Input from GLFW's callbacks (ImGui keeps what falls on its panels), or replayed.
    void onButton(int button, bool press, double x, double y, bool shift, bool ctrl);
    void onMove(double x, double y);
    void onScroll(double dy, bool ctrl);
    void onKey(int key, bool ctrl, bool shift);
    void dispatch(const InputEvent& e);
    // Opens a file (dropped on the window, or the Open button) off the render thread; a file
    // that cannot be opened leaves the current document as it was. Unsaved changes are not
    // dropped without asking.
    void openFile(const std::string& path);

    // What the harness reads and drives.
    GLFWwindow* window() const { return win_; }
    SculptController& controller() { return ctl_; }
    const Document& document() const { return *doc_; }
    Document& document() { return *doc_; }
    Figures& figures() { return ui_.figures; }
    // Nothing left to do before the next input: no job, no sculpting, the film's frame made.
    bool settled() const;
    // The timeline open (or null after a failure to open it).
    Timeline* openFilm();
    // The film's frame as a level set (.vdb) or a mesh.
    void saveFrame(const std::string& path) const;
    // How Save writes level sets: the panel's "half floats" box (first set by --half).
    LevelSetWriteOptions savedPrecision() const;

  private:
    void syncViewport();
    void pollInput();
    void setDocument(std::unique_ptr<Document> doc, const Adoption& adopt = {});
    void startJob(const std::string& what, const DocumentJob::Maker& make,
                  std::shared_ptr<Adoption> adopt = nullptr, std::function<void()> then = {});
    void pollJob();
    void undoByReplay();
    void recover(const std::string& dir);
    void resampleTo(double h);
    void newSphere();
    void closeFilm();
    bool filmKey(int key, bool ctrl);
    void stepFilm();
    void takeMesh();
    void takeFinished();
    void takeSessionError();
    void askBeforeQuitting();
    bool frameDue();
    bool resting() const;
    void confirm(const std::string& question, std::function<void()> action);
    void fail(const std::string& message);
    void save(const std::string& path);
    void draw();
    void scene(int fw, int fh);
    PanelRequests panels();
    void carryOut(PanelRequests& asked);
    void finish();

    ModelerHarness& harness_;
    const ModelerOptions& opt_;
    GLFWwindow* win_;
    SculptController ctl_;
    std::unique_ptr<GlRenderer> renderer_;
    std::unique_ptr<Session> session_; // declared before doc_: it outlives the document
    std::unique_ptr<Document> doc_;
    std::optional<DocumentJob> job_;
    std::unique_ptr<Timeline> film_; // open: the window shows its frame, not the document
    PanelState ui_;
    double groundY_ = -1.0;
    bool discard_ = false; // the user chose to quit without saving
    bool woken_ = true;    // input since the last frame (and at the start)
    int framesToDraw_ = 0; // before the window waits for input
};

// Runs until the window closes; returns the process exit code. Errors before the window
// opens (bad file, no display) are thrown as std::runtime_error.
int runModeler(const ModelerOptions& options);

} // namespace sweepers
