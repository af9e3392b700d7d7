// Dilation of a voxel mask by a cube: every voxel within `radius` steps along each axis of
// an active one becomes active (what `radius` rounds of 26-neighbour dilation give).
//
// A sculpting segment dilates two brush-sized masks by the band's half-width. The cube is
// separable, so it is done as three one-dimensional dilations on the 64-bit words of the
// leaf masks, rather than `radius` rounds over all 26 neighbours. The leaves are indexed by
// their place in a box of leaves, so each one reads its neighbours by an array lookup, and
// they are dilated in parallel.
#pragma once

#include <openvdb/openvdb.h>

namespace sweepers {

// Dilates the active voxels of the leaves of `tree` by the cube of half-side `radius`
// (radius >= 0). Active tiles are left as they are.
void dilateByCube(openvdb::MaskTree& tree, int radius);

} // namespace sweepers
