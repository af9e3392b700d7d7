// SPDX-License-Identifier: Apache-2.0
#include "io/vdb_file.h"

#include <cmath>
#include <fstream>
#include <new>
#include <sstream>

#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/math/Half.h>
#include <openvdb/tools/ChangeBackground.h>

#include "core/format.h"
#include "core/limits.h"
#include "io/atomic_file.h"
#include "io/isolated_read.h"
#include "levelset/create.h"

namespace sweepers {

namespace {

// Values (active or not, in leaves and tiles) that are NaN or infinite.
std::size_t nonFiniteValues(const Grid& grid) {
    std::size_t bad = 0;
    for (auto it = grid.cbeginValueAll(); it; ++it)
        bad += !std::isfinite(*it);
    return bad;
}

// Why Sweepers cannot use this level set, or "" when it can.
std::string unusable(const Grid& grid) {
    if (!grid.hasUniformVoxels() || !grid.transform().isLinear())
        return "has non-uniform voxels; Sweepers needs cubic voxels";
    // A mirroring map (a negative scale) turns the level set's inside out in world space:
    // every stroke would move the wrong side.
    if (!(grid.transform().baseMap()->determinant() > 0.0))
        return "has a mirrored transform (a negative scale); Sweepers needs one that keeps "
               "left and right";
    // Far out, a float's voxel positions and a script's numbers (at most 1e5) no longer
    // reach it: refused as a script's shape would be.
    const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    if (!box.empty()) {
        const openvdb::Vec3d lo = grid.indexToWorld(box.min()), hi = grid.indexToWorld(box.max());
        for (int a = 0; a < 3; ++a)
            if (!(std::max(std::abs(lo[a]), std::abs(hi[a])) <= kLargestNumber))
                return "lies beyond 1e5 of the origin, farther than Sweepers sculpts";
    }
    const double hw = halfWidthOf(grid);
    if (!(hw >= kMinHalfWidth - 1e-6))
        return "has a band of " + formatNumber(hw) + " voxels; Sweepers needs at least 2";
    if (const std::size_t bad = nonFiniteValues(grid))
        return "holds " + std::to_string(bad) + " values that are not finite numbers";
    return "";
}

} // namespace

LevelSetFile readLevelSetFile(const std::string& path, const std::string& gridName) {
    requireRegularFile(path);
    if (!std::ifstream(path).good()) throw FileError(path + ": cannot open the file");
    return readLevelSetInChild(path, gridName);
}

GridPtr readLevelSet(const std::string& path, const std::string& gridName) {
    return readLevelSetFile(path, gridName).grid;
}

LevelSetFile readLevelSetInProcess(const std::string& path, const std::string& gridName) {
    const openvdb::GridPtrVecPtr grids = readAllGrids(path);
    LevelSetFile out;
    std::vector<std::string> refusals; // of the level sets passed over
    for (const openvdb::GridBase::Ptr& base : *grids) {
        const std::string what = describeGrid(*base);
        out.grids.push_back(what);
        GridPtr grid = base->getGridClass() == openvdb::GRID_LEVEL_SET
                           ? openvdb::gridPtrCast<Grid>(base)
                           : nullptr;
        out.levelSets += grid != nullptr;
        if (out.grid || (!gridName.empty() && base->getName() != gridName)) continue;
        if (!grid) {
            if (gridName.empty()) continue;
            std::string message = path;
            message.append(": grid ").append(what).append(" is not a float level set");
            throw FileError(message);
        }
        if (const std::string why = unusable(*grid); !why.empty()) {
            refusals.push_back("grid '" + grid->getName() + "' " + why);
            continue;
        }
        out.name = grid->getName();
        markAsDocument(*grid);
        out.grid = grid;
    }
    if (out.grid) return out;
    if (refusals.size() == 1) throw FileError(path + ": " + refusals.front());
    std::string why;
    for (const std::string& r : refusals)
        why += (why.empty() ? "" : "; ") + r;
    if (!why.empty()) throw FileError(path + ": no level set Sweepers can use (" + why + ")");
    const std::string holds = holdsClause(out.grids);
    if (!gridName.empty()) throw FileError(path + ": no grid named '" + gridName + "'" + holds);
    throw FileError(path + ": no float level set in the file" + holds);
}

openvdb::GridPtrVecPtr readAllGrids(const std::string& path) {
    initVdb();
    requireRegularFile(path);
    if (!std::ifstream(path).good()) throw FileError(path + ": cannot open the file");
    try {
        openvdb::io::File file(path);
        file.open(/*delayLoad=*/false); // no memory map, no temporary copy: read it all now
        openvdb::GridPtrVecPtr grids = file.getGrids();
        file.close();
        return grids;
    } catch (const std::bad_alloc&) {
        throw; // (in the reader's child process: its memory limit)
    } catch (const std::exception& e) {
        throw FileError(path + ": not a readable VDB file (" + e.what() + ")");
    }
}

std::string describeGrid(const openvdb::GridBase& grid) {
    return "'" + grid.getName() + "' (" + grid.valueType() + ", " +
           openvdb::GridBase::gridClassToString(grid.getGridClass()) + ")";
}

std::string holdsClause(const std::vector<std::string>& grids) {
    std::string seen;
    for (const std::string& g : grids)
        seen += (seen.empty() ? "" : ", ") + g;
    return seen.empty() ? std::string(" (it holds no grids)") : " (it holds " + seen + ")";
}

namespace {

// io::File writes through a stream of its own and does not report a failed write; this
// writes the same file format (seekable, with grid offsets, as io::File::write does) into
// the caller's stream, whose writes are checked.
class FileWriter : public openvdb::io::Archive {
  public:
    openvdb::io::Archive::Ptr copy() const override { return std::make_shared<FileWriter>(*this); }
    void writeTo(std::ostream& out, const openvdb::GridCPtrVec& grids) const {
        Archive::write(out, grids, /*seekable=*/true);
    }
};

} // namespace

namespace {

// The smallest 16-bit float at least `value` (a positive float under 65504), as a float.
float halfAtLeast(float value) {
    openvdb::math::half h(value);
    if (float(h) < value) h.setBits(static_cast<unsigned short>(h.bits() + 1));
    return float(h);
}

// The grids of a level-set file: the level set with its metadata, then `beside`.
openvdb::GridCPtrVec levelSetFileGrids(const Grid& source, const LevelSetWriteOptions& options) {
    initVdb();
    // At half precision the background (every inactive value) would round to the nearest
    // 16-bit float, below the band's half-width when the voxel size is not a power of two,
    // and OpenVDB's checks and tools would read a narrower band than the file's metadata
    // says: it is raised to the next 16-bit float up, on a copy of the grid.
    GridPtr raised;
    if (options.half)
        if (const float up = halfAtLeast(source.background()); up != source.background()) {
            raised = source.deepCopy();
            openvdb::tools::changeLevelSetBackground(raised->tree(), up);
        }
    const Grid& grid = raised ? *raised : source;
    // The file's metadata is put together on a grid without voxels and written with the
    // grid's own tree (shared, only read): a deep copy of the voxels, to add a few names,
    // held the grid's memory twice while the file was written.
    GridPtr named = grid.copyWithNewTree();
    markAsDocument(*named);
    named->insertMeta("voxel_size", openvdb::FloatMetadata(float(grid.voxelSize()[0])));
    for (auto it = options.meta.beginMeta(); it != options.meta.endMeta(); ++it)
        named->insertMeta(it->first, *it->second);
    // Always said: a grid read from a half-float file carries the flag in its metadata, and
    // would otherwise be written at half precision again unasked.
    named->setSaveFloatAsHalf(options.half);
    openvdb::GridCPtrVec grids{grid.copyReplacingMetadata(*named)};
    grids.insert(grids.end(), options.beside.begin(), options.beside.end());
    return grids;
}

} // namespace

std::string halfPrecisionProblem(double voxelSize, double halfWidth) {
    // The largest 16-bit float is 65504 and the smallest with full relative precision 2^-14:
    // a value under a voxel from the surface is only rounded relatively while a voxel is
    // larger than that.
    constexpr double kLargestHalf = 65504.0, kSmallestNormalHalf = 1.0 / 16384;
    if (voxelSize * halfWidth > kLargestHalf)
        return "16-bit floats end at 65504, within the band of " + formatNumber(halfWidth) +
               " voxels of size " + formatNumber(voxelSize) + "; write at full precision";
    if (voxelSize < kSmallestNormalHalf)
        return "16-bit floats round a voxel size under 6.1e-05 (" + formatNumber(voxelSize) +
               ") too coarsely; write at full precision";
    return "";
}

AtomicWrite prepareLevelSet(const Grid& grid, const std::string& path,
                            const LevelSetWriteOptions& options) {
    if (options.half)
        if (const std::string why = halfPrecisionProblem(grid.voxelSize()[0], halfWidthOf(grid));
            !why.empty())
            throw FileError(path + ": " + why);
    return prepareGrids(levelSetFileGrids(grid, options), path);
}

std::string levelSetStream(const Grid& grid) {
    std::ostringstream out(std::ios::binary);
    openvdb::io::Stream(out).write(levelSetFileGrids(grid, {}));
    return out.str();
}

AtomicWrite prepareGrids(const openvdb::GridCPtrVec& grids, const std::string& path) {
    initVdb();
    return AtomicWrite(path, [&](std::ostream& out) { FileWriter().writeTo(out, grids); });
}

void writeLevelSet(const Grid& grid, const std::string& path, const LevelSetWriteOptions& options) {
    prepareLevelSet(grid, path, options).commit();
}

} // namespace sweepers
