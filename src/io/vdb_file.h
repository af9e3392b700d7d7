// VDB files (the README's "Files" section): one FloatGrid named "surface", class level
// set, linear transform with the voxel size, background = half-width x voxel size,
// negative inside, metadata creator / voxel_size / half_width. Reading accepts any float
// level set (any name; the first level-set grid when there are several) and says why it
// refuses anything else.
#pragma once

#include <stdexcept>
#include <string>

#include "io/atomic_file.h"
#include "levelset/vdb.h"

namespace sweepers {

class FileError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// Reads the level set in a child process (io/isolated_read.h): a damaged file cannot crash
// or hang the caller. Throws FileError saying what is wrong.
GridPtr readLevelSet(const std::string& path);
// The reader itself, in this process: for files we wrote, and for that child.
GridPtr readLevelSetInProcess(const std::string& path);
// Atomic (io/atomic_file.h): a failed write, a full disk included, keeps the old file.
void writeLevelSet(const Grid& grid, const std::string& path);
// The same, written and flushed but not yet in place: commit() puts it there.
AtomicWrite prepareLevelSet(const Grid& grid, const std::string& path);

} // namespace sweepers
