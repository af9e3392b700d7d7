// SPDX-License-Identifier: Apache-2.0
// OpenVDB types the engine uses, and conversions to and from the Eigen types of the math
// core. Everything from levelset/ up includes this instead of OpenVDB directly.
#pragma once

#include <cmath>
#include <limits>

#include <Eigen/Core>
#include <openvdb/openvdb.h>

#include "vdb/vdb_instances.h"

namespace sweepers {

using Grid = openvdb::FloatGrid;
using GridPtr = Grid::Ptr;
using LeafNode = Grid::TreeType::LeafNodeType;

inline Eigen::Vector3d toEigen(const openvdb::Vec3d& v) {
    return {v.x(), v.y(), v.z()};
}
inline openvdb::Vec3d toVdb(const Eigen::Vector3d& v) {
    return {v.x(), v.y(), v.z()};
}

// Where a grid puts its voxels, for loops that place many: the grids this program makes
// place them by a scale and a translation, whose map's functions are final (so they inline
// here, where the transform's own calls are virtual); any other map goes through the
// transform.
class VoxelPlacement {
  public:
    explicit VoxelPlacement(const openvdb::math::Transform& xform)
        : xform_(xform),
          scaled_(dynamic_cast<const openvdb::math::ScaleTranslateMap*>(xform.baseMap().get())) {}
    openvdb::Vec3d toWorld(const openvdb::Vec3d& ijk) const {
        return scaled_ ? scaled_->applyMap(ijk) : xform_.indexToWorld(ijk);
    }
    openvdb::Vec3d toIndex(const openvdb::Vec3d& p) const {
        return scaled_ ? scaled_->applyInverseMap(p) : xform_.worldToIndex(p);
    }

  private:
    const openvdb::math::Transform& xform_;
    const openvdb::math::ScaleTranslateMap* scaled_;
};

// Half-width of a level set's band in voxels, from its background value.
// The background is a float: background / voxel size misses the half-width set by a unit or
// so in the seventh digit (2.99999993 voxels at voxel size 0.01), and a band widened by
// ceil(needed - half-width) voxels would then get one more ring. Half-widths are whole or
// simple fractions of a voxel: the quotient is rounded to 1/1024 of a voxel.
inline double halfWidthOf(const Grid& grid) {
    return std::round(double(grid.background()) / grid.voxelSize()[0] * 1024.0) / 1024.0;
}

// The background of a band `halfWidth` voxels wide: the float nearest halfWidth x voxel
// size, or the next one up where that one, divided by the voxel size as OpenVDB's checks
// and tools read it back, falls short of the half-width (0.06f / 0.02 is 2.99999993).
inline float bandBackground(double voxelSize, double halfWidth) {
    float b = float(halfWidth * voxelSize);
    while (double(b) / voxelSize < halfWidth)
        b = std::nextafter(b, std::numeric_limits<float>::infinity());
    return b;
}

// Makes sure OpenVDB's grid registry is set up (idempotent, thread-safe).
void initVdb();

} // namespace sweepers
