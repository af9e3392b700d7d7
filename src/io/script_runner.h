// Runs a stroke script on a level set: builds the start shape, then advects the grid
// through every segment of every stroke.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "io/stroke_script.h"
#include "levelset/advect.h"

namespace sweepers {

struct RunOptions {
    double voxelSize = 0.0; // > 0 overrides the script's grid.voxel_size
    AdvectOptions advect;
    bool remesh = false; // keep a mesh up to date after every segment, as the modeler does
};

struct SegmentReport {
    std::size_t stroke = 0, segment = 0;
    AdvectStats stats;
    double seconds = 0.0;     // advection, renormalization included
    double meshSeconds = 0.0; // incremental re-meshing of the touched leaves (when asked)
    std::size_t remeshedLeaves = 0;
    double meshVolume = 0.0; // enclosed volume of the mesh after the segment (when remeshing)
};

// Progress: (segments done, segments in all).
using Progress = std::function<void(std::size_t, std::size_t)>;

// The start grid of a script (sphere, or the vdb / mesh file relative to `scriptDir`).
GridPtr makeStartGrid(const StrokeScript& script, const std::string& scriptDir,
                      const RunOptions& options);

// The deformations of one stroke, in order: a sweep's segments, or one swirl ring or
// inflation (whose reach depends on the grid as it is when the stroke comes).
std::vector<std::unique_ptr<StepDeformation>> planStroke(const Grid& grid, const Stroke& stroke);

// Applies all strokes; calls `after` (if set) after each stroke with its index.
std::vector<SegmentReport> applyStrokes(Grid& grid, const StrokeScript& script,
                                        const RunOptions& options, const Progress& progress = {},
                                        const std::function<void(std::size_t)>& after = {});

std::string directoryOf(const std::string& path);

} // namespace sweepers
