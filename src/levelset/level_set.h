// Creating narrow-band level sets and checking that they stay valid ones.
#pragma once

#include <string>
#include <vector>

#include "core/box.h"
#include "levelset/interrupt.h"
#include "levelset/vdb.h"

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
// "sweepers VERSION", half_width).
void markAsDocument(Grid& grid);

// True when a face neighbour of voxel ijk (value v) lies on the other side of the surface:
// the voxel is next to the zero crossing.
bool nextToCrossing(const Grid::ConstAccessor& acc, const openvdb::Coord& ijk, float v);

struct BandReport {
    std::size_t activeVoxels = 0;
    std::size_t nearInterface = 0; // active voxels within one voxel of the zero crossing
    std::size_t unitGradient = 0;  // ... of which |grad phi| lies in [0.9, 1.1]
    std::size_t beyondBand = 0;    // active voxels with |phi| > half-width + 1 voxel
    std::string vdbCheck;          // tools::checkLevelSet's complaint, empty when none
    double unitGradientFraction() const {
        return nearInterface ? double(unitGradient) / double(nearInterface) : 1.0;
    }
};

// Measures how well the grid is a narrow-band signed distance field.
BandReport checkBand(const Grid& grid);

// World-space box of the active voxels.
Box activeWorldBox(const Grid& grid);

} // namespace sweepers
