// SPDX-License-Identifier: Apache-2.0
#include "app/sculpt_controller.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#define GLFW_INCLUDE_NONE // key codes only: this file uses no window
#include <GLFW/glfw3.h>

#include "app/glm_eigen.h"
#include "io/baked_tool.h"
#include "io/mesh_file.h"
#include "levelset/band.h"
#include "levelset/raycast.h"

namespace sweepers {

void SculptController::setDocument(Document* doc) {
    wait();
    collect();
    doc_ = doc;
    drag_ = DragKind::None;
    pending_ = releasing_ = false;
    if (doc_) {
        doc_->setInterrupter(&stop_);
        volume_ = doc_->mesher().enclosedVolume();
    }
}

void SculptController::setViewport(int width, int height) {
    width_ = std::max(width, 1);
    height_ = std::max(height, 1);
}

void SculptController::onButton(int button, bool press, double x, double y, bool shift, bool ctrl) {
    if (!doc_) return;
    cursorX_ = x;
    cursorY_ = y;
    if (sizing_) {
        // The click that ends F or Shift-F keeps what the mouse set; it sculpts nothing.
        if (press && button == 0) sizing_.reset();
        return;
    }
    if (!press) {
        if (drag_ == DragKind::Sculpt) {
            // The last position counts; the drag ends once its work is done.
            pending_ = true;
            releasing_ = true;
            step();
        } else {
            drag_ = DragKind::None;
        }
        return;
    }
    if (busy() || drag_ == DragKind::Sculpt) return;
    lastX_ = x;
    lastY_ = y;
    if (button == 1 || button == 2) {
        drag_ = DragKind::Pan;
        return;
    }
    const auto hit = sculpting_ ? pick(x, y) : std::nullopt;
    if (!hit) {
        drag_ = DragKind::Orbit;
        return;
    }
    pressOnShape(shift, ctrl, *hit);
}

// A left press on the shape: the gesture of the tool (smoothing with Shift, whatever the
// tool; Ctrl inverts it) begins its edit.
void SculptController::pressOnShape(bool smooth, bool ctrl, const glm::dvec3& at) {
    const SculptMode mode = smooth ? SculptMode::Smooth : settings_.mode;
    gesture_ = makeGesture(mode, Press{at, cursorX_, cursorY_, ctrl});
    drag_ = DragKind::Sculpt;
    pending_ = false;
    stop_.reset();
    pendingSince_ = Clock::now(); // a dab's latency counts from the press
    if (const auto refused = gesture_->press(working())) {
        message_ = *refused;
        stopDrag();
    }
}

RadialSymmetry SculptController::radial() const {
    RadialSymmetry r;
    r.axis = Eigen::Vector3d::Unit(std::clamp(settings_.radialAxis, 0, 2));
    r.count = std::clamp(settings_.radialCount, 1, 64);
    return r;
}

void SculptController::useToolFile(const std::string& path) {
    BakedToolSource source;
    source.kind = isMeshPath(path) ? BakedToolSource::Kind::Mesh : BakedToolSource::Kind::Vdb;
    source.file = std::filesystem::absolute(path).lexically_normal().string();
    if (source.kind == BakedToolSource::Kind::Mesh && doc_)
        source.voxelSize = doc_->grid().voxelSize()[0];
    const auto shape = loadBakedTool(source, "", 1.0, settings_.falloff);
    const Box b = shape->place(Eigen::Affine3d::Identity())->bounds();
    settings_.bakedTool = shape;
    settings_.bakedSource = source;
    settings_.bakedRadius = 0.5 * b.extent().maxCoeff();
}

void SculptController::useBall() {
    settings_.bakedTool.reset();
}

std::optional<Stroke> SculptController::topologyStroke() const {
    if (!doc_ || drag_ != DragKind::Sculpt || !gesture_) return std::nullopt;
    return gesture_->stroke(tools());
}

GestureTools SculptController::tools() const {
    GestureTools t{*doc_,    camera_, settings_, radial(), cursorX_,
                   cursorY_, width_,  height_,   {},       {}};
    t.pick = [this](double x, double y) { return pick(x, y); };
    return t;
}

GestureTools SculptController::working() {
    GestureTools t = tools();
    t.launch = [this](std::function<SegmentReport()> task) { launch(std::move(task)); };
    return t;
}

void SculptController::onMove(double x, double y) {
    const double dx = x - lastX_, dy = y - lastY_;
    cursorX_ = x;
    cursorY_ = y;
    if (sizing_) {
        sizing_->move(x, y, camera_, width_, height_, settings_);
        lastX_ = x;
        lastY_ = y;
        return;
    }
    switch (drag_) {
    case DragKind::Orbit:
        camera_.orbit(-dx * 0.008, dy * 0.008);
        break;
    case DragKind::Pan:
        camera_.pan(dx / height_, dy / height_);
        break;
    case DragKind::Sculpt:
        // Coalesced: one piece per step, at the latest position; its latency counts from
        // the first event it absorbs.
        if (!pending_) pendingSince_ = Clock::now();
        pending_ = true;
        break;
    case DragKind::None:
        break;
    }
    lastX_ = x;
    lastY_ = y;
}

void SculptController::onScroll(double dy, bool ctrl) {
    if (ctrl)
        settings_.radius = std::clamp(settings_.radius * std::pow(1.1, dy), 0.02, 2.0);
    else
        camera_.zoom(std::pow(0.9, dy));
}

KeyAction SculptController::onKey(int key, bool ctrl, bool shift) {
    if (!doc_) return KeyAction::None;
    if (key == GLFW_KEY_ESCAPE) {
        if (sizing_) {
            sizing_->putBack(settings_);
            sizing_.reset();
            return KeyAction::None;
        }
        if (busy()) cancel();
        return KeyAction::Cancel;
    }
    if (ctrl && busy()) return KeyAction::None; // undo and save wait for the sculpting
    if (ctrl && key == 'Z') {
        shift ? doc_->redo() : doc_->undo();
        volume_ = doc_->mesher().enclosedVolume();
        return KeyAction::None;
    }
    if (ctrl && key == 'S') return KeyAction::Save;
    if (ctrl || (drag_ == DragKind::Sculpt && std::isalpha(key))) return KeyAction::None;
    for (const ModeInfo& m : kModes)
        if (key == m.key) {
            settings_.mode = m.mode;
            return KeyAction::None;
        }
    double& size = shift ? settings_.falloff : settings_.radius; // [ and ]: shift for falloff
    switch (key) {
    case 'F':
        if (drag_ == DragKind::None)
            sizing_.emplace(shift ? Sizing::Strength : Sizing::Radius, cursorX_, cursorY_,
                            pick(cursorX_, cursorY_).value_or(camera_.target), settings_);
        break;
    case GLFW_KEY_HOME:
        if (!busy()) frameView();
        break;
    case 'W':
        settings_.wireframe = !settings_.wireframe;
        break;
    case 'M':
        settings_.mirror = MirrorAxis((int(settings_.mirror) + 1) % 4);
        break;
    case '[':
        size = std::max(0.02, size / 1.1);
        break;
    case ']':
        size = std::min(2.0, size * 1.1);
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
    return KeyAction::None;
}

void SculptController::dispatch(const InputEvent& e) {
    switch (e.type) {
    case InputEvent::Type::Press:
    case InputEvent::Type::Release:
        onMove(e.x, e.y);
        onButton(e.button, e.type == InputEvent::Type::Press, e.x, e.y, e.shift, e.ctrl);
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
        break;
    }
}

std::optional<glm::dvec3> SculptController::pick(double x, double y) const {
    if (!doc_) return std::nullopt;
    const Ray r = camera_.rayThrough(x, y, width_, height_);
    const auto hit = raycastLevelSet(doc_->grid(), toEigen3(r.origin), toEigen3(r.direction),
                                     1e3 * camera_.distance);
    if (!hit) return std::nullopt;
    return toGlm(*hit);
}

std::optional<glm::dvec3> SculptController::toolCentre() const {
    if (sizing_) return sizing_->at();
    if (drag_ == DragKind::Sculpt) return gesture_ ? gesture_->toolCentre() : std::nullopt;
    if (drag_ == DragKind::None && !busy() && sculpting_) return pick(cursorX_, cursorY_);
    return std::nullopt;
}

void SculptController::frameView() {
    if (!doc_) return;
    const Box b = activeWorldBox(doc_->grid());
    camera_.frame(toGlm(b.min), toGlm(b.max));
    volume_ = doc_->mesher().enclosedVolume();
}

void SculptController::launch(std::function<SegmentReport()> task) {
    workSince_ = pendingSince_;
    // A replay waits for each piece, so the window's thread runs it itself. On a worker
    // thread, the worker and TBB's thread it wakes can queue on one of the two vCPUs of a
    // virtual machine whose kernel sees no shared cache (so a wakeup looks for no idle
    // core) while the other stays idle: a replay, which measures latency, would measure
    // the scheduler instead of the engine.
    work_ = std::async(waitEach_ ? std::launch::deferred : std::launch::async, std::move(task));
    if (waitEach_) work_.wait();
}

// Takes finished work (its report, or why it failed).
void SculptController::collect() {
    if (!busy() || work_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    try {
        finished_ = Finished{work_.get(), workSince_};
    } catch (const Cancelled&) {
        // The document has put the edit back already.
        stopDrag();
        volume_ = doc_->mesher().enclosedVolume();
        message_ = "the stroke was cancelled; the shape is as it was before it";
    } catch (const std::exception& e) {
        doc_->endEdit();
        stopDrag();
        message_ = e.what();
    }
}

void SculptController::finishDrag() {
    doc_->endEdit();
    volume_ = doc_->mesher().enclosedVolume();
    stopDrag();
}

void SculptController::stopDrag() {
    drag_ = DragKind::None;
    gesture_.reset();
    releasing_ = pending_ = false;
}

// One piece of sculpting for the latest cursor position of a drag (its gesture's: a sweep
// segment or a few, a swirl ring, a fluid push, a dab), then, at the release, the drag's end.
void SculptController::step() {
    collect();
    if (busy()) return;
    if (idle_) idle_();
    if (drag_ != DragKind::Sculpt) return;
    if (std::exchange(pending_, false) && gesture_->move(working())) return;
    if (!releasing_) return;
    pendingSince_ = Clock::now(); // a piece the release launches counts from here
    switch (gesture_->release(working(), message_)) {
    case Gesture::Release::Done:
        finishDrag();
        break;
    case Gesture::Release::Launched:
        break;
    case Gesture::Release::Refused:
        stopDrag();
        break;
    }
}

namespace {

// A circle of radius r about c in the plane normal to n, as 48 segments.
void addCircle(std::vector<glm::dvec3>& lines, const glm::dvec3& c, const glm::dvec3& n, double r) {
    const glm::dvec3 a = glm::normalize(
        glm::cross(n, std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
    const glm::dvec3 b = glm::cross(n, a);
    const int segments = 48;
    for (int i = 0; i < segments; ++i)
        for (int k : {i, i + 1}) {
            const double t = 2.0 * M_PI * k / segments;
            lines.push_back(c + r * (std::cos(t) * a + std::sin(t) * b));
        }
}

} // namespace

std::vector<glm::dvec3> SculptController::symmetryPreview(const glm::dvec3& centre) const {
    std::vector<glm::dvec3> lines;
    const glm::dvec3 facing = glm::normalize(camera_.eye() - camera_.target);
    std::vector<glm::dvec3> copies;
    const RadialSymmetry r = radial();
    copies.reserve(2 * std::size_t(r.count));
    for (int k = 0; k < r.count; ++k)
        copies.push_back(toGlm(r.turn(k) * toEigen3(centre)));
    // Mirror planes copy the sweeps (grab, twist, inflate) only.
    const SculptMode m = settings_.mode;
    const bool sweeps = m == SculptMode::Grab || m == SculptMode::Twist || m == SculptMode::Inflate;
    if (settings_.mirror != MirrorAxis::None && sweeps) {
        const int axis = int(settings_.mirror) - 1;
        for (std::size_t k = 0, n = copies.size(); k < n; ++k) {
            glm::dvec3 m = copies[k];
            m[axis] = -m[axis];
            copies.push_back(m);
        }
    }
    for (std::size_t k = 1; k < copies.size(); ++k)
        addCircle(lines, copies[k], facing, settings_.radius);
    return lines;
}

std::vector<glm::dvec3> strokePreview(const Stroke& stroke) {
    std::vector<glm::dvec3> lines;
    if (const auto* p = std::get_if<PinchStroke>(&stroke)) {
        const glm::dvec3 at = toGlm(p->at), axis = glm::normalize(toGlm(p->axis));
        for (double side : {1.0, -1.0})
            lines.insert(lines.end(), {at + side * p->size * axis, at});
        addCircle(lines, at, axis, p->open);
    } else if (const auto* s = std::get_if<StrangleStroke>(&stroke)) {
        const glm::dvec3 at = toGlm(s->at), axis = glm::normalize(toGlm(s->axis));
        addCircle(lines, at, axis, s->size);
        lines.insert(lines.end(), {at - 0.5 * s->open * axis, at + 0.5 * s->open * axis});
    }
    return lines;
}

ReplayClock::ReplayClock(std::vector<InputEvent> events)
    : events_(std::move(events)), lastFrame_(events_.empty() ? 1 : events_.back().frame + 2) {}

void ReplayClock::deliver(const SculptController& controller,
                          const std::function<void(const InputEvent&)>& dispatch) {
    if (!controller.readyForEvents()) return;
    for (; next_ < events_.size() && events_[next_].frame == frame_; ++next_)
        dispatch(events_[next_]);
}

void ReplayClock::endFrame(const SculptController& controller) {
    if (controller.readyForEvents()) ++frame_;
}

void replayEvents(SculptController& controller, const std::vector<InputEvent>& events) {
    ReplayClock clock(events);
    while (!clock.over() || controller.busy() || controller.drag() != DragKind::None) {
        clock.deliver(controller, [&](const InputEvent& e) { controller.dispatch(e); });
        controller.step();
        clock.endFrame(controller);
        if (clock.overtime() > 1000) break; // a drag never released: stop waiting for it
    }
    controller.wait();
    controller.step();
}

} // namespace sweepers
