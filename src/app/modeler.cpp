// SPDX-License-Identifier: Apache-2.0
#define GL_GLEXT_PROTOTYPES
#include "app/modeler.h"

#include <GL/gl.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <stdexcept>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <stb_image_write.h>

#include "app/gl_renderer.h"
#include "app/input_replay.h"
#include "app/sculpt_controller.h"
#include "app/session.h"
#include "app/timeline.h"
#include "core/format.h"
#include "core/statistics.h"
#include "core/stopwatch.h"
#include "document/document.h"
#include "io/atomic_file.h"
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

// The panel's width when it first opens; every label must fit in it (mustFit).
constexpr float kPanelWidth = 380.0f;
// The voxel sizes the panel offers as levels of detail (1/N).
constexpr int kDetailLevels[] = {64, 128, 256, 512};
// A mesh's bytes per triangle: three indices, and about half a vertex's position and normal.
constexpr double kMeshBytesPerTriangle = 3 * 4 + 0.5 * 24;

// "1/128" where the voxel size is one over a whole number, else the number.
std::string detailName(double h) {
    const double n = std::round(1.0 / h);
    if (h > 0 && std::abs(1.0 / n - h) < 1e-9 * h) return "1/" + std::to_string(int(n));
    return formatNumber(h);
}

// The window, its drawing and panels, and long jobs (open, import, resample) off the
// render thread. What input does to the document and the camera is the controller's.
class Modeler {
  public:
    Modeler(const ModelerOptions& o, GLFWwindow* w)
        : batch_(!o.replayInput.empty() || !o.screenshot.empty() || !o.recordFrames.empty()),
          ctl_(batch_ && !o.replayLive), opt_(o), win_(w) {
        renderer_ = std::make_unique<GlRenderer>(findShaderDir(o.argv0));
        if (const auto look = parseLook(o.look)) renderer_->setLook(*look);
        ctl_.setIdle([this] { takeMesh(); });
        std::snprintf(path_, sizeof path_, "%s", o.open.empty() ? "untitled.vdb" : o.open.c_str());
        voxelSizeInput_ = float(o.voxelSize);
        syncViewport();
        // Interrupted sessions are looked for before this one exists (its lock is held).
        std::vector<std::string> interrupted;
        if (!batch_ || !o.sessionDir.empty() || o.recover) {
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
        if (o.recover && !interrupted.empty()) {
            setDocument(std::make_unique<Document>(Document::sphereScript(o.voxelSize), "."));
            recover(interrupted.front());
        } else if (o.open.empty()) {
            setDocument(std::make_unique<Document>(Document::sphereScript(o.voxelSize), "."));
        } else {
            const std::string path = o.open;
            const double h = o.voxelSize;
            startJob("opening " + path, [path, h](const Progress& p, Interrupter* stop) {
                return std::make_unique<Document>(Document::open(path, h, p, stop));
            });
        }
        if (!o.recover && !interrupted.empty() && !batch_) {
            offerRecovery_ = interrupted.front();
            try {
                const JournalState st = readJournal(offerRecovery_);
                offerText_ = "Sweepers stopped without closing, " +
                             std::to_string(st.script.strokes.size()) +
                             " strokes into a document. Recover it?";
            } catch (const std::exception& e) {
                offerText_ = "Sweepers stopped without closing, but its session cannot be "
                             "recovered: " +
                             std::string(e.what());
            }
        }
    }

    int run() {
        // Replayed events count frames in which no long job runs, as a user waits for one.
        ReplayClock replay(opt_.replay.events);
        while (!glfwWindowShouldClose(win_)) {
            const auto t0 = Clock::now();
            uploadMs_ = 0; // this frame's uploads (a release may take a piece as well as step)
            uploadedBricks_ = 0;
            // With nothing to show, an interactive window waits for input instead of drawing
            // the same picture again (a core of software GL, or the GPU at the display's rate).
            if (framesToDraw_ > 0 || !resting())
                glfwPollEvents();
            else
                glfwWaitEventsTimeout(kIdleWakeSeconds);
            syncViewport();
            pollJob();
            if (!job_) {
                replay.deliver(ctl_, [this](const InputEvent& e) { dispatch(e); });
                ctl_.step();
                takeFinished();
            }
            stepFilm();
            if (session_) {
                const std::string problem = session_->takeError();
                if (!problem.empty()) {
                    wake();
                    status_ = problem;
                    std::fprintf(stderr, "sweepers: %s\n", problem.c_str());
                }
            }
            if (!batch_ && glfwWindowShouldClose(win_) && !ctl_.busy() && doc_->modified() &&
                !discard_) {
                glfwSetWindowShouldClose(win_, GLFW_FALSE); // ask first
                askQuit_ = true;
                wake();
            }
            if (woken_ || !resting()) framesToDraw_ = kSettleFrames;
            woken_ = false;
            if (framesToDraw_ == 0) continue; // the picture on screen is still right
            --framesToDraw_;
            const auto drawStart = Clock::now();
            draw();
            if (batch_ && !job_ && !ctl_.busy() && ctl_.drag() == DragKind::None && replay.over() &&
                filmSettled())
                batchStep();
            if (!job_) replay.endFrame(ctl_);
            glfwSwapBuffers(win_);
            if (measuring_) {
                // Latency of the segment: from its drag event to the new mesh on screen.
                glFinish();
                const auto now = Clock::now();
                const SegmentReport& r = finished_.report;
                latencies_.push_back(
                    {1e3 * r.advectSeconds(), 1e3 * r.stats.renormalizeSeconds, 1e3 * r.meshSeconds,
                     uploadMs_, 1e3 * secondsSince(drawStart, now),
                     1e3 * secondsSince(finished_.since, now), double(uploadedBricks_)});
                measuring_ = false;
            }
            frameMs_ = 1e3 * secondsSince(t0);
            if (ctl_.drag() == DragKind::None && !ctl_.busy() && !job_)
                idleFrames_.push_back(frameMs_);
        }
        ctl_.wait();
        ctl_.step();
        doc_->endEdit();
        for (const std::string& label : clipped_)
            std::fprintf(stderr, "sweepers: the panel's '%s' does not fit its width\n",
                         label.c_str());
        if (opt_.latencyReport) reportLatency();
        if (!opt_.latencyCsv.empty()) writeLatencyCsv(opt_.latencyCsv);
        if (!opt_.saveVdb.empty()) doc_->saveVdb(opt_.saveVdb);
        if (!opt_.saveScript.empty()) doc_->saveScript(opt_.saveScript);
        if (!opt_.saveFrame.empty()) {
            if (!film_ || !film_->grid())
                throw std::runtime_error("--save-frame: the timeline shows no frame");
            saveFrame(opt_.saveFrame);
        }
        // A clean end: the user saved or chose to discard (or a batch run wrote its files).
        if (session_) session_->close();
        return 0;
    }

    // Input or a change of the window (any of GLFW's callbacks): frames are drawn again.
    void wake() { woken_ = true; }
    // Nothing runs or moves that a frame would show: no replay, long job, sculpting or film.
    bool resting() const {
        return !batch_ && !job_ && !ctl_.busy() && ctl_.drag() == DragKind::None && !film_;
    }

    // --- input from GLFW's callbacks (ImGui keeps what falls on its panels) -------------
    void onButton(int button, bool press, double x, double y, bool shift, bool ctrl) {
        if (!job_) ctl_.onButton(button, press, x, y, shift, ctrl);
    }
    void onMove(double x, double y) {
        if (!job_) ctl_.onMove(x, y);
    }
    void onScroll(double dy, bool ctrl) {
        if (!job_) ctl_.onScroll(dy, ctrl);
    }
    void onKey(int key, bool ctrl, bool shift) {
        if (job_) {
            if (key == GLFW_KEY_ESCAPE) job_->stop->interrupt();
            return;
        }
        if (!ctrl && key == 'V') {
            film_ ? closeFilm() : openFilm();
            return;
        }
        if (film_ && filmKey(key, ctrl)) return;
        if (ctrl && !shift && key == 'Z' && doc_->undoNeedsReplay() && !ctl_.busy() &&
            ctl_.drag() == DragKind::None) {
            undoByReplay();
            return;
        }
        if (ctl_.onKey(key, ctrl, shift) == KeyAction::Save) save(path_);
    }

    // Opens a file (dropped on the window, or the Open button) off the render thread; a
    // file that cannot be opened leaves the current document as it was. Unsaved changes
    // are not dropped without asking.
    void openFile(const std::string& path) {
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

  private:
    void syncViewport() {
        int w, h;
        glfwGetWindowSize(win_, &w, &h);
        ctl_.setViewport(w, h);
    }

    void setDocument(std::unique_ptr<Document> doc, const Adoption& adopt = {}) {
        closeFilm();
        ctl_.setDocument(nullptr);
        doc_ = std::move(doc);
        doc_->setUndoBudget(opt_.undoBudgetBytes);
        ctl_.setDocument(doc_.get());
        if (session_) session_->follow(*doc_, adopt);
        renderer_->update(doc_->mesher(), MeshChanges{true, {}});
        ctl_.frameView();
    }

    using Maker = std::function<std::unique_ptr<Document>(const Progress&, Interrupter*)>;
    // `then`: for a job that changes the current document rather than making a new one (its
    // maker returns null), what to do with the document when it is done.
    void startJob(const std::string& what, const Maker& make,
                  std::shared_ptr<Adoption> adopt = nullptr, std::function<void()> then = {}) {
        auto done = std::make_shared<std::atomic<std::size_t>>(0);
        auto total = std::make_shared<std::atomic<std::size_t>>(0);
        auto stop = std::make_shared<FlagInterrupter>();
        Progress progress = [done, total](std::size_t d, std::size_t t) {
            *done = d;
            *total = t;
        };
        job_.emplace(Job{std::async(std::launch::async,
                                    [make, progress, stop] { return make(progress, stop.get()); }),
                         done, total, stop, what, std::move(adopt), std::move(then)});
    }

    // Undo beyond the budget: the grid before the edit is rebuilt off the render thread,
    // from the session's newest checkpoint before it (or the start), then put in.
    void undoByReplay() {
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
    void recover(const std::string& dir) {
        auto adopt = std::make_shared<Adoption>();
        startJob(
            "recovering the session " + dir,
            [dir, adopt](const Progress& p, Interrupter* stop) {
                return recoverDocument(dir, *adopt, p, stop);
            },
            adopt);
    }

    // Takes the finished job's document, or shows why there is none.
    void pollJob() {
        if (!job_ || job_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
            return;
        Job job = std::move(*job_);
        job_.reset();
        std::unique_ptr<Document> doc;
        try {
            doc = job.result.get();
        } catch (const Cancelled&) {
            if (!doc_) throw std::runtime_error(job.what + ": cancelled");
            status_ = job.what + ": cancelled; the document was not changed";
            return;
        } catch (const std::exception& e) {
            if (!doc_) throw; // nothing to keep: the start file itself is bad
            fail(e.what());
            return;
        }
        status_ = job.what + ": done";
        if (job.then) {
            job.then();
            return;
        }
        setDocument(std::move(doc), job.adopt ? *job.adopt : Adoption{});
        if (job.adopt) {
            status_ = job.adopt->report;
            std::fprintf(stderr, "sweepers: %s\n", status_.c_str());
        }
    }

    // --- the timeline: the history played as a film on a grid of its own -------------
    void openFilm() {
        if (film_ || !doc_ || job_ || ctl_.busy() || ctl_.drag() != DragKind::None) return;
        film_ = std::make_unique<Timeline>(*doc_);
        ctl_.setSculpting(false);
        status_ = "film of " + std::to_string(doc_->script().strokes.size()) +
                  " strokes: " + std::to_string(film_->frameCount()) + " frames at " +
                  formatNumber(film_->fps()) + " fps; the document is unchanged";
    }

    void closeFilm() {
        if (!film_) return;
        film_.reset();
        ctl_.setSculpting(true);
        if (doc_) renderer_->update(doc_->mesher(), MeshChanges{true, {}});
    }

    // Keys while the film is open; false: the key is not the timeline's.
    bool filmKey(int key, bool ctrl) {
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

    void stepFilm() {
        if (!film_) return;
        if (batch_) film_->wait(); // batch runs make every frame asked for
        if (film_->step()) filmVolume_ = film_->mesher()->enclosedVolume();
        const std::string problem = film_->takeMessage();
        if (problem.empty()) return;
        if (batch_) throw std::runtime_error(problem);
        fail(problem);
        closeFilm();
    }

    bool filmSettled() const {
        return !film_ || (!film_->busy() && film_->shown() == film_->wanted());
    }

    void saveFrame(const std::string& path) {
        if (!film_ || !film_->grid()) throw std::runtime_error("the timeline shows no frame yet");
        if (isMeshPath(path))
            writeMesh(film_->mesher()->weld(), path);
        else
            writeLevelSet(*film_->grid(), path);
    }

    // A batch run with nothing left to replay: records the film's frames one by one (each
    // drawn before it is read back), takes the screenshot, and closes the window.
    void batchStep() {
        if (!opt_.recordFrames.empty() && recordNext_ == 0) {
            openFilm();
            if (!film_) throw std::runtime_error("--record-frames: the film cannot be opened");
            recordNext_ = 1;
            film_->scrubTo(1);
            return;
        }
        if (recordNext_ != 0 && recordNext_ <= film_->frameCount()) {
            const std::size_t count = film_->frameCount();
            const int digits = std::max(4, int(std::to_string(count).size()));
            char name[32];
            std::snprintf(name, sizeof name, "frame_%0*zu.png", digits, recordNext_);
            screenshot((std::filesystem::path(opt_.recordFrames) / name).string());
            if (++recordNext_ <= count) {
                film_->scrubTo(recordNext_);
                return;
            }
            std::fprintf(stderr, "sweepers: wrote %zu frames to %s\n", count,
                         opt_.recordFrames.c_str());
        }
        if (!opt_.screenshot.empty()) screenshot(opt_.screenshot);
        glfwSetWindowShouldClose(win_, GLFW_TRUE);
    }

    void filmPanel() {
        const ImVec2 size = ImGui::GetIO().DisplaySize;
        ImGui::SetNextWindowPos(ImVec2(size.x * 0.5f, size.y - 10.0f), ImGuiCond_Always,
                                ImVec2(0.5f, 1.0f));
        ImGui::SetNextWindowSize(ImVec2(std::min(size.x - 20.0f, 720.0f), 0.0f), ImGuiCond_Always);
        ImGui::Begin("Film of the history (V)", nullptr,
                     ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoResize);
        Timeline& f = *film_;
        int frame = int(f.wanted());
        ImGui::SetNextItemWidth(-1.0f);
        if (ImGui::SliderInt("##frame", &frame, 1, int(f.frameCount()), "frame %d")) {
            f.pause();
            f.scrubTo(std::size_t(frame));
        }
        if (ImGui::Button(f.playing() ? "Pause (space)" : "Play (space)"))
            filmKey(GLFW_KEY_SPACE, false);
        ImGui::SameLine();
        if (ImGui::Button("|< Home")) filmKey(GLFW_KEY_HOME, false);
        ImGui::SameLine();
        if (ImGui::Button("< ,")) filmKey(GLFW_KEY_COMMA, false);
        ImGui::SameLine();
        if (ImGui::Button(". >")) filmKey(GLFW_KEY_PERIOD, false);
        ImGui::SameLine();
        if (ImGui::Button("End >|")) filmKey(GLFW_KEY_END, false);
        ImGui::SameLine();
        static const float speeds[] = {0.25f, 0.5f, 1.0f, 2.0f, 4.0f};
        int speed = 2;
        for (int k = 0; k < 5; ++k)
            if (double(speeds[k]) == f.speed()) speed = k;
        ImGui::SetNextItemWidth(90.0f);
        if (ImGui::Combo("speed", &speed,
                         "0.25x\0"
                         "0.5x\0"
                         "1x\0"
                         "2x\0"
                         "4x\0"))
            f.setSpeed(speeds[speed]);
        ImGui::Text("frame %zu of %zu, %.2f of %.2f s, volume %.5f%s", f.shown(), f.frameCount(),
                    filmFrameTime(std::max<std::size_t>(f.shown(), 1), f.seconds(), f.fps()),
                    f.seconds(), filmVolume_, f.busy() ? "  (making a frame...)" : "");
        ImGui::BeginDisabled(f.busy() || !f.grid());
        if (ImGui::Button("Export this frame")) {
            try {
                saveFrame(path_);
                status_ = std::string("wrote the frame to ") + path_;
            } catch (const std::exception& e) {
                fail(e.what());
            }
        }
        ImGui::EndDisabled();
        ImGui::SameLine();
        ImGui::TextDisabled("to the file in the panel (.vdb or a mesh)");
        ImGui::SameLine();
        if (ImGui::Button("Close (V)")) closeFilm();
        ImGui::End();
    }

    void confirm(const std::string& question, std::function<void()> action) {
        confirmText_ = question;
        confirmAction_ = std::move(action);
    }

    // Errors go to a dialog, and to stderr for whoever started the modeler.
    void fail(const std::string& message) {
        error_ = message;
        std::fprintf(stderr, "sweepers: %s\n", message.c_str());
    }

    void dispatch(const InputEvent& e) {
        if (e.type == InputEvent::Type::Drop)
            openFile(e.path);
        else if (e.type == InputEvent::Type::Key)
            onKey(e.key, e.ctrl, e.shift);
        else
            ctl_.dispatch(e);
    }

    // The document's new mesh to the GPU, and the panel's figures (only while no sculpting
    // works on the document). The film shows its own mesh; closing it uploads the document's.
    void takeMesh() {
        if (!doc_ || film_) return;
        const MeshChanges changes = doc_->takeMeshChanges();
        if (changes.any()) {
            const auto t0 = Clock::now();
            renderer_->update(doc_->mesher(), changes);
            uploadMs_ += 1e3 * secondsSince(t0);
            uploadedBricks_ += renderer_->uploadedBricksLastUpdate();
            groundY_ = activeWorldBox(doc_->grid()).min.y();
        }
        // Only a new mesh or a change of the undo history changes the figures (counting the
        // active voxels walks the whole tree: not at every wake of an idle window).
        if (changes.any() || doc_->undoCount() != info_.undoCount ||
            doc_->undoBytes() != info_.undoBytes)
            info_ = {doc_->grid().voxelSize()[0],
                     std::size_t(doc_->grid().activeVoxelCount()),
                     doc_->mesher().triangleCount(),
                     doc_->undoCount(),
                     doc_->undoBytes(),
                     std::size_t(doc_->grid().memUsage())};
    }

    // Takes what the controller finished: a report to measure, or a message to show.
    void takeFinished() {
        if (auto f = ctl_.takeFinished()) {
            finished_ = *f;
            measuring_ = true;
        }
        const std::string message = ctl_.takeMessage();
        if (!message.empty()) fail(message);
    }

    void reportLatency() const {
        static const char* names[] = {"advect", "renorm", "mesh", "upload", "draw", "total"};
        if (latencies_.empty()) {
            // Zeros would read as a measurement.
            std::fprintf(stderr, "latency: nothing was sculpted, so there is nothing to report "
                                 "(did the drags reach the shape?)\n");
        } else {
            std::fprintf(stderr, "latency over %zu segments at voxel size %g (ms, p50 / p95):",
                         latencies_.size(), doc_->grid().voxelSize()[0]);
            for (int k = 0; k < 6; ++k) {
                std::vector<double> v;
                for (const auto& l : latencies_)
                    v.push_back(l[k]);
                std::fprintf(stderr, " %s %.1f / %.1f%s", names[k], percentile(v, 0.5),
                             percentile(v, 0.95), k < 5 ? "," : "\n");
            }
        }
        if (!idleFrames_.empty())
            std::fprintf(stderr, "frame time when not sculpting (ms, p50 over %zu frames): %.1f\n",
                         idleFrames_.size(), percentile(idleFrames_, 0.5));
    }

    void writeLatencyCsv(const std::string& path) const {
        std::string text = "advect,renorm,mesh,upload,draw,total,bricks\n";
        char row[256];
        for (const auto& l : latencies_) {
            std::snprintf(row, sizeof row, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.0f\n", l[0], l[1], l[2],
                          l[3], l[4], l[5], l[6]);
            text += row;
        }
        writeTextAtomically(path, text);
    }

    void save(const std::string& path) {
        try {
            if (path.size() > 5 && path.substr(path.size() - 5) == ".json") {
                doc_->saveScript(path);
            } else if (isMeshPath(path)) {
                writeMesh(doc_->mesher().weld(), path);
                return; // an export does not save the document
            } else {
                doc_->saveVdb(path);
            }
            doc_->markSaved();
            status_ = "saved " + path;
        } catch (const std::exception& e) {
            fail(e.what());
        }
    }

    void scene(int fw, int fh) {
        if (film_) {
            if (const SurfaceMesher* m = film_->mesher()) {
                const auto t0 = Clock::now();
                renderer_->update(*m, film_->takeMeshChanges());
                uploadMs_ = 1e3 * secondsSince(t0);
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

    void draw() {
        int fw, fh;
        glfwGetFramebufferSize(win_, &fw, &fh);
        glViewport(0, 0, fw, fh);
        glClearColor(0.16f, 0.17f, 0.19f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        if (doc_) scene(fw, fh);
        if (!opt_.hideUi || job_) panels();
    }

    void panels() {
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        if (doc_ && !opt_.hideUi) mainPanel();
        if (film_ && !opt_.hideUi) filmPanel();
        if (job_) {
            const ImVec2 size = ImGui::GetIO().DisplaySize;
            ImGui::SetNextWindowPos(ImVec2(size.x * 0.5f, size.y * 0.5f), ImGuiCond_Always,
                                    ImVec2(0.5f, 0.5f));
            ImGui::Begin("Working", nullptr,
                         ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoCollapse);
            const std::size_t d = *job_->done, t = *job_->total;
            ImGui::Text("%s", job_->what.c_str());
            char label[64];
            std::snprintf(label, sizeof label, "segment %zu / %zu", d, t);
            ImGui::ProgressBar(t ? float(d) / float(t) : 0.0f, ImVec2(320, 0), label);
            if (ImGui::Button("Cancel (Esc)")) job_->stop->interrupt();
            ImGui::End();
        }
        popups();
        ImGui::Render();
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    }

    // An item whose right edge passes the panel's: its label is cut off. Reported once at
    // exit, so that a test of the window at its default size sees it.
    void mustFit(const char* what) {
        const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
        if (ImGui::GetItemRectMax().x > right + 0.5f) clipped_.insert(what);
    }

    // The memory a document of this shape needs at voxel size h: its band and its mesh both
    // grow with the surface's area in voxels, so the figures now scale as (h_now / h)^2.
    double memoryAtVoxelSize(double h) const {
        const double now = info_.voxelSize > 0 ? info_.voxelSize : h;
        const double bytes = double(info_.gridBytes) + kMeshBytesPerTriangle * info_.triangles;
        return bytes * (now / h) * (now / h);
    }

    void resampleTo(double h) {
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
                     auto d =
                         std::make_unique<Document>(Document::replayAt(script, dir, h, p, stop));
                     if (modified) d->markModified();
                     return d;
                 });
    }

    void mainPanel() {
        ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowSize(ImVec2(kPanelWidth, 0), ImGuiCond_FirstUseEver);
        ImGui::Begin("Sweepers");
        // Sliders and fields leave room for the longest label beside them.
        const ImGuiStyle& style = ImGui::GetStyle();
        ImGui::PushItemWidth(-(ImGui::CalcTextSize("falloff  shift [ ]").x +
                               style.ItemInnerSpacing.x + style.WindowPadding.x * 0.5f));
        ImGui::Text("Tool");
        ToolSettings& s = ctl_.settings();
        const bool sculpting = ctl_.drag() == DragKind::Sculpt;
        ImGui::BeginDisabled(sculpting);
        int m = int(s.mode);
        const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
        for (std::size_t k = 0; k < kModes.size(); ++k) {
            // As many to a row as fit the panel's width: the sweeps first, then swirl,
            // fluid and clay, then the topology tools.
            if (k != 0) {
                const float width = ImGui::GetFrameHeight() + style.ItemInnerSpacing.x +
                                    ImGui::CalcTextSize(kModes[k].label).x;
                ImGui::SameLine();
                if (ImGui::GetCursorScreenPos().x + width > right) ImGui::NewLine();
            }
            ImGui::RadioButton(kModes[k].label, &m, int(kModes[k].mode));
            mustFit(kModes[k].label);
        }
        s.mode = SculptMode(m);
        ImGui::EndDisabled();
        if (s.mode == SculptMode::Pinch)
            ImGui::TextWrapped("Drag from the surface: the hole goes through along the view, "
                               "the drag sets its radius; release to pinch.");
        else if (s.mode == SculptMode::Strangle)
            ImGui::TextWrapped("Drag across a limb: the drag sets the circle's radius, the "
                               "radius below the gap; release to strangle.");
        if (s.bakedTool) {
            ImGui::Text("tool: %s", s.bakedSource.file.c_str());
            ImGui::SameLine();
            if (ImGui::Button("Ball")) ctl_.useBall();
        }
        float r = float(s.radius), f = float(s.falloff);
        if (ImGui::SliderFloat("radius  [ ]", &r, 0.02f, 1.0f, "%.3f",
                               ImGuiSliderFlags_Logarithmic))
            s.radius = r;
        mustFit("radius  [ ]");
        if (ImGui::SliderFloat("falloff  shift [ ]", &f, 0.02f, 1.0f, "%.3f",
                               ImGuiSliderFlags_Logarithmic))
            s.falloff = f;
        mustFit("falloff  shift [ ]");
        float strength = float(s.strength);
        if (ImGui::SliderFloat("strength  shift F", &strength, 0.01f, 1.0f, "%.2f"))
            s.strength = std::clamp(double(strength), 0.01, 1.0);
        mustFit("strength  shift F");
        // Smoothing's own strength (Shift-drag uses it whatever the tool): past 1 it reaches
        // the form, not only the noise.
        float smooth = float(s.smoothStrength);
        if (ImGui::SliderFloat("smooth strength", &smooth, 0.1f, float(kMostSmoothStrength), "%.2f",
                               ImGuiSliderFlags_Logarithmic))
            s.smoothStrength = std::clamp(double(smooth), 0.01, kMostSmoothStrength);
        mustFit("smooth strength");
        int mirror = int(s.mirror);
        ImGui::Combo("mirror (M)", &mirror, "none\0x\0y\0z\0");
        mustFit("mirror (M)");
        s.mirror = MirrorAxis(mirror);
        ImGui::SliderInt("radial", &s.radialCount, 1, 64);
        mustFit("radial");
        if (s.radialCount > 1) {
            ImGui::Combo("radial axis", &s.radialAxis, "x\0y\0z\0");
            mustFit("radial axis");
        }
        if (ctl_.sizing() != Sizing::None)
            ImGui::TextWrapped("Move the mouse to set the %s; click to keep it, Esc to put it "
                               "back.",
                               ctl_.sizing() == Sizing::Radius ? "radius" : "strength");
        ImGui::Checkbox("wireframe (W)", &s.wireframe);
        // The surface's look: clay, or a matcap that reads form without lights.
        int look = int(renderer_->look());
        ImGui::Combo("look", &look, "clay\0glossy\0red wax\0normals\0");
        mustFit("look");
        renderer_->setLook(kSurfaceLooks[std::clamp(look, 0, 3)]);
        // Nothing that changes the document while a drag is being sculpted, or while the
        // film of its history plays.
        ImGui::BeginDisabled(ctl_.busy() || sculpting || film_);
        if (ImGui::Button("Undo")) onKey('Z', true, false);
        ImGui::SameLine();
        if (ImGui::Button("Redo")) onKey('Z', true, true);
        ImGui::SameLine();
        if (ImGui::Button("Film of the history (V)")) openFilm();
        mustFit("Film of the history (V)");
        ImGui::Separator();
        ImGui::InputText("file", path_, sizeof path_);
        if (ImGui::Button("Open")) openFile(path_);
        ImGui::SameLine();
        if (ImGui::Button("Tool from file")) {
            try {
                ctl_.useToolFile(path_);
                status_ = std::string("grab and twist with ") + path_;
            } catch (const std::exception& e) {
                fail(e.what());
            }
        }
        ImGui::SameLine();
        if (ImGui::Button("Save")) save(path_);
        ImGui::SameLine();
        if (ImGui::Button("New sphere")) {
            auto fresh = [this] {
                setDocument(std::make_unique<Document>(
                    Document::sphereScript(doc_->grid().voxelSize()[0]), "."));
            };
            if (doc_->modified())
                confirm("Start a new sphere and discard the unsaved changes?", fresh);
            else
                fresh();
        }
        mustFit("New sphere");
        ImGui::TextWrapped("Open reads .vdb and .json, imports .obj/.ply/.stl; Save writes "
                           ".vdb, the stroke script for .json, a mesh for .obj/.ply/.stl.");
        // Detail: the history replayed at a finer or coarser voxel size, offered at the sizes
        // artists pick from, each with what it would cost for this shape, or at any size.
        ImGui::Separator();
        char current[64];
        std::snprintf(current, sizeof current, "%s (now)", detailName(info_.voxelSize).c_str());
        if (ImGui::BeginCombo("detail", current)) {
            for (const int n : kDetailLevels) {
                const double h = 1.0 / n;
                const std::string item = "1/" + std::to_string(n) + "  (about " +
                                         formatBytes(memoryAtVoxelSize(h)) + ")";
                const bool now = std::abs(h - info_.voxelSize) < 1e-9 * h;
                if (ImGui::Selectable(item.c_str(), now) && !now) {
                    voxelSizeInput_ = float(h);
                    resampleTo(h);
                }
            }
            ImGui::EndCombo();
        }
        mustFit("detail");
        ImGui::InputFloat("voxel size", &voxelSizeInput_, 0.0f, 0.0f, "%.6f");
        mustFit("voxel size");
        if (ImGui::Button("Resample at this voxel size")) resampleTo(voxelSizeInput_);
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("Replay the history at this voxel size");
        mustFit("Resample at this voxel size");
        ImGui::EndDisabled();
        if (!status_.empty()) ImGui::TextWrapped("%s", status_.c_str());
        // The engine's figures: for whoever wants them, out of an artist's way.
        if (ImGui::CollapsingHeader("Statistics")) {
            ImGui::Text("voxel size %.5g, active voxels %zu", info_.voxelSize, info_.activeVoxels);
            ImGui::Text("triangles %zu, volume %.5f", info_.triangles, ctl_.volume());
            ImGui::Text("frame %.1f ms, upload %.1f ms", frameMs_, uploadMs_);
            const SegmentReport& last = finished_.report;
            ImGui::Text("last segment: advect %.1f, renorm %.1f,", 1e3 * last.advectSeconds(),
                        1e3 * last.stats.renormalizeSeconds);
            ImGui::Text("  mesh %.1f ms", 1e3 * last.meshSeconds);
            ImGui::Text("undo: %zu edits in %.1f of %.0f MB,", info_.undoCount,
                        double(info_.undoBytes) / (1 << 20),
                        double(doc_->undoBudget()) / (1 << 20));
            ImGui::Text("  %zu more by replay", doc_->droppedCount());
        }
        ImGui::PopItemWidth();
        ImGui::End();
    }

    void popups() {
        if (!error_.empty()) ImGui::OpenPopup("Error");
        if (ImGui::BeginPopupModal("Error", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
            ImGui::TextWrapped("%s", error_.c_str());
            ImGui::Text("The document was not changed.");
            if (ImGui::Button("OK")) {
                error_.clear();
                ImGui::CloseCurrentPopup();
            }
            ImGui::EndPopup();
        }
        if (askQuit_) ImGui::OpenPopup("Unsaved changes");
        if (ImGui::BeginPopupModal("Unsaved changes", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
            ImGui::Text("Save before quitting? (file: %s)", path_);
            if (ImGui::Button("Save and quit")) {
                save(path_);
                if (!doc_->modified()) glfwSetWindowShouldClose(win_, GLFW_TRUE);
                askQuit_ = false;
                ImGui::CloseCurrentPopup();
            }
            ImGui::SameLine();
            if (ImGui::Button("Discard")) {
                discard_ = true;
                glfwSetWindowShouldClose(win_, GLFW_TRUE);
                askQuit_ = false;
                ImGui::CloseCurrentPopup();
            }
            ImGui::SameLine();
            if (ImGui::Button("Cancel")) {
                askQuit_ = false;
                ImGui::CloseCurrentPopup();
            }
            ImGui::EndPopup();
        }
        if (!offerRecovery_.empty() && !job_) ImGui::OpenPopup("Recover");
        if (ImGui::BeginPopupModal("Recover", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
            ImGui::TextWrapped("%s", offerText_.c_str());
            ImGui::TextDisabled("%s", offerRecovery_.c_str());
            if (ImGui::Button("Recover")) {
                recover(offerRecovery_);
                offerRecovery_.clear();
                ImGui::CloseCurrentPopup();
            }
            ImGui::SameLine();
            if (ImGui::Button("Discard it")) {
                discardSession(offerRecovery_);
                offerRecovery_.clear();
                ImGui::CloseCurrentPopup();
            }
            ImGui::SameLine();
            if (ImGui::Button("Ask again next time")) {
                offerRecovery_.clear();
                ImGui::CloseCurrentPopup();
            }
            ImGui::EndPopup();
        }
        if (!confirmText_.empty()) ImGui::OpenPopup("Confirm");
        if (ImGui::BeginPopupModal("Confirm", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
            ImGui::Text("%s", confirmText_.c_str());
            if (ImGui::Button("Yes")) {
                auto action = std::move(confirmAction_);
                confirmText_.clear();
                ImGui::CloseCurrentPopup();
                action();
            }
            ImGui::SameLine();
            if (ImGui::Button("Cancel")) {
                confirmText_.clear();
                ImGui::CloseCurrentPopup();
            }
            ImGui::EndPopup();
        }
    }

    void screenshot(const std::string& path) {
        int fw, fh;
        glfwGetFramebufferSize(win_, &fw, &fh);
        std::vector<unsigned char> px(std::size_t(fw) * fh * 3);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadBuffer(GL_BACK);
        glReadPixels(0, 0, fw, fh, GL_RGB, GL_UNSIGNED_BYTE, px.data());
        stbi_flip_vertically_on_write(1);
        // Encoded into the checked atomic save, like every other file we write.
        writeFileAtomically(path, [&](std::ostream& out) {
            const auto put = [](void* stream, void* data, int size) {
                static_cast<std::ostream*>(stream)->write(static_cast<const char*>(data), size);
            };
            if (!stbi_write_png_to_func(put, &out, fw, fh, 3, px.data(), fw * 3))
                throw std::runtime_error(path + ": cannot encode the screenshot");
        });
    }

    struct Job {
        std::future<std::unique_ptr<Document>> result;
        std::shared_ptr<std::atomic<std::size_t>> done, total;
        std::shared_ptr<FlagInterrupter> stop; // Esc or the Cancel button
        std::string what;
        std::shared_ptr<Adoption> adopt; // a recovery: what the session takes over
        std::function<void()> then;      // see startJob
    };
    bool batch_ = false;
    SculptController ctl_;
    ModelerOptions opt_;
    GLFWwindow* win_;
    std::optional<Job> job_;
    std::unique_ptr<Session> session_; // declared before doc_: it outlives the document
    std::unique_ptr<Document> doc_;
    std::unique_ptr<GlRenderer> renderer_;
    std::unique_ptr<Timeline> film_; // open: the window shows its frame, not the document
    double filmVolume_ = 0.0;
    std::size_t recordNext_ = 0; // --record-frames: the next frame to write (0: not begun)
    std::string offerRecovery_, offerText_; // an interrupted session the user has not
                                            // decided about, and what the offer says
    double groundY_ = -1.0;
    struct Info {
        double voxelSize = 0;
        std::size_t activeVoxels = 0, triangles = 0, undoCount = 0, undoBytes = 0, gridBytes = 0;
    } info_;
    std::set<std::string> clipped_; // panel items cut off at the window's width
    std::string confirmText_;
    std::function<void()> confirmAction_;
    float voxelSizeInput_ = 1.0f / 64;
    bool askQuit_ = false, discard_ = false;
    SculptController::Finished finished_;
    bool measuring_ = false;
    bool woken_ = true;    // input since the last frame (and at the start)
    int framesToDraw_ = 0; // before the window waits for input
    // Per piece: advect, renorm, mesh, upload, draw (+ swap, finish) and total, in ms, and
    // how many mesh bricks its frame uploaded.
    std::vector<std::array<double, 7>> latencies_;
    std::vector<double> idleFrames_;
    double frameMs_ = 0, uploadMs_ = 0;
    std::size_t uploadedBricks_ = 0;
    char path_[1024] = {};
    std::string error_, status_;
};

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
    Modeler m(o, w);
    glfwSetWindowUserPointer(w, &m);
    const int code = m.run();
    glfwSetWindowUserPointer(w, nullptr);
    return code;
}

} // namespace sweepers
