// SPDX-License-Identifier: Apache-2.0
#include "io/start_grid.h"

#include <cmath>
#include <cstdio>

#include "core/format.h"
#include "core/limits.h"

#include "io/mesh_file.h"
#include "io/stroke_script.h"
#include "io/vdb_file.h"
#include "levelset/create.h"

namespace sweepers {

void requireMemoryForBand(double area, double voxelSize, double halfWidth, double bytesPerVoxel,
                          bool force, const std::string& what) {
    // The band is 2 halfWidth voxels thick over the surface.
    const double voxels = area / (voxelSize * voxelSize) * 2.0 * halfWidth;
    if (force) return;
    char count[32];
    std::snprintf(count, sizeof count, "%.2g", voxels);
    requireMemory(voxels * bytesPerVoxel, what,
                  std::string(count) + " band voxels at voxel size " + formatNumber(voxelSize),
                  "use a coarser voxel size, --max-memory or --force");
}

void requireSphereSize(double radius, double voxelSize) {
    if (!(radius / voxelSize >= 1.5 && radius / voxelSize <= 1e5))
        throw ScriptError("a sphere of radius " + formatNumber(radius) + " at voxel size " +
                          formatNumber(voxelSize) + " is " + formatNumber(radius / voxelSize) +
                          " voxels in radius; use 1.5 to 100000");
}

void requireBuildableStart(const StrokeScript& script, double voxelSize, bool force) {
    const double h = voxelSize > 0 ? voxelSize : script.grid.voxelSize;
    const double hw = script.grid.halfWidth;
    if (hw < kMinHalfWidth)
        throw ScriptError("the band half-width must be at least 2 voxels for meshing");
    const StartShape& s = script.start;
    if (s.kind != StartShape::Kind::Sphere) return;
    requireSphereSize(s.radius, h);
    // Sculpting needs more than building the start: a script with strokes, as a run does.
    requireMemoryForBand(4.0 * M_PI * s.radius * s.radius, h, hw,
                         script.strokes.empty() ? kSphereBytesPerVoxel : kRunBytesPerVoxel, force,
                         script.strokes.empty() ? "the start shape" : "applying the script");
}

GridPtr makeStartGrid(const StrokeScript& script, const std::string& scriptDir, double voxelSize,
                      Interrupter* interrupter, bool force) {
    requireBuildableStart(script, voxelSize, force);
    const double h = voxelSize > 0 ? voxelSize : script.grid.voxelSize;
    const double hw = script.grid.halfWidth;
    const StartShape& s = script.start;
    auto resolve = [&](const std::string& f) { return f.front() == '/' ? f : scriptDir + "/" + f; };
    switch (s.kind) {
    case StartShape::Kind::Sphere:
        return makeSphere(s.center, s.radius, h, hw);
    case StartShape::Kind::Vdb: {
        // A VDB start is sculpted on its own grid. Resampling it to another voxel size or
        // band (through a mesh of the surface) would be lossy, so a script or a command line
        // that asks for another one is refused instead of being silently ignored.
        GridPtr g = readLevelSet(resolve(s.file), s.gridName);
        const double fileH = g->voxelSize()[0], fileHw = halfWidthOf(*g);
        auto refuse = [&](const std::string& what, double file, const std::string& asked,
                          double value) {
            // As many digits as tell the two apart.
            std::string a = formatNumber(file), b = formatNumber(value);
            if (a == b) a = formatPrecise(file), b = formatPrecise(value);
            throw ScriptError(resolve(s.file) + ": its " + what + " " + a + " differs from " +
                              asked + " " + b + " (a VDB start keeps its own grid: give " + a +
                              " or leave the setting out)");
        };
        // A file may hold its voxel size as a float (pyopenvdb writes it so): the same size
        // to a float's precision is the same.
        const auto same = [fileH](double h) { return std::abs(fileH - h) <= 4e-7 * h; };
        if (voxelSize > 0 && !same(voxelSize))
            refuse("voxel size", fileH, "--voxel-size", voxelSize);
        if (voxelSize <= 0 && script.grid.voxelSizeGiven && !same(script.grid.voxelSize))
            refuse("voxel size", fileH, "the script's /grid/voxel_size", script.grid.voxelSize);
        if (script.grid.halfWidthGiven && std::abs(fileHw - script.grid.halfWidth) > 1e-3)
            refuse("band half-width", fileHw, "the script's /grid/half_width",
                   script.grid.halfWidth);
        return g;
    }
    case StartShape::Kind::Mesh: {
        const TriangleMesh m = readMesh(resolve(s.file));
        requireMemoryForBand(surfaceArea(m), h, hw, kMeshBytesPerVoxel, force);
        return levelSetFromMesh(m.positions, m.triangles, h, hw, interrupter);
    }
    }
    return nullptr;
}

ExactReference::StartFunction exactStart(const StrokeScript& script, const GridPtr& start) {
    if (script.start.kind == StartShape::Kind::Sphere)
        return ExactReference::sphere(script.start.center, script.start.radius);
    return ExactReference::sampled(start->deepCopy());
}

} // namespace sweepers
