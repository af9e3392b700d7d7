// SPDX-License-Identifier: Apache-2.0
// The tool a sculptor holds: its mode and the settings the panel, the keys and the wheel
// change. The sculpt controller (app/sculpt_controller.h) and its gestures (app/gestures.h)
// read them; the panel (app/panels.h) shows them.
#pragma once

#include <array>
#include <memory>

#include "sculpt/stroke.h"
#include "tools/tool_shape.h"

namespace sweepers {

// Grab, twist and inflate are sweeps (one segment per piece); swirl moves clay while
// keeping its volume (one swirl ring per piece, 4.1), and so does fluid (the swept fluid of
// 4.2, one fluid stroke per piece); clay adds material (Decaudin's
// inflation, 2.30) under the cursor. Pinch and strangle change the topology (3.5): a drag
// sets them up, shown as a preview, and the release applies the whole stroke. Smooth
// relaxes the surface under the brush (levelset/smooth.h), one dab every quarter radius.
enum class SculptMode { Grab, Twist, Inflate, Swirl, Fluid, Clay, Pinch, Strangle, Smooth };

// Each mode's key and its name in the panel, in SculptMode's order: the key handler and the
// panel both read this table.
struct ModeInfo {
    SculptMode mode;
    int key;
    const char* label;
};
inline constexpr std::array<ModeInfo, 9> kModes{{
    {SculptMode::Grab, 'G', "Grab (G)"},
    {SculptMode::Twist, 'T', "Twist (T)"},
    {SculptMode::Inflate, 'I', "Inflate (I)"},
    {SculptMode::Swirl, 'S', "Swirl, keeps volume (S)"},
    {SculptMode::Fluid, 'U', "Fluid, keeps volume (U)"},
    {SculptMode::Clay, 'C', "Add clay (C)"},
    {SculptMode::Pinch, 'P', "Pinch a hole (P)"},
    {SculptMode::Strangle, 'K', "Strangle (K)"},
    {SculptMode::Smooth, 'O', "Smooth (O, Shift-drag)"},
}};
struct ToolSettings {
    SculptMode mode = SculptMode::Grab;
    MirrorAxis mirror = MirrorAxis::None;
    double radius = 0.25, falloff = 0.25;
    // (0, 1]: the fraction of the hand's motion a grab, twist, inflate or fluid applies, of
    // a swirl's move, of the clay ball's radius.
    double strength = 1.0;
    // (0, kMostSmoothStrength]: a smooth dab's flow time over the default dab's (Shift-drag
    // smooths with it whatever the tool; a smooth dab is cheap enough to reach the form).
    double smoothStrength = 1.0;
    // Radial symmetry: `radialCount` copies of a grab, twist or inflate tool (and of each
    // swirl ring and dab of clay or smoothing) turned about the axis `radialAxis` (0 x, 1 y,
    // 2 z) through the origin; 1 is the tool alone.
    int radialCount = 1, radialAxis = 1;
    bool wireframe = false;
    // Grab and twist move this shape instead of a ball when set (a baked tool, 3.4.3),
    // scaled by `radius` over its own half-size `bakedRadius`.
    std::shared_ptr<const ToolShape> bakedTool;
    BakedToolSource bakedSource;
    double bakedRadius = 1.0;
};

// F and Shift-F: the radius, or the strength, set by moving the mouse (a circle on the
// screen), a click to keep it, Esc to put it back.
enum class Sizing { None, Radius, Strength };

} // namespace sweepers
