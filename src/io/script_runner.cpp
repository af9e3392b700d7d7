#include "io/script_runner.h"

#include <chrono>

#include "io/mesh_file.h"
#include "io/vdb_file.h"
#include "levelset/level_set.h"
#include "mesh/marching_cubes.h"

namespace sweepers {

std::string directoryOf(const std::string& path) {
    const auto slash = path.find_last_of('/');
    if (slash == std::string::npos) return ".";
    return slash == 0 ? "/" : path.substr(0, slash);
}

GridPtr makeStartGrid(const StrokeScript& script, const std::string& scriptDir,
                      const RunOptions& options) {
    const double h = options.voxelSize > 0 ? options.voxelSize : script.grid.voxelSize;
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
        if (options.voxelSize > 0 && std::abs(g->voxelSize()[0] - h) > 1e-9 * h) {
            // Resample to the requested voxel size through a mesh of the surface is lossy;
            // refuse instead of guessing.
            throw ScriptError(resolve(s.file) + ": its voxel size differs from --voxel-size");
        }
        return g;
    }
    case StartShape::Kind::Mesh: {
        const TriangleMesh m = readMesh(resolve(s.file));
        return levelSetFromMesh(m.positions, m.triangles, h, hw);
    }
    }
    return nullptr;
}

void requireApplicable(const StrokeScript& script, const std::string& name) {
    for (std::size_t i = 0; i < script.strokes.size(); ++i)
        if (std::holds_alternative<SwirlStroke>(script.strokes[i]))
            throw ScriptError(name + ": /strokes/" + std::to_string(i) +
                              ": swirl strokes are not supported by this build yet");
}

std::vector<SegmentReport> applyStrokes(Grid& grid, const StrokeScript& script,
                                        const RunOptions& options, const Progress& progress,
                                        const std::function<void(std::size_t)>& after) {
    std::vector<Sweep> sweeps;
    std::size_t total = 0;
    for (const Stroke& s : script.strokes) {
        sweeps.push_back(toSweep(std::get<SweepStroke>(s)));
        total += sweeps.back().segmentCount();
    }
    std::vector<SegmentReport> reports;
    std::size_t done = 0;
    SurfaceMesher mesher;
    if (options.remesh) mesher.rebuild(grid);
    for (std::size_t i = 0; i < sweeps.size(); ++i) {
        for (std::size_t k = 0; k < sweeps[i].segmentCount(); ++k) {
            const auto t0 = std::chrono::steady_clock::now();
            const SweepSegment seg(sweeps[i], k);
            SegmentReport r;
            r.stroke = i;
            r.segment = k;
            r.stats = advectSegment(grid, seg, options.advect);
            const auto t1 = std::chrono::steady_clock::now();
            r.seconds = std::chrono::duration<double>(t1 - t0).count();
            if (options.remesh) {
                r.remeshedLeaves = mesher.update(grid, r.stats.touched);
                r.meshSeconds =
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
            }
            reports.push_back(r);
            if (progress) progress(++done, total);
        }
        if (after) after(i);
    }
    return reports;
}

} // namespace sweepers
