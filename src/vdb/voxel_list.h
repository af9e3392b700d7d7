// SPDX-License-Identifier: Apache-2.0
// A voxel set listed leaf by leaf: each leaf's origin and its voxels as words (leafwords). A
// leaf may be listed more than once: its voxels are those of all its entries. A segment's
// working sets are kept so, where they are only read a leaf at a time: as trees, each of
// their thousands of leaves was made and freed on its own.
#pragma once

#include <array>
#include <vector>

#include <openvdb/math/Coord.h>

#include "vdb/leaf_words.h"

namespace sweepers {

struct LeafVoxels {
    openvdb::Coord origin;
    leafwords::Words words;
};
using VoxelList = std::vector<LeafVoxels>;

// A value for voxels of some leaves, listed leaf by leaf (each leaf once): NaN where a voxel
// has none.
struct LeafValues {
    openvdb::Coord origin;
    std::array<float, 512> values;
};
using VoxelValues = std::vector<LeafValues>;

} // namespace sweepers
