// Renormalization of a narrow-band level set by the fast marching method (thesis 5.3.3,
// [Bae01]): after a deformation the values near the surface still locate it, but are no
// longer distances. Fast marching rebuilds |grad phi| = 1 outward from the surface:
//
//  1. seeds: every voxel with a face neighbour of the other sign gets the distance to the
//     crossings along each axis (linear interpolation of phi), combined as the distance to
//     the plane through them. The sign of every voxel is kept, so the interface does not
//     move and features one voxel thin survive.
//  2. march inside and outside in increasing |phi| with the first-order upwind stencil or
//     the second-order one (HAFMM) where two upwind neighbours are known.
//  3. voxels past the half-width are deactivated and set to +-background.
//
// Only a box of the grid is recomputed; the voxels around it keep their values and act as
// fixed boundary values.
#pragma once

#include "levelset/vdb.h"

namespace sweepers {

enum class FmmOrder { First = 1, Second = 2 };

struct FmmStats {
    std::size_t seeds = 0;
    std::size_t marched = 0; // voxels accepted by the march (seeds excluded)
};

// Recomputes the distances of the voxels inside `region` (index space). The result is a
// valid narrow band of the grid's half-width there; the tree is pruned afterwards.
FmmStats renormalize(Grid& grid, const openvdb::CoordBBox& region,
                     FmmOrder order = FmmOrder::Second);

// Renormalizes the whole active band.
FmmStats renormalizeAll(Grid& grid, FmmOrder order = FmmOrder::Second);

} // namespace sweepers
