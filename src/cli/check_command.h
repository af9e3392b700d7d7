// SPDX-License-Identifier: Apache-2.0
// sweepers-cli check: a stroke script validated and its plan shown, step by step, as apply
// will run it (sculpt/stroke_plan.h makes both); and the plan's rows, which apply --stats
// reports for the steps it ran, from the same function.
#pragma once

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "sculpt/stroke_plan.h"

namespace sweepers::cli {

// One step of a plan: {"stroke", "segment", "type", and "tools", "steps", "bound",
// "affected_box" (and "fluid_steps") for a deformation, "center", "radius", "time" for a
// smooth dab, "decided_on_shape": true where the shape decides the rest}.
nlohmann::json stepJson(std::size_t stroke, const PlannedStep& step);

struct CheckArgs {
    std::string script;
    double voxelSize = 0.0; // 0: the script's (a VDB start's own)
};

int runCheck(const CheckArgs& args);

} // namespace sweepers::cli
