#include "io/script_runner.h"

#include <chrono>
#include <memory>

#include "deform/inflate.h"
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

std::vector<std::unique_ptr<StepDeformation>> planStroke(const Grid& grid, const Stroke& s) {
    // Planned when the stroke comes: an inflation's reach is the shape as it is then.
    std::vector<std::unique_ptr<StepDeformation>> parts;
    const Box reach = activeWorldBox(grid).expanded(2 * grid.voxelSize()[0]);
    if (const auto* sweep = std::get_if<SweepStroke>(&s)) {
        const Sweep sw = toSweep(*sweep);
        for (std::size_t k = 0; k < sw.segmentCount(); ++k)
            parts.push_back(std::make_unique<SweepSegment>(sw, k));
    } else if (const auto* swirl = std::get_if<SwirlStroke>(&s)) {
        if (swirl->ball > 0.0)
            parts.push_back(starShapedSwirl(toSwirl(*swirl), swirl->ball, reach));
        else
            parts.push_back(std::make_unique<SwirlSegment>(toSwirl(*swirl)));
    } else {
        const auto& in = std::get<InflateStroke>(s);
        parts.push_back(std::make_unique<Inflation>(in.at, in.radius, reach));
    }
    return parts;
}

std::vector<SegmentReport> applyStrokes(Grid& grid, const StrokeScript& script,
                                        const RunOptions& options, const Progress& progress,
                                        const std::function<void(std::size_t)>& after) {
    // Segments per stroke: a sweep's segments, or one swirl ring or inflation.
    std::size_t total = 0;
    for (const Stroke& s : script.strokes)
        total += std::holds_alternative<SweepStroke>(s)
                     ? toSweep(std::get<SweepStroke>(s)).segmentCount()
                     : 1;
    std::vector<SegmentReport> reports;
    std::size_t done = 0;
    SurfaceMesher mesher;
    if (options.remesh) mesher.rebuild(grid);
    for (std::size_t i = 0; i < script.strokes.size(); ++i) {
        const auto parts = planStroke(grid, script.strokes[i]);
        for (std::size_t k = 0; k < parts.size(); ++k) {
            const auto t0 = std::chrono::steady_clock::now();
            SegmentReport r;
            r.stroke = i;
            r.segment = k;
            r.stats = advectSegment(grid, *parts[k], options.advect);
            const auto t1 = std::chrono::steady_clock::now();
            r.seconds = std::chrono::duration<double>(t1 - t0).count();
            if (options.remesh) {
                r.remeshedLeaves = mesher.update(grid, r.stats.touched);
                r.meshSeconds =
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
                r.meshVolume = mesher.enclosedVolume();
            }
            reports.push_back(r);
            if (progress) progress(++done, total);
        }
        if (after) after(i);
    }
    return reports;
}

} // namespace sweepers
