#define GL_GLEXT_PROTOTYPES
#include "app/modeler.h"

#include <GL/gl.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <stdexcept>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <stb_image_write.h>

#include "app/camera.h"
#include "app/document.h"
#include "app/gl_renderer.h"
#include "app/input_replay.h"
#include "io/mesh_file.h"
#include "levelset/level_set.h"
#include "levelset/raycast.h"

namespace sweepers {

namespace {

// Grab, twist and inflate are sweeps (one segment per frame); swirl moves clay while
// keeping its volume (one swirl ring per frame, 4.1); clay adds material (Decaudin's
// inflation, 2.30) under the cursor.
enum class Mode { Grab, Twist, Inflate, Swirl, Clay };
enum class Drag { None, Sculpt, Orbit, Pan };

glm::dvec3 toGlm(const Eigen::Vector3d& v) {
    return {v.x(), v.y(), v.z()};
}
Eigen::Vector3d toEigen3(const glm::dvec3& v) {
    return {v.x, v.y, v.z};
}

class Modeler {
  public:
    Modeler(const ModelerOptions& o, GLFWwindow* w)
        : batch_(!o.replayInput.empty() || !o.screenshot.empty()), opt_(o), win_(w) {
        renderer_ = std::make_unique<GlRenderer>(findShaderDir(o.argv0));
        std::snprintf(path_, sizeof path_, "%s", o.open.empty() ? "untitled.vdb" : o.open.c_str());
        voxelSizeInput_ = float(o.voxelSize);
        if (o.open.empty()) {
            doc_ = std::make_unique<Document>(Document::sphereScript(o.voxelSize), ".");
            frame();
        } else {
            const std::string path = o.open;
            const double h = o.voxelSize;
            startJob("opening " + path, [path, h](const Progress& p) {
                return std::make_unique<Document>(Document::open(path, h, p));
            });
        }
    }

    int run() {
        std::vector<InputEvent> events;
        if (!opt_.replayInput.empty()) events = readInputEvents(opt_.replayInput);
        const bool batch = batch_;
        const int lastFrame = events.empty() ? 1 : events.back().frame + 2;
        std::size_t next = 0;
        // Replayed events count frames in which no long job runs, as a user waits for one.
        int eventFrame = 0;
        while (!glfwWindowShouldClose(win_)) {
            const auto t0 = Clock::now();
            glfwPollEvents();
            pollJob();
            if (!job_) {
                if (!busy() || opt_.replayLive)
                    for (; next < events.size() && events[next].frame == eventFrame; ++next)
                        dispatch(events[next]);
                step();
            }
            const auto drawStart = Clock::now();
            draw();
            if (batch && !job_ && !busy() && drag_ == Drag::None && eventFrame >= lastFrame) {
                if (!opt_.screenshot.empty()) screenshot(opt_.screenshot);
                glfwSetWindowShouldClose(win_, GLFW_TRUE);
            }
            if (!job_ && (!busy() || opt_.replayLive)) ++eventFrame;
            glfwSwapBuffers(win_);
            if (measuring_) {
                // Latency of the segment: from its drag event to the new mesh on screen.
                glFinish();
                const auto now = Clock::now();
                latencies_.push_back(
                    {1e3 * (report_.stats.growSeconds + report_.stats.sampleSeconds),
                     1e3 * report_.stats.renormalizeSeconds, 1e3 * report_.meshSeconds, uploadMs_,
                     1e3 * std::chrono::duration<double>(now - drawStart).count(),
                     1e3 * std::chrono::duration<double>(now - pendingSince_).count()});
                measuring_ = false;
            }
            frameMs_ = 1e3 * std::chrono::duration<double>(Clock::now() - t0).count();
            if (drag_ == Drag::None && !busy() && !job_) idleFrames_.push_back(frameMs_);
            if (!batch && glfwWindowShouldClose(win_) && !busy() && doc_->modified() && !discard_) {
                glfwSetWindowShouldClose(win_, GLFW_FALSE); // ask first
                askQuit_ = true;
            }
        }
        if (busy()) work_.wait();
        collect();
        doc_->endEdit();
        if (opt_.latencyReport) reportLatency();
        if (!opt_.saveVdb.empty()) doc_->saveVdb(opt_.saveVdb);
        if (!opt_.saveScript.empty()) doc_->saveScript(opt_.saveScript);
        return 0;
    }

    // --- input, from GLFW callbacks or a replay -------------------------------------
    void onButton(int button, bool press, double x, double y, bool shift) {
        if (job_ || !doc_) return; // the document is being replaced
        cursorX_ = x;
        cursorY_ = y;
        if (!press) {
            if (drag_ == Drag::Sculpt) {
                // The last position counts; the drag ends once its work is done.
                pending_ = true;
                releasing_ = true;
                step();
            } else {
                drag_ = Drag::None;
            }
            return;
        }
        if (busy() || drag_ == Drag::Sculpt) return;
        pressX_ = lastX_ = x;
        pressY_ = lastY_ = y;
        if (button == 1 || button == 2 || (button == 0 && shift)) {
            drag_ = Drag::Pan;
            return;
        }
        const auto hit = pick(x, y);
        if (!hit) {
            drag_ = Drag::Orbit;
            return;
        }
        grab_ = *hit;
        axis_ = glm::normalize(camera_.eye() - camera_.target);
        last_ = placementAt(x, y);
        drag_ = Drag::Sculpt;
        pending_ = false;
        if (mode_ == Mode::Swirl || mode_ == Mode::Clay) {
            doc_->beginEdit();
            if (mode_ == Mode::Clay) {
                pendingSince_ = Clock::now();
                cursorX_ = x;
                cursorY_ = y;
                dab(grab_);
            }
            return;
        }
        ToolSpec tool;
        tool.shape = "ball";
        tool.size = Eigen::Vector3d::Constant(radius_);
        tool.falloff = falloff_;
        tool.path = {last_};
        doc_->beginStroke(tool, mirror_);
    }

    // Clay mode: one inflation of the tool's radius (2.30) centred half a radius under the
    // surface point p (along the view ray), so that it adds the whole ball (a centre inside
    // the material gives the inserted ball its sign).
    void dab(const glm::dvec3& p) {
        const glm::dvec3 in = p + 0.5 * radius_ * glm::normalize(p - camera_.eye());
        const InflateStroke stroke{toEigen3(in), radius_};
        Document* doc = doc_.get();
        launch([doc, stroke] { return doc->applyStroke(stroke); });
        lastDab_ = p;
        dabX_ = cursorX_;
        dabY_ = cursorY_;
    }

    void onMove(double x, double y) {
        const double dx = x - lastX_, dy = y - lastY_;
        cursorX_ = x;
        cursorY_ = y;
        int w, h;
        glfwGetWindowSize(win_, &w, &h);
        switch (drag_) {
        case Drag::Orbit:
            camera_.orbit(-dx * 0.008, dy * 0.008);
            break;
        case Drag::Pan:
            camera_.pan(dx / h, dy / h);
            break;
        case Drag::Sculpt:
            // Coalesced: one segment per frame, at the latest position; its latency counts
            // from the first event it absorbs.
            if (!pending_) pendingSince_ = Clock::now();
            pending_ = true;
            break;
        case Drag::None:
            break;
        }
        lastX_ = x;
        lastY_ = y;
    }

    void onScroll(double dy, bool ctrl) {
        if (ctrl)
            radius_ = std::clamp(radius_ * std::pow(1.1, dy), 0.02, 2.0);
        else
            camera_.zoom(std::pow(0.9, dy));
    }

    void onKey(int key, bool ctrl, bool shift) {
        if (job_ || !doc_) return;
        if (ctrl && busy()) return; // undo and save wait for the sculpting to finish
        if (ctrl && key == 'Z') {
            shift ? doc_->redo() : doc_->undo();
            volume_ = doc_->mesher().enclosedVolume();
        } else if (ctrl && key == 'S') {
            save(path_);
        } else if (!ctrl && !(drag_ == Drag::Sculpt && std::isalpha(key))) {
            switch (key) {
            case 'G':
                mode_ = Mode::Grab;
                break;
            case 'T':
                mode_ = Mode::Twist;
                break;
            case 'S':
                mode_ = Mode::Swirl;
                break;
            case 'C':
                mode_ = Mode::Clay;
                break;
            case 'I':
                mode_ = Mode::Inflate;
                break;
            case 'F':
                if (!busy()) frame();
                break;
            case 'W':
                wireframe_ = !wireframe_;
                break;
            case 'M':
                mirror_ = MirrorAxis((int(mirror_) + 1) % 4);
                break;
            case '[': // with shift: the falloff
                (shift ? falloff_ : radius_) = std::max(0.02, (shift ? falloff_ : radius_) / 1.1);
                break;
            case ']':
                (shift ? falloff_ : radius_) = std::min(2.0, (shift ? falloff_ : radius_) * 1.1);
                break;
            case GLFW_KEY_LEFT:
                camera_.orbit(-0.1, 0);
                break;
            case GLFW_KEY_RIGHT:
                camera_.orbit(0.1, 0);
                break;
            case GLFW_KEY_UP:
                camera_.orbit(0, 0.1);
                break;
            case GLFW_KEY_DOWN:
                camera_.orbit(0, -0.1);
                break;
            case GLFW_KEY_EQUAL:
                camera_.zoom(0.9);
                break;
            case GLFW_KEY_MINUS:
                camera_.zoom(1.0 / 0.9);
                break;
            default:
                break;
            }
        }
    }

    // Opens a file (dropped on the window, or the Open button) off the render thread; a
    // file that cannot be opened leaves the current document as it was. Unsaved changes
    // are not dropped without asking.
    void openFile(const std::string& path) {
        if (job_ || busy()) return;
        const double h = doc_ ? doc_->grid().voxelSize()[0] : opt_.voxelSize;
        auto open = [this, path, h] {
            startJob("opening " + path, [path, h](const Progress& p) {
                return std::make_unique<Document>(Document::open(path, h, p));
            });
        };
        if (doc_ && doc_->modified())
            confirm("Open " + path + " and discard the unsaved changes?", open);
        else
            open();
    }

  private:
    using Maker = std::function<std::unique_ptr<Document>(const Progress&)>;
    void startJob(const std::string& what, Maker make) {
        auto done = std::make_shared<std::atomic<std::size_t>>(0);
        auto total = std::make_shared<std::atomic<std::size_t>>(0);
        Progress progress = [done, total](std::size_t d, std::size_t t) {
            *done = d;
            *total = t;
        };
        job_.emplace(
            Job{std::async(std::launch::async, [make, progress] { return make(progress); }), done,
                total, what});
    }

    // Takes the finished job's document, or shows why there is none.
    void pollJob() {
        if (!job_ || job_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
            return;
        Job job = std::move(*job_);
        job_.reset();
        try {
            doc_ = job.result.get();
        } catch (const std::exception& e) {
            if (!doc_) throw; // nothing to keep: the start file itself is bad
            fail(e.what());
            return;
        }
        drag_ = Drag::None;
        renderer_->update(doc_->mesher(), MeshChanges{true, {}});
        frame();
        status_ = job.what + ": done";
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
        switch (e.type) {
        case InputEvent::Type::Press:
        case InputEvent::Type::Release:
            onMove(e.x, e.y);
            onButton(e.button, e.type == InputEvent::Type::Press, e.x, e.y, e.shift);
            break;
        case InputEvent::Type::Move:
            onMove(e.x, e.y);
            break;
        case InputEvent::Type::Key:
            onKey(e.key, e.ctrl, e.shift);
            break;
        case InputEvent::Type::Scroll:
            onScroll(e.dy, e.ctrl);
            break;
        case InputEvent::Type::Drop:
            openFile(e.path);
            break;
        }
    }

    std::optional<glm::dvec3> pick(double x, double y) const {
        int w, h;
        glfwGetWindowSize(win_, &w, &h);
        const Ray r = camera_.rayThrough(x, y, w, h);
        const auto hit = raycastLevelSet(doc_->grid(), toEigen3(r.origin), toEigen3(r.direction),
                                         1e3 * camera_.distance);
        if (!hit) return std::nullopt;
        return toGlm(*hit);
    }

    // The tool placement for the cursor at (x, y) during a drag, by mode.
    Placement placementAt(double x, double y) const {
        int w, h;
        glfwGetWindowSize(win_, &w, &h);
        Placement p;
        p.t = toEigen3(grab_);
        switch (mode_) {
        case Mode::Grab:
        case Mode::Swirl:
        case Mode::Clay:
            p.t = toEigen3(grab_ + camera_.dragInViewPlane(grab_, pressX_, pressY_, x, y, w, h));
            break;
        case Mode::Twist:
            p.axis = toEigen3(axis_);
            p.angleDegrees = std::clamp(0.5 * (x - pressX_), -720.0, 720.0);
            break;
        case Mode::Inflate:
            p.scale = Eigen::Vector3d::Constant(
                std::exp(std::clamp(-(y - pressY_), -400.0, 400.0) * 0.004));
            break;
        }
        return p;
    }

    // The sculpting of a frame runs off the render thread; while it runs, the render thread
    // keeps drawing what it has and touches neither the grid nor the mesh. A replay waits
    // for each piece, so it is deterministic: one piece per event frame.
    bool busy() const { return work_.valid(); }

    void launch(std::function<SegmentReport()> task) {
        work_ = std::async(std::launch::async, std::move(task));
        if (batch_ && !opt_.replayLive) work_.wait();
    }

    // Takes finished work (its report, or why it failed).
    void collect() {
        if (!busy() || work_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
        try {
            report_ = work_.get();
            measuring_ = true;
        } catch (const std::exception& e) {
            doc_->endEdit();
            drag_ = Drag::None;
            releasing_ = pending_ = false;
            fail(e.what());
        }
    }

    void finishDrag() {
        doc_->endEdit();
        volume_ = doc_->mesher().enclosedVolume();
        drag_ = Drag::None;
        releasing_ = false;
    }

    // One piece of sculpting per frame for the latest cursor position of a drag: a sweep
    // segment, a swirl ring or a dab of clay.
    void step() {
        collect();
        if (busy() || drag_ != Drag::Sculpt) return;
        if (pending_) {
            pending_ = false;
            Document* doc = doc_.get();
            if (mode_ == Mode::Clay) {
                // A new dab once the cursor has moved half a radius (in the view plane: the
                // surface under a still cursor rises with every dab).
                int w, h;
                glfwGetWindowSize(win_, &w, &h);
                const double moved = glm::length(
                    camera_.dragInViewPlane(lastDab_, dabX_, dabY_, cursorX_, cursorY_, w, h));
                if (moved >= 0.5 * radius_) {
                    if (const auto hit = pick(cursorX_, cursorY_)) {
                        dab(*hit);
                        return;
                    }
                }
            } else if (const Placement p = placementAt(cursorX_, cursorY_); !(p == last_)) {
                if (mode_ == Mode::Swirl) {
                    // A swirl ring carries the clay from the last position to this one.
                    SwirlStroke sw;
                    sw.at = last_.t;
                    sw.move = p.t - last_.t;
                    sw.radius = radius_;
                    launch([doc, sw] { return doc->applyStroke(sw); });
                } else {
                    launch([doc, p] { return doc->extendStroke(p); });
                }
                last_ = p;
                return;
            }
        }
        if (releasing_) finishDrag();
    }

    void reportLatency() const {
        static const char* names[] = {"advect", "renorm", "mesh", "upload", "draw", "total"};
        std::fprintf(stderr, "latency over %zu segments at voxel size %g (ms, p50 / p95):",
                     latencies_.size(), doc_->grid().voxelSize()[0]);
        for (int k = 0; k < 6; ++k) {
            std::vector<double> v;
            for (const auto& l : latencies_)
                v.push_back(l[k]);
            std::sort(v.begin(), v.end());
            auto at = [&](double q) {
                return v.empty() ? 0.0
                                 : v[std::min(v.size() - 1, std::size_t(q * (v.size() - 1) + 0.5))];
            };
            std::fprintf(stderr, " %s %.1f / %.1f%s", names[k], at(0.5), at(0.95),
                         k < 5 ? "," : "\n");
        }
        std::vector<double> idle = idleFrames_;
        std::sort(idle.begin(), idle.end());
        if (!idle.empty())
            std::fprintf(stderr, "frame time when not sculpting (ms, p50 over %zu frames): %.1f\n",
                         idle.size(), idle[idle.size() / 2]);
    }

    void frame() {
        const Box b = activeWorldBox(doc_->grid());
        camera_.frame(toGlm(b.min), toGlm(b.max));
        volume_ = doc_->mesher().enclosedVolume();
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
        if (!busy()) {
            const auto t0 = std::chrono::steady_clock::now();
            renderer_->update(doc_->mesher(), doc_->takeMeshChanges());
            uploadMs_ =
                1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            groundY_ = activeWorldBox(doc_->grid()).min.y();
            info_ = {doc_->grid().voxelSize()[0], std::size_t(doc_->grid().activeVoxelCount()),
                     doc_->mesher().triangleCount(), doc_->undoCount(), doc_->undoBytes()};
        }
        ToolOverlay tool;
        tool.radius = radius_;
        tool.falloff = falloff_;
        if (drag_ == Drag::Sculpt) {
            tool.visible = mode_ != Mode::Clay;
            tool.center = toGlm(last_.t);
        } else if (drag_ == Drag::None && !busy()) {
            if (const auto hit = pick(cursorX_, cursorY_)) {
                tool.visible = true;
                tool.center = *hit;
            }
        }
        renderer_->draw(camera_.view(), camera_.projection(double(fw) / std::max(fh, 1)),
                        wireframe_, tool, groundY_);
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
            ImGui::End();
        }
        popups();
        ImGui::Render();
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    }

    void mainPanel() {
        ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowSize(ImVec2(380, 0), ImGuiCond_FirstUseEver);
        ImGui::Begin("Sweepers");
        ImGui::Text("Tool");
        ImGui::BeginDisabled(drag_ == Drag::Sculpt);
        int m = int(mode_);
        ImGui::RadioButton("Grab (G)", &m, 0);
        ImGui::SameLine();
        ImGui::RadioButton("Twist (T)", &m, 1);
        ImGui::SameLine();
        ImGui::RadioButton("Inflate (I)", &m, 2);
        ImGui::RadioButton("Swirl, keeps volume (S)", &m, 3);
        ImGui::SameLine();
        ImGui::RadioButton("Add clay (C)", &m, 4);
        mode_ = Mode(m);
        ImGui::EndDisabled();
        float r = float(radius_), f = float(falloff_);
        if (ImGui::SliderFloat("radius  [ ]", &r, 0.02f, 1.0f, "%.3f",
                               ImGuiSliderFlags_Logarithmic))
            radius_ = r;
        if (ImGui::SliderFloat("falloff  shift [ ]", &f, 0.02f, 1.0f, "%.3f",
                               ImGuiSliderFlags_Logarithmic))
            falloff_ = f;
        int mirror = int(mirror_);
        ImGui::Combo("mirror (M)", &mirror, "none\0x\0y\0z\0");
        mirror_ = MirrorAxis(mirror);
        ImGui::Checkbox("wireframe (W)", &wireframe_);
        ImGui::Separator();
        ImGui::Text("frame %.1f ms, upload %.1f ms", frameMs_, uploadMs_);
        ImGui::Text("voxel size %.5g, active voxels %zu", info_.voxelSize, info_.activeVoxels);
        ImGui::Text("triangles %zu, volume %.5f", info_.triangles, volume_);
        ImGui::Text("last segment: advect %.1f, renorm %.1f, mesh %.1f ms",
                    1e3 * (report_.stats.growSeconds + report_.stats.sampleSeconds),
                    1e3 * report_.stats.renormalizeSeconds, 1e3 * report_.meshSeconds);
        ImGui::Text("undo: %zu strokes, %.1f of %.0f MB", info_.undoCount,
                    double(info_.undoBytes) / (1 << 20), double(doc_->undoBudget()) / (1 << 20));
        // Nothing that changes the document while a drag is being sculpted.
        ImGui::BeginDisabled(busy() || drag_ == Drag::Sculpt);
        if (ImGui::Button("Undo")) onKey('Z', true, false);
        ImGui::SameLine();
        if (ImGui::Button("Redo")) onKey('Z', true, true);
        ImGui::Separator();
        ImGui::InputText("file", path_, sizeof path_);
        if (ImGui::Button("Open")) openFile(path_);
        ImGui::SameLine();
        if (ImGui::Button("Save")) save(path_);
        ImGui::SameLine();
        if (ImGui::Button("New sphere")) {
            auto fresh = [this] {
                doc_ = std::make_unique<Document>(
                    Document::sphereScript(doc_->grid().voxelSize()[0]), ".");
                renderer_->update(doc_->mesher(), MeshChanges{true, {}});
                frame();
            };
            if (doc_->modified())
                confirm("Start a new sphere and discard the unsaved changes?", fresh);
            else
                fresh();
        }
        ImGui::TextWrapped("Open reads .vdb and .json, imports .obj/.ply/.stl; Save writes "
                           ".vdb, the stroke script for .json, a mesh for .obj/.ply/.stl.");
        ImGui::InputFloat("voxel size", &voxelSizeInput_, 0.0f, 0.0f, "%.6f");
        if (ImGui::Button("Resample (replay the history at this voxel size)")) {
            const double h = voxelSizeInput_;
            StrokeScript script = doc_->script();
            const std::string dir = doc_->scriptDir();
            doc_->endStroke();
            if (!(h >= 1e-4 && h <= 0.5)) {
                fail("the voxel size must lie between 0.0001 and 0.5");
            } else {
                const bool modified = doc_->modified();
                startJob("resampling to voxel size " + std::to_string(h),
                         [script, dir, h, modified](const Progress& p) {
                             auto d =
                                 std::make_unique<Document>(Document::replayAt(script, dir, h, p));
                             if (modified) d->markModified();
                             return d;
                         });
            }
        }
        ImGui::EndDisabled();
        if (!status_.empty()) ImGui::TextWrapped("%s", status_.c_str());
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
        // Atomic: a temporary beside the target, renamed when complete.
        const std::string tmp = path + ".tmp";
        if (!stbi_write_png(tmp.c_str(), fw, fh, 3, px.data(), fw * 3) ||
            std::rename(tmp.c_str(), path.c_str()) != 0) {
            std::remove(tmp.c_str());
            throw std::runtime_error(path + ": cannot write the screenshot");
        }
    }

    struct Job {
        std::future<std::unique_ptr<Document>> result;
        std::shared_ptr<std::atomic<std::size_t>> done, total;
        std::string what;
    };
    std::optional<Job> job_;
    std::future<SegmentReport> work_;
    bool batch_ = false, releasing_ = false;
    double groundY_ = -1.0;
    struct Info {
        double voxelSize = 0;
        std::size_t activeVoxels = 0, triangles = 0, undoCount = 0, undoBytes = 0;
    } info_;
    std::string confirmText_;
    std::function<void()> confirmAction_;
    float voxelSizeInput_ = 1.0f / 64;

    ModelerOptions opt_;
    GLFWwindow* win_;
    std::unique_ptr<Document> doc_;
    std::unique_ptr<GlRenderer> renderer_;
    OrbitCamera camera_;
    Mode mode_ = Mode::Grab;
    Drag drag_ = Drag::None;
    MirrorAxis mirror_ = MirrorAxis::None;
    double radius_ = 0.25, falloff_ = 0.25;
    bool wireframe_ = false, pending_ = false, askQuit_ = false, discard_ = false;
    double pressX_ = 0, pressY_ = 0, lastX_ = 0, lastY_ = 0, cursorX_ = -1, cursorY_ = -1;
    glm::dvec3 grab_{0.0}, axis_{0, 0, 1}, lastDab_{0.0};
    double dabX_ = 0, dabY_ = 0;
    Placement last_;
    SegmentReport report_;
    using Clock = std::chrono::steady_clock;
    Clock::time_point pendingSince_;
    bool measuring_ = false;
    // Per segment: advect, renorm, mesh, upload, draw (+ swap, finish), total; in ms.
    std::vector<std::array<double, 6>> latencies_;
    std::vector<double> idleFrames_;
    double frameMs_ = 0, uploadMs_ = 0, volume_ = 0;
    char path_[1024] = {};
    std::string error_, status_;
};

Modeler* gModeler = nullptr;

bool ctrlDown(GLFWwindow* w) {
    return glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS ||
           glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS;
}

// GLFW callbacks; ImGui's backend chains to them, and keeps what falls on its panels.
void buttonCallback(GLFWwindow* w, int button, int action, int mods) {
    if (!gModeler || (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse)) return;
    double x, y;
    glfwGetCursorPos(w, &x, &y);
    const int b = button == GLFW_MOUSE_BUTTON_LEFT ? 0 : button == GLFW_MOUSE_BUTTON_RIGHT ? 1 : 2;
    gModeler->onButton(b, action == GLFW_PRESS, x, y, (mods & GLFW_MOD_SHIFT) != 0);
}
void cursorCallback(GLFWwindow*, double x, double y) {
    if (gModeler) gModeler->onMove(x, y);
}
void scrollCallback(GLFWwindow* w, double, double dy) {
    if (!gModeler || (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse)) return;
    gModeler->onScroll(dy, ctrlDown(w));
}
void dropCallback(GLFWwindow*, int count, const char** paths) {
    if (gModeler && count > 0) gModeler->openFile(paths[0]);
}
void keyCallback(GLFWwindow*, int key, int, int action, int mods) {
    if (!gModeler || action == GLFW_RELEASE) return;
    if (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureKeyboard) return;
    int k = key;
    if (key == GLFW_KEY_LEFT_BRACKET) k = '[';
    if (key == GLFW_KEY_RIGHT_BRACKET) k = ']';
    gModeler->onKey(k, (mods & GLFW_MOD_CONTROL) != 0, (mods & GLFW_MOD_SHIFT) != 0);
}

} // namespace

int runModeler(const ModelerOptions& o) {
    if (!glfwInit())
        throw std::runtime_error(
            "cannot open a window (no display?); sweepers-cli works without one");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    // 4x multisampling, except on a software rasterizer (llvmpipe without a GPU), where it
    // costs more than half of every frame: the window is then made again without it.
    auto open = [&](int samples) {
        glfwWindowHint(GLFW_SAMPLES, samples);
        GLFWwindow* w = glfwCreateWindow(o.width, o.height, "Sweepers", nullptr, nullptr);
        if (!w) {
            glfwTerminate();
            throw std::runtime_error("cannot create an OpenGL 3.3 core window");
        }
        glfwMakeContextCurrent(w);
        return w;
    };
    GLFWwindow* w = open(4);
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    if (renderer && (std::strstr(renderer, "llvmpipe") || std::strstr(renderer, "softpipe"))) {
        glfwDestroyWindow(w);
        w = open(0);
    }
    glfwSwapInterval(o.replayInput.empty() && o.screenshot.empty() ? 1 : 0);
    glfwSetMouseButtonCallback(w, buttonCallback);
    glfwSetCursorPosCallback(w, cursorCallback);
    glfwSetScrollCallback(w, scrollCallback);
    glfwSetKeyCallback(w, keyCallback);
    glfwSetDropCallback(w, dropCallback);
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(w, true); // chains to the callbacks above
    ImGui_ImplOpenGL3_Init("#version 330 core");
    int code = 1;
    try {
        Modeler m(o, w);
        gModeler = &m;
        code = m.run();
        gModeler = nullptr;
    } catch (...) {
        gModeler = nullptr;
        ImGui_ImplOpenGL3_Shutdown();
        ImGui_ImplGlfw_Shutdown();
        ImGui::DestroyContext();
        glfwDestroyWindow(w);
        glfwTerminate();
        throw;
    }
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(w);
    glfwTerminate();
    return code;
}

} // namespace sweepers
