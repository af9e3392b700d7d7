// SPDX-License-Identifier: Apache-2.0
// Making narrow-band level sets: the document's lattice, spheres, closed meshes, and the
// metadata every grid Sweepers writes carries.
#pragma once

#include <vector>

#include "levelset/interrupt.h"
#include "vdb/vdb.h"

namespace sweepers {

// Half-widths below this leave cubes that straddle the surface without an active corner,
// which the mesher and the renormalization rely on.
constexpr double kMinHalfWidth = 2.0;

// The transform of every grid the engine creates: voxel size h, voxel centres at
// (i + 1/2) h. No voxel centre lies on a coordinate plane, so a sheet squeezed onto a
// mirror plane thinner than a voxel leaves the grid instead of surviving as a one-voxel
// membrane, and a symmetric shape is sampled symmetrically.
openvdb::math::Transform::Ptr documentTransform(double voxelSize);

// Sphere of the given radius, as a narrow band of `halfWidth` voxels on each side.
GridPtr makeSphere(const Eigen::Vector3d& center, double radius, double voxelSize,
                   double halfWidth);

// Level set of a closed triangle mesh (vertices in world units); throws Cancelled when
// `interrupter` stops it.
GridPtr levelSetFromMesh(const std::vector<Eigen::Vector3f>& vertices,
                         const std::vector<Eigen::Vector3i>& triangles, double voxelSize,
                         double halfWidth, Interrupter* interrupter = nullptr);

// Names the grid "surface" and stamps the metadata of the file contract (creator:
// "sweepers VERSION", half_width), and makes its background read back as at least its
// half-width in voxels (bandBackground).
void markAsDocument(Grid& grid);

} // namespace sweepers
