// SPDX-License-Identifier: Apache-2.0
// Small pieces of index arithmetic on the voxel lattice, written once: rounding down to a
// block, the corners of a voxel cube, the central-difference gradient.
#pragma once

#include "vdb/vdb.h"

namespace sweepers {

// The largest multiple of n (> 0) not above v, for negative v too.
inline int floorToMultiple(int v, int n) {
    return v >= 0 ? v / n * n : -((-v + n - 1) / n) * n;
}
inline openvdb::Coord floorToMultiple(const openvdb::Coord& c, int n) {
    return {floorToMultiple(c.x(), n), floorToMultiple(c.y(), n), floorToMultiple(c.z(), n)};
}

// Corner c (0..7: bit 0 along x, bit 1 along y, bit 2 along z) of the cube of voxel
// centres whose lowest corner is `base` (the marching-cubes numbering of mesh/mc_table).
inline openvdb::Coord cubeCorner(const openvdb::Coord& base, int c) {
    return base.offsetBy(c & 1, c >> 1 & 1, c >> 2 & 1);
}

// One axis of the central-difference gradient below, from the values one voxel below and
// above.
inline float centralDifference(float below, float above, double h) {
    return float((above - below) / (2 * h));
}

// grad phi at a voxel by central differences, in world units (voxel size h): the surface
// normal of 5.17 and the unit-gradient check of a signed distance.
// `acc` is anything with getValue(Coord): a tree accessor, or a block of copied values.
template <typename Accessor>
Eigen::Vector3f centralGradient(const Accessor& acc, const openvdb::Coord& ijk, double h) {
    Eigen::Vector3f g;
    for (int a = 0; a < 3; ++a) {
        openvdb::Coord lo = ijk, hi = ijk;
        lo[a] -= 1;
        hi[a] += 1;
        g[a] = centralDifference(acc.getValue(lo), acc.getValue(hi), h);
    }
    return g;
}

} // namespace sweepers
