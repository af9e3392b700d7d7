// SPDX-License-Identifier: Apache-2.0
// The start shape of a stroke script as a level set: a sphere, or the .vdb or mesh file
// the script names (relative to the script's directory).
#pragma once

#include <string>

#include "levelset/interrupt.h"
#include "sculpt/stroke.h"
#include "study/reference.h"

namespace sweepers {

// voxelSize > 0 overrides the script's grid.voxel_size. Throws ScriptError (or a file
// error) for a start that cannot be made, or whose band would need more memory than the
// machine has available (unless `force`), Cancelled when `interrupter` stops it.
GridPtr makeStartGrid(const StrokeScript& script, const std::string& scriptDir,
                      double voxelSize = 0.0, Interrupter* interrupter = nullptr,
                      bool force = false);

// The start shape as the exact reference of a history starts from it (study/reference.h):
// a sphere's own distance, or `start` (the grid makeStartGrid made) sampled.
ExactReference::StartFunction exactStart(const StrokeScript& script, const GridPtr& start);

// The checks makeStartGrid makes before it reads or builds anything: the half-width, and for
// a sphere its size in voxels and the memory its band needs. `check` makes them too.
void requireBuildableStart(const StrokeScript& script, double voxelSize = 0.0, bool force = false);

// Throws ScriptError unless the sphere is 1.5 to 100000 voxels in radius.
void requireSphereSize(double radius, double voxelSize);

// Peak memory per band voxel while a start is built (measured: a sphere about 28 bytes, a
// mesh conversion 40 to 65), with some headroom.
constexpr double kSphereBytesPerVoxel = 32.0, kMeshBytesPerVoxel = 64.0;
// Peak resident memory per band voxel of a run's grid while it is sculpted, measured and
// meshed (the grid, the advector's scratch, undo's or the reference's copies, the mesh),
// with headroom: what `apply` and a study's run need.
constexpr double kRunBytesPerVoxel = 160.0;

// Throws LimitExceeded when a band of `halfWidth` voxels around a surface of `area` would
// need more memory than the limit (core/limits.h; unless `force`), with both figures in the
// message, which begins with `what`.
void requireMemoryForBand(double area, double voxelSize, double halfWidth, double bytesPerVoxel,
                          bool force, const std::string& what = "the start shape");

} // namespace sweepers
