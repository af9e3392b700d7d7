// SPDX-License-Identifier: Apache-2.0
// The one planner: where a stroke (sculpt/stroke.h) becomes the steps a sculptor applies,
// each a deformation of space or a smooth dab. `sweepers-cli check` prints the plan made
// ahead of the shape, `apply` runs the plan made on the shape, and both come from the same
// function, so they cannot disagree where the shape does not decide.
//
// What the shape decides, and only that, is left out of a plan made ahead: an inflation's
// and a star-shaped swirl's reach (the whole shape as it is when the stroke comes), where an
// inflation's centre lands on the surface, and a flow's segment count when the script does
// not give it. Sub-steps and boxes of every other step depend on the stroke and the voxel
// size alone.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "deform/step_deformation.h"
#include "levelset/smooth.h"
#include "sculpt/stroke.h"
#include "vdb/vdb.h"

namespace sweepers {

// One step of a stroke's plan.
struct PlannedStep {
    std::size_t segment = 0; // its place in the stroke's plan
    // What it is, in the user's words: "sweep", "swirl", "star-shaped swirl", "inflate",
    // "remove", "pinch needles", "pinch pull", "strangle noose", "strangle pull",
    // "keyframed", "slide", "flow (<field>)", "fluid" or "smooth".
    std::string kind;
    // The deformation to apply, or null: a smooth dab (`dab` then), or a step planned ahead
    // whose deformation the shape decides (`leftToShape`).
    std::shared_ptr<const StepDeformation> deformation;
    std::optional<SmoothBrush> dab;
    // The deformation's summary, kept when the deformation itself is let go: its sub-steps
    // and the box outside which it is the identity. Planned ahead, a flow whose segments the
    // shape chooses shows its whole span here (apply cuts it into segments).
    int subSteps = 0;
    Box affected;
    std::size_t tools = 0; // tools swept together (a sweep's, a pinch's needles), else 1 or 0
    double bound = 0.0;    // a sweep segment's sub-step bound (3.19), else 0
    int fluidSteps = 0;    // a fluid segment's chained flow steps (4.26), else 0
    bool leftToShape = false;
};

// The plan of `stroke` made on `shape`, the grid as it is when the stroke comes: what apply
// runs. Refuses (core/limits.h) an inflation whose new band, or a fluid segment whose work,
// the machine cannot hold. Throws std::invalid_argument for a baked tool or a fluid whose
// solution was not loaded (io/stroke_script.h).
std::vector<PlannedStep> planStroke(const Grid& shape, const Stroke& stroke);
// The same plan made ahead of any shape, at `voxelSize`: what the shape decides is left out
// (leftToShape steps without a deformation).
std::vector<PlannedStep> planStrokeAhead(const Stroke& stroke, double voxelSize);

} // namespace sweepers
