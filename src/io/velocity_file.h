// SPDX-License-Identifier: Apache-2.0
// Velocity fields in VDB files: a grid of float vectors (vec3s, OpenVDB's Vec3SGrid) with
// cubic voxels aligned with the axes, velocities in world units per unit of time, cell-centred
// or staggered (grid class "staggered": the x component of voxel (i, j, k) lies on its face at
// i - 1/2, as OpenVDB's staggered grids and Houdini's have it). Inactive voxels are at rest,
// so the background must be zero. What we write reads back the same.
#pragma once

#include <string>
#include <vector>

#include "deform/sampled_field.h"
#include "io/vdb_file.h"

namespace sweepers {

struct VelocityFile {
    openvdb::Vec3SGrid::Ptr grid;
    std::string name;               // its name in the file
    std::vector<std::string> grids; // every grid of the file: 'name' (type, class)
};

// The velocity grid named `gridName` (empty: the first vec3s grid), in this process. Throws
// FileError saying what is wrong: not a VDB file, no such grid, a grid of another type,
// voxels that are not cubes along the axes, values that are not finite, a background that is
// not zero, no active voxel, or a lattice of more than kMostVelocitySamples.
VelocityFile readVelocityInProcess(const std::string& path, const std::string& gridName = "");

// The samples of that grid over its active voxels' bounding box, read in a child process
// (io/isolated_read.h) so that a damaged file cannot crash or hang the caller.
VelocitySamples readVelocitySamples(const std::string& path, const std::string& gridName = "");

// The same, from a file read already (`path` for messages).
VelocitySamples velocitySamples(const VelocityFile& file, const std::string& path);

// The samples as reading what writeVelocity wrote gives them back: every zero vector +0.
VelocitySamples storedSamples(VelocitySamples samples);

constexpr double kMostVelocitySamples = 64.0 * 1024 * 1024; // 768 MB of float vectors

// Writes the samples as a vec3s grid named `name` (zero samples left inactive), atomically
// (io/atomic_file.h), with `meta` on the grid and the lattice's size (kLatticeDimsKey), so
// that reading it gives back the same lattice (storedSamples) even where its outer samples
// are zero.
inline const char* const kLatticeDimsKey = "lattice_dims";
void writeVelocity(const VelocitySamples& samples, const std::string& path, const std::string& name,
                   const openvdb::MetaMap& meta = {});

} // namespace sweepers
