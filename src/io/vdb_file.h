// SPDX-License-Identifier: Apache-2.0
// VDB files (docs/files.md): one FloatGrid named "surface", class level
// set, linear transform with the voxel size, background = half-width x voxel size,
// negative inside, metadata creator / voxel_size / half_width. Reading accepts any float
// level set of any name: the one named, or else the first usable one in the file (a level
// set Sweepers cannot use does not hide a good one after it), and says why it refuses
// anything else.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "io/atomic_file.h"
#include "io/input_file.h"
#include "vdb/vdb.h"

namespace sweepers {

// A level set read from a file, and what else the file holds.
struct LevelSetFile {
    GridPtr grid;                   // named "surface", whatever its name in the file
    std::string name;               // its name in the file
    std::vector<std::string> grids; // every grid of the file: 'name' (type, class)
    std::size_t levelSets = 0;      // how many of them are float level sets
};

// Reads the level set named `gridName` (empty: the first usable one) in a child process
// (io/isolated_read.h): a damaged file cannot crash or hang the caller. Throws FileError
// saying what is wrong.
LevelSetFile readLevelSetFile(const std::string& path, const std::string& gridName = "");
GridPtr readLevelSet(const std::string& path, const std::string& gridName = "");
// The reader itself, in this process: for files we wrote, and for that child.
LevelSetFile readLevelSetInProcess(const std::string& path, const std::string& gridName = "");
// Every grid of a VDB file, read whole (no memory map); FileError when it is not readable.
openvdb::GridPtrVecPtr readAllGrids(const std::string& path);
// A grid as messages name it: 'name' (type, class).
std::string describeGrid(const openvdb::GridBase& grid);
// " (it holds 'a' (float, level set), ...)" for the grids so described.
std::string holdsClause(const std::vector<std::string>& grids);
// How a level set is written: what joins it in the file, and at what precision.
struct LevelSetWriteOptions {
    openvdb::MetaMap meta;       // joins the level set's metadata
    openvdb::GridCPtrVec beside; // grids that follow it in the file
    // Values stored as 16-bit floats (OpenVDB's save-float-as-half flag on the ordinary float
    // grid, which every reader turns back into 32-bit floats): files a third smaller, each
    // value rounded by at most 1/2048 of itself or of a voxel, whichever is larger
    // (docs/files.md). Off: the exact values, which a history's guarantees (docs/engine.md)
    // are about.
    bool half = false;
};
// Why a level set at this voxel size and half-width cannot be written with 16-bit floats, in
// the user's words, or "" when it can: its band reaches past the largest 16-bit float, or its
// voxels are so small that values near the surface lose the relative precision above.
std::string halfPrecisionProblem(double voxelSize, double halfWidth);
// Atomic (io/atomic_file.h): a failed write, a full disk included, keeps the old file.
void writeLevelSet(const Grid& grid, const std::string& path,
                   const LevelSetWriteOptions& options = {});
// The same, written and flushed but not yet in place: commit() puts it there.
AtomicWrite prepareLevelSet(const Grid& grid, const std::string& path,
                            const LevelSetWriteOptions& options = {});
// The level set as prepareLevelSet writes it, as the bytes of an in-memory VDB stream
// (openvdb::io::Stream), which pyopenvdb's grids unpickle.
std::string levelSetStream(const Grid& grid);
// Any grids, in OpenVDB's file format, written and flushed but not yet in place.
AtomicWrite prepareGrids(const openvdb::GridCPtrVec& grids, const std::string& path);

} // namespace sweepers
