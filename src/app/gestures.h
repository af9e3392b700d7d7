// SPDX-License-Identifier: Apache-2.0
// What a sculpting drag does from its press to its release, one gesture per tool family:
// sweeps (grab, twist, inflate), pushes that keep the volume (swirl, fluid), dabs (clay,
// smooth) and the topology tools (pinch, strangle); and F's sizing of the tool, between the
// key and a click. A gesture keeps its own state; the sculpt controller
// (app/sculpt_controller.h) owns the drag, its worker and its timing, and hands each gesture
// what it may use (GestureTools). A new tool adds a gesture here, not flags to the controller.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "app/camera.h"
#include "app/tool_settings.h"
#include "document/document.h"

namespace sweepers {

// What a gesture works with, as it is at the call.
struct GestureTools {
    Document& doc;
    const OrbitCamera& camera;
    const ToolSettings& settings;
    RadialSymmetry radial;           // the symmetry the panel sets
    double cursorX = 0, cursorY = 0; // the cursor now, in window pixels
    int width = 1, height = 1;       // the viewport
    // Starts a piece of sculpting on the controller's worker.
    std::function<void(std::function<SegmentReport()>)> launch;
    // The surface point under a window pixel.
    std::function<std::optional<glm::dvec3>(double, double)> pick;

    // The cursor's way from window pixel (x0, y0), taken into the view plane through `at`.
    glm::dvec3 dragFrom(const glm::dvec3& at, double x0, double y0) const {
        return camera.dragInViewPlane(at, x0, y0, cursorX, cursorY, width, height);
    }
};

// Where a drag began: the surface point pressed, the pixel, Ctrl held (the tool inverted).
struct Press {
    glm::dvec3 at{0.0};
    double x = 0, y = 0;
    bool inverted = false;
};

class Gesture {
  public:
    virtual ~Gesture() = default;
    // The press: begins the document's edit or stroke. A message when the drag cannot start
    // there (the drag then does not start).
    virtual std::optional<std::string> press(const GestureTools& t) = 0;
    // The cursor moved since the last piece: launches the next piece if the move asks for one
    // (true), else nothing.
    virtual bool move(const GestureTools& t) = 0;
    enum class Release { Done, Launched, Refused };
    // The release, once no piece runs: done, or a last piece launched (a pinch applies
    // now; the release comes again when it is done), or refused with `message`.
    virtual Release release(const GestureTools& t, std::string& message) {
        (void)t, (void)message;
        return Release::Done;
    }
    // Where the tool is drawn during the drag (none for dabs and topology tools).
    virtual std::optional<glm::dvec3> toolCentre() const { return std::nullopt; }
    // The stroke the release will apply, as it stands (pinch, strangle).
    virtual std::optional<Stroke> stroke(const GestureTools& t) const {
        (void)t;
        return std::nullopt;
    }
};

// The gesture of a drag in `mode` pressed at `press`.
std::unique_ptr<Gesture> makeGesture(SculptMode mode, const Press& press);

// F and Shift-F: the radius, or the strength, set by moving the mouse (a circle on the
// screen), a click to keep it, Esc to put it back.
class ToolSizing {
  public:
    // Begins with the cursor at (x, y), the circle about the surface point `at` under it.
    ToolSizing(Sizing what, double x, double y, const glm::dvec3& at, ToolSettings& settings);
    Sizing what() const { return what_; }
    const glm::dvec3& at() const { return at_; }
    void move(double x, double y, const OrbitCamera& camera, int width, int height,
              ToolSettings& settings) const;
    // Esc: the value it had.
    void putBack(ToolSettings& settings) const;

  private:
    // The strength Shift-F sets: the smooth tool's own, or every other tool's.
    static double& strengthOf(ToolSettings& s);

    Sizing what_;
    double x_, y_, from_;
    glm::dvec3 at_;
};

// A pinch's falloff is at least this many voxels (see the topology gesture's stroke).
inline constexpr double kMinPinchFalloffVoxels = 16.0;
// Twist drags are cut into placements at most this far apart, so that every segment turns
// the way the hand went, however fast it went (a segment's motion is the logarithm of the
// relative placement, which takes the short way round).
inline constexpr double kMaxTwistStepDegrees = 60.0;

} // namespace sweepers
