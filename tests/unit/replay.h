// SPDX-License-Identifier: Apache-2.0
// A stroke script applied the way `sweepers-cli apply` applies it: its start grid, then
// every stroke through a Sculptor.
#pragma once

#include <functional>
#include <string>

#include "io/start_grid.h"
#include "sculpt/sculptor.h"

namespace sweepers {

// voxelSize > 0 overrides the script's; `after` runs after every stroke with the grid.
inline GridPtr applyScript(const StrokeScript& script, const std::string& dir,
                           double voxelSize = 0.0,
                           const std::function<void(std::size_t, const Grid&)>& after = {}) {
    Sculptor sculptor(makeStartGrid(script, dir, voxelSize));
    applyStrokes(sculptor, script.strokes, {}, [&](std::size_t stroke) {
        if (after) after(stroke, sculptor.grid());
    });
    return sculptor.gridPtr();
}

} // namespace sweepers
