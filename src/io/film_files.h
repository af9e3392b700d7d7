// SPDX-License-Identifier: Apache-2.0
// The files of a film (sweepers-cli animate, sculpt/film.h): one VDB per frame, named by a
// pattern whose run of '#' is the frame number padded with zeros to its length
// (NAME_####.vdb: Blender's default for volume sequences), each holding the level set
// "surface" stamped with the frame, its time, the frame rate and the script it came from,
// and optionally a fog volume beside it for renderers that want a density.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "io/atomic_file.h"
#include "sculpt/film.h"
#include "vdb/vdb.h"

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
    std::string script;     // what the frame is made of (frameDigests)
    double voxelSize = 0.0; // of the level set (read back; not written as a stamp)
};

// A digest of a script's text: 16 hex digits (64-bit FNV-1a), the same on every machine.
std::string scriptDigest(const std::string& text);

// What each frame of the film of a script (its text, as parsed into `script`) is made of,
// as a digest: the script's grid and start, each stroke finished by the frame's time with
// its duration, the stroke the frame falls in and the time in it, the frame's time, and
// `extra` (what else a frame file holds). A keyed stroke counts by the keys its spline
// depends on there (the first, and the two before and the two after the time), and once
// finished by its first and last. Element n is frame n's (element 0 is unused). So an
// edited key changes the digests of the frames its spline spans only, an edited stroke
// those from its start on.
std::vector<std::string> frameDigests(const std::string& scriptText, const StrokeScript& script,
                                      const FilmTiming& timing, const std::string& extra = "");

// What a frame file holds besides its level set, and at what precision.
struct FrameFileOptions {
    // When not empty, a fog volume of that name (0 outside, rising across the inside half of
    // the band to 1 deep inside: openvdb::tools::sdfToFogVolume).
    std::string fog;
    bool half = false; // the grids' values as 16-bit floats (LevelSetWriteOptions::half)
};

// Frame `stamp.frame`: the level set with the stamp as metadata (frame, time, fps, script)
// and what `options` asks. Written and flushed, not yet in place (io/atomic_file.h).
AtomicWrite prepareFrame(const Grid& grid, const FrameStamp& stamp, const std::string& path,
                         const FrameFileOptions& options = {});

// The stamp of a frame file and its voxel size (read in a child process,
// io/isolated_read.h); nullopt when the file holds no usable level set or its level set no
// stamp.
std::optional<FrameStamp> readFrameStamp(const std::string& path);

} // namespace sweepers
