// SPDX-License-Identifier: Apache-2.0
// Measuring a level set as a narrow band: where it crosses zero, how much of it is a true
// distance, and the box it covers.
#pragma once

#include <string>
#include <vector>

#include "core/box.h"
#include "vdb/vdb.h"

namespace sweepers {

// True when a face neighbour of voxel `offset` of `leaf` lies on the other side of the
// surface: the voxel is next to the zero crossing. Neighbours inside the leaf are read from
// its buffer, the others through `acc` (of the leaf's grid).
bool nextToCrossing(const LeafNode& leaf, openvdb::Index offset, const Grid::ConstAccessor& acc);

// The voxels of `leaf` next to the zero crossing (what nextToCrossing answers for each of
// them, active or not), in the layout of the leaf's value mask: found 64 voxels at a time
// from their signs and those of the neighbouring leaves' faces (read through `acc`).
LeafNode::NodeMaskType crossingVoxels(const LeafNode& leaf, const Grid::ConstAccessor& acc);

struct BandReport {
    std::size_t activeVoxels = 0;
    std::size_t nearInterface = 0; // active voxels within one voxel of the zero crossing
    std::size_t unitGradient = 0;  // ... of which |grad phi| lies in [0.9, 1.1]
    std::size_t beyondBand = 0;    // active voxels with |phi| > half-width + 1 voxel
    std::size_t bandHoles = 0;     // active voxels with |phi| < half-width - 1.001 voxel next
                                   // to an inactive one (the band misses a voxel it must hold)
    std::string vdbCheck;          // tools::checkLevelSet's complaint, empty when none
    double unitGradientFraction() const {
        return nearInterface ? double(unitGradient) / double(nearInterface) : 1.0;
    }
};

// Measures how well the grid is a narrow-band signed distance field.
BandReport checkBand(const Grid& grid);

// World-space box of the active voxels.
Box activeWorldBox(const Grid& grid);

// The centres of the voxels next to the zero crossing, evenly thinned to at most `most` (a
// sample of the surface, in leaf order; walks the whole grid).
std::vector<Eigen::Vector3d> surfacePoints(const Grid& grid, std::size_t most);

} // namespace sweepers
