#include "io/start_grid.h"

#include <cmath>

#include "io/mesh_file.h"
#include "io/stroke_script.h"
#include "io/vdb_file.h"
#include "levelset/create.h"

namespace sweepers {

GridPtr makeStartGrid(const StrokeScript& script, const std::string& scriptDir, double voxelSize,
                      Interrupter* interrupter) {
    const double h = voxelSize > 0 ? voxelSize : script.grid.voxelSize;
    const double hw = script.grid.halfWidth;
    if (hw < kMinHalfWidth)
        throw ScriptError("the band half-width must be at least 2 voxels for meshing");
    const StartShape& s = script.start;
    auto resolve = [&](const std::string& f) { return f.front() == '/' ? f : scriptDir + "/" + f; };
    switch (s.kind) {
    case StartShape::Kind::Sphere:
        if (s.radius / h > 1e5 || s.radius / h < 1.5)
            throw ScriptError("a sphere of radius " + std::to_string(s.radius) + " at voxel size " +
                              std::to_string(h) + " is " + std::to_string(s.radius / h) +
                              " voxels across; use 1.5 to 100000");
        return makeSphere(s.center, s.radius, h, hw);
    case StartShape::Kind::Vdb: {
        GridPtr g = readLevelSet(resolve(s.file));
        if (voxelSize > 0 && std::abs(g->voxelSize()[0] - h) > 1e-9 * h) {
            // Resample to the requested voxel size through a mesh of the surface is lossy;
            // refuse instead of guessing.
            throw ScriptError(resolve(s.file) + ": its voxel size differs from --voxel-size");
        }
        return g;
    }
    case StartShape::Kind::Mesh: {
        const TriangleMesh m = readMesh(resolve(s.file));
        return levelSetFromMesh(m.positions, m.triangles, h, hw, interrupter);
    }
    }
    return nullptr;
}

} // namespace sweepers
