// SPDX-License-Identifier: Apache-2.0
#include "io/baked_tool.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>
#include <tuple>

#include "core/format.h"
#include "io/mesh_file.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "io/vdb_file.h"
#include "levelset/level_set_tool.h"

namespace sweepers {

namespace fs = std::filesystem;

namespace {

struct CacheKey {
    std::string path, grid;
    double voxelSize, reach;
    fs::file_time_type modified;
    std::uintmax_t bytes;
    bool operator<(const CacheKey& o) const {
        return std::tie(path, grid, voxelSize, reach, modified, bytes) <
               std::tie(o.path, o.grid, o.voxelSize, o.reach, o.modified, o.bytes);
    }
};

// Weak: a tool lives as long as a script holds it.
std::mutex gCacheMutex;
std::map<CacheKey, std::weak_ptr<const LevelSetTool>> gCache;

std::shared_ptr<const LevelSetTool> bake(const BakedToolSource& source, const std::string& path,
                                         double reach, Interrupter* interrupter) {
    GridPtr grid;
    if (source.kind == BakedToolSource::Kind::Vdb) {
        const GridPtr levelSet = readLevelSet(path, source.gridName);
        const double h = levelSet->voxelSize()[0], hw = halfWidthOf(*levelSet);
        // The surface area the band implies, for the memory check.
        const double area = double(levelSet->activeVoxelCount()) * h * h / (2.0 * hw);
        requireMemoryForBand(area, h, 0.5 * (std::ceil(reach / h) + 5.0), kMeshBytesPerVoxel, false,
                             path + ": the tool");
        grid = bakeToolGrid(*levelSet, reach, interrupter);
    } else {
        const TriangleMesh mesh = readMesh(path); // refuses an open mesh
        const double h = source.voxelSize;
        if (!(h > 0.0)) throw ScriptError(path + ": a mesh tool needs a positive voxel size");
        // The band is `reach` wide outside and three voxels inside.
        const double halfWidth = 0.5 * (std::ceil(reach / h) + 5.0);
        requireMemoryForBand(surfaceArea(mesh), h, halfWidth, kMeshBytesPerVoxel, false,
                             path + ": the tool");
        grid = bakeToolGrid(mesh.positions, mesh.triangles, h, reach, interrupter);
    }
    try {
        return std::make_shared<LevelSetTool>(grid, fs::path(path).filename().string());
    } catch (const std::invalid_argument& e) {
        throw FileError(path + ": cannot be a tool: " + e.what());
    }
}

} // namespace

std::string resolveAgainst(const std::string& file, const std::string& baseDir) {
    if (file.empty() || file.front() == '/' || baseDir.empty()) return file;
    return baseDir + "/" + file;
}

std::shared_ptr<const ToolShape> loadBakedTool(const BakedToolSource& source,
                                               const std::string& baseDir, double size,
                                               double reach, Interrupter* interrupter) {
    if (!(reach > 0.0) || !std::isfinite(reach) || !(size > 0.0) || !std::isfinite(size))
        throw ScriptError(source.file + ": a tool needs a positive size and falloff");
    // Bands a quarter octave apart: a modeler changing its falloff by a few percent reuses
    // the tool it has (a wider band changes no distance inside the narrower one).
    reach = std::exp2(std::ceil(4.0 * std::log2(reach)) / 4.0);
    const std::string path = resolveAgainst(source.file, baseDir);
    std::error_code error;
    const fs::path absolute = fs::absolute(path, error).lexically_normal();
    const auto modified = fs::last_write_time(absolute, error);
    const std::uintmax_t bytes = error ? 0 : fs::file_size(absolute, error);
    if (error) throw FileError(path + ": cannot open the file (" + error.message() + ")");
    const bool mesh = source.kind == BakedToolSource::Kind::Mesh;
    const CacheKey key{
        absolute.string(), source.gridName, mesh ? source.voxelSize : 0.0, reach, modified, bytes};
    std::shared_ptr<const LevelSetTool> tool;
    {
        const std::lock_guard<std::mutex> lock(gCacheMutex);
        tool = gCache[key].lock();
    }
    if (!tool) {
        tool = bake(source, path, reach, interrupter);
        const std::lock_guard<std::mutex> lock(gCacheMutex);
        gCache[key] = tool;
    }
    return tool->scaled(size);
}

} // namespace sweepers
