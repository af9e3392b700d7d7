// OpenVDB types the engine uses, and conversions to and from the Eigen types of the math
// core. Everything from levelset/ up includes this instead of OpenVDB directly.
#pragma once

#include <Eigen/Core>
#include <openvdb/openvdb.h>

namespace sweepers {

using Grid = openvdb::FloatGrid;
using GridPtr = Grid::Ptr;

inline Eigen::Vector3d toEigen(const openvdb::Vec3d& v) {
    return {v.x(), v.y(), v.z()};
}
inline openvdb::Vec3d toVdb(const Eigen::Vector3d& v) {
    return {v.x(), v.y(), v.z()};
}

// Half-width of a level set's band in voxels, from its background value.
inline double halfWidthOf(const Grid& grid) {
    return double(grid.background()) / grid.voxelSize()[0];
}

// Makes sure OpenVDB's grid registry is set up (idempotent, thread-safe).
void initVdb();

} // namespace sweepers
