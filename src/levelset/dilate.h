// SPDX-License-Identifier: Apache-2.0
// The voxel sets of a segment's work, listed leaf by leaf (VoxelList): dilation by a cube,
// and what turns a tree into such a list and a list into a tree.
//
// Dilation by a cube: every voxel within `radius` steps along each axis of one in the set
// joins it (what `radius` rounds of 26-neighbour dilation give).
//
// A sculpting segment dilates two brush-sized sets by the band's reach. The cube is
// separable, so it is done as three one-dimensional dilations on the 64-bit words of the
// leaves, rather than `radius` rounds over all 26 neighbours. The leaves are indexed by
// their place in a box of leaves, so each one reads its neighbours by an array lookup, and
// they are dilated in parallel.
#pragma once

#include <openvdb/openvdb.h>

#include "vdb/voxel_list.h"

namespace sweepers {

// The voxels of the list dilated by the cube of half-side `radius` (>= 0), each leaf once.
VoxelList dilatedByCube(const VoxelList& from, int radius);

// The active voxels of a tree's leaves (not its tiles), listed in its order.
VoxelList listLeaves(const openvdb::MaskTree& tree);
// Adds the voxels of the list to `into`, a leaf at a time.
void uniteMasks(openvdb::MaskTree& into, const VoxelList& from);
// The same voxels, each leaf listed once (in the order of their origins).
VoxelList eachLeafOnce(VoxelList list);

} // namespace sweepers
