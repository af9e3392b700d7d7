// The files of a film (sweepers-cli animate, sculpt/film.h): one VDB per frame, named by a
// pattern whose run of '#' is the frame number padded with zeros to its length
// (NAME_####.vdb: Blender's default for volume sequences), each holding the level set
// "surface" stamped with the frame, its time, the frame rate and the script it came from,
// and optionally a fog volume beside it for renderers that want a density.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "io/atomic_file.h"
#include "levelset/vdb.h"

namespace sweepers {

// Throws std::invalid_argument, saying what is wrong, for a pattern without exactly one
// run of '#'.
void checkFramePattern(const std::string& pattern);
// The pattern with frame `frame` in place of its '#' (more digits than '#' when needed).
std::string framePath(const std::string& pattern, std::size_t frame);

struct FrameStamp {
    int frame = 0;
    double time = 0.0; // seconds
    double fps = 0.0;
    std::string script;     // scriptDigest of the script played
    double voxelSize = 0.0; // of the level set (read back; not written as a stamp)
};

// A digest of a script's text: 16 hex digits (64-bit FNV-1a), the same on every machine.
std::string scriptDigest(const std::string& text);

// Frame `stamp.frame`: the level set with the stamp as metadata (frame, time, fps, script)
// and, when fogName is not empty, a fog volume of that name (0 outside, rising across the
// inside half of the band to 1 deep inside: openvdb::tools::sdfToFogVolume). Written and
// flushed, not yet in place (io/atomic_file.h).
AtomicWrite prepareFrame(const Grid& grid, const FrameStamp& stamp, const std::string& fogName,
                         const std::string& path);

// The stamp of a frame file and its voxel size (read in a child process,
// io/isolated_read.h); nullopt when the file holds no usable level set or its level set no
// stamp.
std::optional<FrameStamp> readFrameStamp(const std::string& path);

} // namespace sweepers
