// The start shape of a stroke script as a level set: a sphere, or the .vdb or mesh file
// the script names (relative to the script's directory).
#pragma once

#include <string>

#include "levelset/interrupt.h"
#include "sculpt/stroke.h"

namespace sweepers {

// voxelSize > 0 overrides the script's grid.voxel_size. Throws ScriptError (or a file
// error) for a start that cannot be made, Cancelled when `interrupter` stops it.
GridPtr makeStartGrid(const StrokeScript& script, const std::string& scriptDir,
                      double voxelSize = 0.0, Interrupter* interrupter = nullptr);

} // namespace sweepers
