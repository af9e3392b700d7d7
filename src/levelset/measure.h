// SPDX-License-Identifier: Apache-2.0
// What `sweepers-cli info` reports about a level set.
#pragma once

#include "core/box.h"
#include "vdb/vdb.h"

namespace sweepers {

struct LevelSetMeasures {
    double voxelSize = 0.0, halfWidth = 0.0;
    std::size_t activeVoxels = 0, leafNodes = 0, memoryBytes = 0;
    Box bounds; // world box of the active voxels
    double volume = 0.0, area = 0.0;
    int eulerCharacteristic = 0; // exact count on the voxels, see below
    int curvatureEuler = 0;      // OpenVDB's LevelSetMeasure (Gaussian curvature integral)
    int genus = 0;               // total: components - chi / 2
    std::size_t components = 0;
};

LevelSetMeasures measureLevelSet(const Grid& grid);

// The enclosed volume alone (world units), as measureLevelSet finds it: without the
// curvature integral, the Euler count and the components, which walk the whole band and
// cost more than many stroke segments.
double levelSetVolume(const Grid& grid);

// Euler characteristic of the surface, counted exactly on the grid: twice that of the
// solid made of the closed cubes around the inside voxels (phi < 0), a cubical complex
// whose vertices, edges, faces and cubes are tallied from every 2x2x2 block of voxels.
// Blocks entirely inside or outside add nothing, so only the band is visited.
// OpenVDB's LevelSetMeasure integrates Gaussian curvature instead, which drifts by a few
// units on features a few voxels across.
int topologicalEulerCharacteristic(const Grid& grid);

} // namespace sweepers
