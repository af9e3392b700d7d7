// SPDX-License-Identifier: Apache-2.0
#define GL_GLEXT_PROTOTYPES
#include "app/modeler.h"

#include <GL/gl.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include "app/harness.h"
#include "core/format.h"
#include "io/mesh_file.h"
#include "io/vdb_file.h"
#include "levelset/band.h"

namespace sweepers {

namespace {

// After input, an interactive window draws this many frames (ImGui lays a new window out in
// one frame and draws it in the next), then waits for more input; it wakes this often to show
// what other threads report.
constexpr int kSettleFrames = 4;
constexpr double kIdleWakeSeconds = 0.25;

} // namespace

Modeler::Modeler(const ModelerOptions& o, GLFWwindow* w, ModelerHarness& harness)
    : harness_(harness), opt_(o), win_(w), ctl_(harness.batch() && !o.replayLive) {
    renderer_ = std::make_unique<GlRenderer>(findShaderDir(o.argv0));
    if (const auto look = parseLook(o.look)) renderer_->setLook(*look);
    ctl_.setIdle([this] { takeMesh(); });
    std::snprintf(ui_.path, sizeof ui_.path, "%s",
                  o.open.empty() ? "untitled.vdb" : o.open.c_str());
    ui_.voxelSizeInput = float(o.voxelSize);
    ui_.saveHalf = o.saveHalf;
    syncViewport();
    // Interrupted sessions are looked for before this one exists (its lock is held).
    std::vector<std::string> interrupted;
    if (!harness.batch() || !o.sessionDir.empty() || o.recover) {
        const std::string root = o.sessionDir.empty() ? defaultSessionRoot() : o.sessionDir;
        interrupted = interruptedSessions(root);
        try {
            SessionOptions so;
            so.root = root;
            so.checkpointStrokes = std::max<std::size_t>(1, o.checkpointStrokes);
            session_ = std::make_unique<Session>(so);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "sweepers: %s; strokes are not protected against a crash\n",
                         e.what());
        }
    }
    if (o.recover && interrupted.empty())
        std::fprintf(stderr, "sweepers: there is no interrupted session to recover\n");
    if (o.open.empty() || (o.recover && !interrupted.empty()))
        setDocument(std::make_unique<Document>(Document::sphereScript(o.voxelSize), "."));
    if (o.recover && !interrupted.empty()) {
        recover(interrupted.front());
    } else if (!o.open.empty()) {
        const std::string path = o.open;
        const double h = o.voxelSize;
        startJob("opening " + path, [path, h](const Progress& p, Interrupter* stop) {
            return std::make_unique<Document>(Document::open(path, h, p, stop));
        });
    }
    if (o.recover || interrupted.empty() || harness.batch()) return;
    ui_.offerRecovery = interrupted.front();
    try {
        const JournalState st = readJournal(ui_.offerRecovery);
        ui_.offerText = "Sweepers stopped without closing, " +
                        std::to_string(st.script.strokes.size()) +
                        " strokes into a document. Recover it?";
    } catch (const std::exception& e) {
        ui_.offerText = "Sweepers stopped without closing, but its session cannot be "
                        "recovered: " +
                        std::string(e.what());
    }
}

// The loop: input, the sculpting's step, the frame (scene and panels), the swap. Between
// inputs an interactive window rests; a harness run never does.
int Modeler::run() {
    while (!glfwWindowShouldClose(win_)) {
        const auto frameStart = Clock::now();
        pollInput();
        pollJob();
        if (!job_) {
            harness_.deliver(*this);
            ctl_.step();
            takeFinished();
        }
        stepFilm();
        takeSessionError();
        askBeforeQuitting();
        if (!frameDue()) continue; // the picture on screen is still right
        const auto drawStart = Clock::now();
        draw();
        PanelRequests asked = panels();
        carryOut(asked);
        harness_.afterDraw(*this, bool(job_));
        glfwSwapBuffers(win_);
        harness_.afterSwap(*this, frameStart, drawStart,
                           ctl_.drag() == DragKind::None && !ctl_.busy() && !job_);
    }
    finish();
    return 0;
}

// With nothing to show, an interactive window waits for input instead of drawing the same
// picture again (a core of software GL, or the GPU at the display's rate).
void Modeler::pollInput() {
    ui_.figures.uploadMs = 0; // this frame's uploads (a release may take a piece as well as step)
    ui_.figures.uploadedBricks = 0;
    if (framesToDraw_ > 0 || !resting())
        glfwPollEvents();
    else
        glfwWaitEventsTimeout(kIdleWakeSeconds);
    syncViewport();
}

bool Modeler::frameDue() {
    if (woken_ || !resting()) framesToDraw_ = kSettleFrames;
    woken_ = false;
    if (framesToDraw_ == 0) return false;
    --framesToDraw_;
    return true;
}

// Nothing runs or moves that a frame would show: no replay, long job, sculpting or film.
bool Modeler::resting() const {
    return !harness_.batch() && !job_ && !ctl_.busy() && ctl_.drag() == DragKind::None && !film_;
}

bool Modeler::settled() const {
    return !job_ && !ctl_.busy() && ctl_.drag() == DragKind::None &&
           (!film_ || (!film_->busy() && film_->shown() == film_->wanted()));
}

void Modeler::finish() {
    ctl_.wait();
    ctl_.step();
    doc_->endEdit();
    for (const std::string& label : ui_.clipped)
        std::fprintf(stderr, "sweepers: the panel's '%s' does not fit its width\n", label.c_str());
    harness_.finish(*this);
    // A clean end: the user saved or chose to discard (or a batch run wrote its files).
    if (session_) session_->close();
}

void Modeler::takeSessionError() {
    if (!session_) return;
    const std::string problem = session_->takeError();
    if (problem.empty()) return;
    wake();
    ui_.status = problem;
    std::fprintf(stderr, "sweepers: %s\n", problem.c_str());
}

// Closing the window with unsaved changes asks first.
void Modeler::askBeforeQuitting() {
    if (harness_.batch() || !glfwWindowShouldClose(win_) || ctl_.busy() || !doc_->modified() ||
        discard_)
        return;
    glfwSetWindowShouldClose(win_, GLFW_FALSE);
    ui_.askQuit = true;
    wake();
}

void Modeler::onButton(int button, bool press, double x, double y, bool shift, bool ctrl) {
    if (!job_) ctl_.onButton(button, press, x, y, shift, ctrl);
}

void Modeler::onMove(double x, double y) {
    if (!job_) ctl_.onMove(x, y);
}

void Modeler::onScroll(double dy, bool ctrl) {
    if (!job_) ctl_.onScroll(dy, ctrl);
}

void Modeler::onKey(int key, bool ctrl, bool shift) {
    if (job_) {
        if (key == GLFW_KEY_ESCAPE) job_->cancel();
        return;
    }
    if (!ctrl && key == 'V') {
        film_ ? closeFilm() : void(openFilm());
        return;
    }
    if (film_ && filmKey(key, ctrl)) return;
    if (ctrl && !shift && key == 'Z' && doc_->undoNeedsReplay() && !ctl_.busy() &&
        ctl_.drag() == DragKind::None) {
        undoByReplay();
        return;
    }
    if (ctl_.onKey(key, ctrl, shift) == KeyAction::Save) save(ui_.path);
}

void Modeler::dispatch(const InputEvent& e) {
    if (e.type == InputEvent::Type::Drop)
        openFile(e.path);
    else if (e.type == InputEvent::Type::Key)
        onKey(e.key, e.ctrl, e.shift);
    else
        ctl_.dispatch(e);
}

void Modeler::openFile(const std::string& path) {
    if (job_ || ctl_.busy()) return;
    const double h = doc_ ? doc_->grid().voxelSize()[0] : opt_.voxelSize;
    auto open = [this, path, h] {
        startJob("opening " + path, [path, h](const Progress& p, Interrupter* stop) {
            return std::make_unique<Document>(Document::open(path, h, p, stop));
        });
    };
    if (doc_ && doc_->modified())
        confirm("Open " + path + " and discard the unsaved changes?", open);
    else
        open();
}

void Modeler::syncViewport() {
    int w, h;
    glfwGetWindowSize(win_, &w, &h);
    ctl_.setViewport(w, h);
}

void Modeler::setDocument(std::unique_ptr<Document> doc, const Adoption& adopt) {
    closeFilm();
    ctl_.setDocument(nullptr);
    doc_ = std::move(doc);
    doc_->setUndoBudget(opt_.undoBudgetBytes);
    ctl_.setDocument(doc_.get());
    if (session_) session_->follow(*doc_, adopt);
    renderer_->update(doc_->mesher(), MeshChanges{true, {}});
    ctl_.frameView();
}

void Modeler::startJob(const std::string& what, const DocumentJob::Maker& make,
                       std::shared_ptr<Adoption> adopt, std::function<void()> then) {
    job_.emplace(what, make, std::move(adopt), std::move(then));
}

// Takes the finished job's document, or shows why there is none.
void Modeler::pollJob() {
    if (!job_ || !job_->ready()) return;
    DocumentJob job = std::move(*job_);
    job_.reset();
    std::unique_ptr<Document> doc;
    try {
        doc = job.take();
    } catch (const Cancelled&) {
        if (!doc_) throw std::runtime_error(job.what() + ": cancelled");
        ui_.status = job.what() + ": cancelled; the document was not changed";
        return;
    } catch (const std::exception& e) {
        if (!doc_) throw; // nothing to keep: the start file itself is bad
        fail(e.what());
        return;
    }
    ui_.status = job.what() + ": done";
    if (job.then()) {
        job.then()();
        return;
    }
    setDocument(std::move(doc), job.adoption() ? *job.adoption() : Adoption{});
    if (job.adoption()) {
        ui_.status = job.adoption()->report;
        std::fprintf(stderr, "sweepers: %s\n", ui_.status.c_str());
    }
}

// Undo beyond the budget: the grid before the edit is rebuilt off the render thread, from the
// session's newest checkpoint before it (or the start), then put in.
void Modeler::undoByReplay() {
    const std::size_t target = doc_->replayTarget();
    std::size_t done = 0;
    GridPtr from = session_ ? session_->checkpointAtOrBefore(target, done) : nullptr;
    auto grid = std::make_shared<GridPtr>();
    const Document* doc = doc_.get(); // not edited while a job runs
    startJob(
        "undoing by replaying " + std::to_string(target - done) + " strokes",
        [doc, from, done, grid](const Progress& p, Interrupter* stop) {
            *grid = doc->replayTo(from, done, p, stop);
            return std::unique_ptr<Document>();
        },
        nullptr,
        [this, grid] {
            doc_->undoByReplay(*grid);
            ctl_.setDocument(doc_.get()); // its volume
        });
}

// Rebuilds the document of an interrupted session off the render thread.
void Modeler::recover(const std::string& dir) {
    auto adopt = std::make_shared<Adoption>();
    startJob(
        "recovering the session " + dir,
        [dir, adopt](const Progress& p, Interrupter* stop) {
            return recoverDocument(dir, *adopt, p, stop);
        },
        adopt);
}

void Modeler::resampleTo(double h) {
    StrokeScript script = doc_->script();
    const std::string dir = doc_->scriptDir();
    doc_->endStroke();
    if (!(h >= 1e-4 && h <= 0.5)) {
        fail("the voxel size must lie between 0.0001 and 0.5");
        return;
    }
    const bool modified = doc_->modified();
    startJob("resampling to voxel size " + formatNumber(h),
             [script, dir, h, modified](const Progress& p, Interrupter* stop) {
                 auto d = std::make_unique<Document>(Document::replayAt(script, dir, h, p, stop));
                 if (modified) d->markModified();
                 return d;
             });
}

void Modeler::newSphere() {
    auto fresh = [this] {
        setDocument(
            std::make_unique<Document>(Document::sphereScript(doc_->grid().voxelSize()[0]), "."));
    };
    if (doc_->modified())
        confirm("Start a new sphere and discard the unsaved changes?", fresh);
    else
        fresh();
}

// --- the timeline: the history played as a film on a grid of its own ------------------------
Timeline* Modeler::openFilm() {
    if (film_ || !doc_ || job_ || ctl_.busy() || ctl_.drag() != DragKind::None) return film_.get();
    film_ = std::make_unique<Timeline>(*doc_);
    ctl_.setSculpting(false);
    ui_.status = "film of " + std::to_string(doc_->script().strokes.size()) +
                 " strokes: " + std::to_string(film_->frameCount()) + " frames at " +
                 formatNumber(film_->fps()) + " fps; the document is unchanged";
    return film_.get();
}

void Modeler::closeFilm() {
    if (!film_) return;
    film_.reset();
    ctl_.setSculpting(true);
    if (doc_) renderer_->update(doc_->mesher(), MeshChanges{true, {}});
}

// Keys while the film is open; false: the key is not the timeline's.
bool Modeler::filmKey(int key, bool ctrl) {
    if (ctrl) return key == 'Z'; // nothing changes the document meanwhile
    switch (key) {
    case GLFW_KEY_ESCAPE:
        closeFilm();
        return true;
    case GLFW_KEY_SPACE:
        film_->playing() ? film_->pause() : film_->play();
        return true;
    case GLFW_KEY_COMMA:
        film_->pause();
        film_->scrubTo(std::max<std::size_t>(film_->wanted(), 2) - 1);
        return true;
    case GLFW_KEY_PERIOD:
        film_->pause();
        film_->scrubTo(film_->wanted() + 1);
        return true;
    case GLFW_KEY_HOME:
        film_->pause();
        film_->scrubTo(1);
        return true;
    case GLFW_KEY_END:
        film_->pause();
        film_->scrubTo(film_->frameCount());
        return true;
    default:
        return false;
    }
}

void Modeler::stepFilm() {
    if (!film_) return;
    if (harness_.batch()) film_->wait(); // batch runs make every frame asked for
    if (film_->step()) ui_.figures.filmVolume = film_->mesher()->enclosedVolume();
    const std::string problem = film_->takeMessage();
    if (problem.empty()) return;
    if (harness_.batch()) throw std::runtime_error(problem);
    fail(problem);
    closeFilm();
}

void Modeler::saveFrame(const std::string& path) const {
    if (!film_ || !film_->grid()) throw std::runtime_error("the timeline shows no frame yet");
    if (isMeshPath(path))
        writeMesh(film_->mesher()->weld(), path);
    else
        writeLevelSet(*film_->grid(), path, savedPrecision());
}

LevelSetWriteOptions Modeler::savedPrecision() const {
    LevelSetWriteOptions options;
    options.half = ui_.saveHalf;
    return options;
}

void Modeler::confirm(const std::string& question, std::function<void()> action) {
    ui_.confirmText = question;
    ui_.confirmAction = std::move(action);
}

// Errors go to a dialog, and to stderr for whoever started the modeler.
void Modeler::fail(const std::string& message) {
    ui_.error = message;
    std::fprintf(stderr, "sweepers: %s\n", message.c_str());
}

// The document's new mesh to the GPU, and the panel's figures (only while no sculpting works
// on the document). The film shows its own mesh; closing it uploads the document's.
void Modeler::takeMesh() {
    if (!doc_ || film_) return;
    Figures& f = ui_.figures;
    const MeshChanges changes = doc_->takeMeshChanges();
    if (changes.any()) {
        const auto t0 = Clock::now();
        renderer_->update(doc_->mesher(), changes);
        f.uploadMs += 1e3 * secondsSince(t0);
        f.uploadedBricks += renderer_->uploadedBricksLastUpdate();
        groundY_ = activeWorldBox(doc_->grid()).min.y();
    }
    // Only a new mesh or a change of the undo history changes the figures (counting the
    // active voxels walks the whole tree: not at every wake of an idle window).
    if (!changes.any() && doc_->undoCount() == f.undoCount && doc_->undoBytes() == f.undoBytes)
        return;
    f.voxelSize = doc_->grid().voxelSize()[0];
    f.activeVoxels = std::size_t(doc_->grid().activeVoxelCount());
    f.triangles = doc_->mesher().triangleCount();
    f.undoCount = doc_->undoCount();
    f.undoBytes = doc_->undoBytes();
    f.gridBytes = std::size_t(doc_->grid().memUsage());
}

// Takes what the controller finished: a report to measure and show, or a message.
void Modeler::takeFinished() {
    if (auto f = ctl_.takeFinished()) {
        ui_.figures.lastSegment = f->report;
        harness_.finished(*f);
    }
    const std::string message = ctl_.takeMessage();
    if (!message.empty()) fail(message);
}

void Modeler::save(const std::string& path) {
    try {
        if (path.size() > 5 && path.substr(path.size() - 5) == ".json") {
            doc_->saveScript(path);
        } else if (isMeshPath(path)) {
            writeMesh(doc_->mesher().weld(), path);
            return; // an export does not save the document
        } else {
            doc_->saveVdb(path, savedPrecision());
        }
        doc_->markSaved();
        ui_.status = "saved " + path;
    } catch (const std::exception& e) {
        fail(e.what());
    }
}

void Modeler::draw() {
    int fw, fh;
    glfwGetFramebufferSize(win_, &fw, &fh);
    glViewport(0, 0, fw, fh);
    glClearColor(0.16f, 0.17f, 0.19f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    if (doc_) scene(fw, fh);
}

void Modeler::scene(int fw, int fh) {
    if (film_) {
        if (const SurfaceMesher* m = film_->mesher()) {
            const auto t0 = Clock::now();
            renderer_->update(*m, film_->takeMeshChanges());
            ui_.figures.uploadMs = 1e3 * secondsSince(t0);
        }
    }
    const ToolSettings& s = ctl_.settings();
    ToolOverlay tool;
    tool.radius = s.radius;
    tool.falloff = s.falloff;
    if (const auto centre = ctl_.toolCentre()) {
        tool.visible = true;
        tool.center = *centre;
        for (const glm::dvec3& p : ctl_.symmetryPreview(*centre))
            tool.lines.emplace_back(p);
    }
    if (const auto stroke = ctl_.topologyStroke())
        for (const glm::dvec3& p : strokePreview(*stroke))
            tool.lines.emplace_back(p);
    const OrbitCamera& camera = ctl_.camera();
    renderer_->draw(camera.view(), camera.projection(double(fw) / std::max(fh, 1)), s.wireframe,
                    tool, groundY_);
}

// The panels over the scene (none with --hide-ui, but a job's progress); what their clicks
// ask is carried out after the frame.
PanelRequests Modeler::panels() {
    PanelRequests asked;
    if (opt_.hideUi && !job_) return asked;
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    const bool locked = ctl_.busy() || ctl_.drag() == DragKind::Sculpt || film_;
    if (doc_ && !opt_.hideUi) mainPanel(ui_, ctl_, *renderer_, *doc_, locked, asked);
    if (film_ && !opt_.hideUi) filmPanel(ui_, *film_, asked);
    if (job_) jobPanel(*job_);
    dialogs(ui_, bool(job_), asked);
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    return asked;
}

void Modeler::carryOut(PanelRequests& asked) {
    if (asked.undo) onKey('Z', true, false);
    if (asked.redo) onKey('Z', true, true);
    if (asked.openFilm) openFilm();
    if (asked.filmKey && film_) filmKey(asked.filmKey, false);
    if (asked.closeFilm) closeFilm();
    if (asked.open) openFile(ui_.path);
    if (asked.save) save(ui_.path);
    if (asked.newSphere) newSphere();
    if (asked.resample) resampleTo(*asked.resample);
    if (asked.toolFromFile) {
        try {
            ctl_.useToolFile(ui_.path);
            ui_.status = std::string("grab and twist with ") + ui_.path;
        } catch (const std::exception& e) {
            fail(e.what());
        }
    }
    if (asked.exportFrame) {
        try {
            saveFrame(ui_.path);
            ui_.status = std::string("wrote the frame to ") + ui_.path;
        } catch (const std::exception& e) {
            fail(e.what());
        }
    }
    if (asked.saveAndQuit) {
        save(ui_.path);
        if (!doc_->modified()) glfwSetWindowShouldClose(win_, GLFW_TRUE);
    }
    if (asked.discardAndQuit) {
        discard_ = true;
        glfwSetWindowShouldClose(win_, GLFW_TRUE);
    }
    if (asked.recover) recover(ui_.offerRecovery);
    if (asked.discardSession) discardSession(ui_.offerRecovery);
    if (asked.recover || asked.discardSession) ui_.offerRecovery.clear();
    if (asked.confirmed) asked.confirmed();
}

namespace {

Modeler* modelerOf(GLFWwindow* w) {
    return static_cast<Modeler*>(glfwGetWindowUserPointer(w));
}

bool ctrlDown(GLFWwindow* w) {
    return glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS ||
           glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS;
}

bool imguiWantsMouse() {
    return ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse;
}

// GLFW callbacks; ImGui's backend chains to them, and keeps what falls on its panels.
// Any callback wakes the window (Modeler::wake), whatever ImGui keeps.
void wakeCallback(GLFWwindow* w) {
    if (Modeler* m = modelerOf(w)) m->wake();
}
void buttonCallback(GLFWwindow* w, int button, int action, int mods) {
    wakeCallback(w);
    Modeler* m = modelerOf(w);
    if (!m || imguiWantsMouse()) return;
    double x, y;
    glfwGetCursorPos(w, &x, &y);
    const int b = button == GLFW_MOUSE_BUTTON_LEFT ? 0 : button == GLFW_MOUSE_BUTTON_RIGHT ? 1 : 2;
    m->onButton(b, action == GLFW_PRESS, x, y, (mods & GLFW_MOD_SHIFT) != 0,
                (mods & GLFW_MOD_CONTROL) != 0);
}
void cursorCallback(GLFWwindow* w, double x, double y) {
    wakeCallback(w);
    if (Modeler* m = modelerOf(w)) m->onMove(x, y);
}
void scrollCallback(GLFWwindow* w, double, double dy) {
    wakeCallback(w);
    Modeler* m = modelerOf(w);
    if (!m || imguiWantsMouse()) return;
    m->onScroll(dy, ctrlDown(w));
}
void dropCallback(GLFWwindow* w, int count, const char** paths) {
    wakeCallback(w);
    Modeler* m = modelerOf(w);
    if (m && count > 0) m->openFile(paths[0]);
}
void keyCallback(GLFWwindow* w, int key, int, int action, int mods) {
    wakeCallback(w);
    Modeler* m = modelerOf(w);
    if (!m || action == GLFW_RELEASE) return;
    // Esc always reaches the modeler: it cancels long work even over a panel.
    if (key != GLFW_KEY_ESCAPE && ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureKeyboard)
        return;
    m->onKey(key, (mods & GLFW_MOD_CONTROL) != 0, (mods & GLFW_MOD_SHIFT) != 0);
}
void errorCallback(int code, const char* description) {
    std::fprintf(stderr, "sweepers: GLFW error %d: %s\n", code, description);
}

// Owns GLFW and the ImGui context for the life of the window.
struct WindowSession {
    GLFWwindow* window = nullptr;
    bool imgui = false;
    ~WindowSession() {
        if (imgui) {
            ImGui_ImplOpenGL3_Shutdown();
            ImGui_ImplGlfw_Shutdown();
            ImGui::DestroyContext();
        }
        if (window) glfwDestroyWindow(window);
        glfwTerminate();
    }
};

} // namespace

int runModeler(const ModelerOptions& o) {
    if (!o.recordFrames.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(o.recordFrames, ec);
        if (ec || !std::filesystem::is_directory(o.recordFrames))
            throw std::runtime_error(o.recordFrames + ": cannot make the directory for the frames" +
                                     (ec ? ": " + ec.message() : ""));
    }
    glfwSetErrorCallback(errorCallback);
    if (!glfwInit())
        throw std::runtime_error(
            "cannot open a window (no display?); sweepers-cli works without one");
    WindowSession session;
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    // 4x multisampling, except on a software rasterizer (llvmpipe without a GPU), where it
    // costs more than half of every frame: the window is then made again without it.
    auto open = [&](int samples) {
        glfwWindowHint(GLFW_SAMPLES, samples);
        GLFWwindow* w = glfwCreateWindow(o.width, o.height, "Sweepers", nullptr, nullptr);
        if (!w) throw std::runtime_error("cannot create an OpenGL 3.3 core window");
        glfwMakeContextCurrent(w);
        return w;
    };
    session.window = open(4);
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    if (renderer && (std::strstr(renderer, "llvmpipe") || std::strstr(renderer, "softpipe"))) {
        glfwDestroyWindow(session.window);
        session.window = nullptr;
        session.window = open(0);
    }
    GLFWwindow* w = session.window;
    glfwSwapInterval(o.replayInput.empty() && o.screenshot.empty() ? 1 : 0);
    glfwSetMouseButtonCallback(w, buttonCallback);
    glfwSetCursorPosCallback(w, cursorCallback);
    glfwSetScrollCallback(w, scrollCallback);
    glfwSetKeyCallback(w, keyCallback);
    glfwSetDropCallback(w, dropCallback);
    // What only ImGui or the window itself reads wakes the window too (ImGui chains to these).
    glfwSetCharCallback(w, [](GLFWwindow* win, unsigned) { wakeCallback(win); });
    glfwSetCursorEnterCallback(w, [](GLFWwindow* win, int) { wakeCallback(win); });
    glfwSetWindowFocusCallback(w, [](GLFWwindow* win, int) { wakeCallback(win); });
    glfwSetWindowRefreshCallback(w, wakeCallback);
    glfwSetWindowCloseCallback(w, wakeCallback);
    glfwSetFramebufferSizeCallback(w, [](GLFWwindow* win, int, int) { wakeCallback(win); });
    glfwSetWindowIconifyCallback(w, [](GLFWwindow* win, int) { wakeCallback(win); });
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    session.imgui = true;
    ImGui::GetIO().IniFilename = nullptr;
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(w, true); // chains to the callbacks above
    ImGui_ImplOpenGL3_Init("#version 330 core");
    ModelerHarness harness(o);
    Modeler m(o, w, harness);
    glfwSetWindowUserPointer(w, &m);
    const int code = m.run();
    glfwSetWindowUserPointer(w, nullptr);
    return code;
}

} // namespace sweepers
