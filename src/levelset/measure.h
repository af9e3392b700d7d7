// What `sweepers-cli info` reports about a level set.
#pragma once

#include "core/box.h"
#include "levelset/vdb.h"

namespace sweepers {

struct LevelSetMeasures {
    double voxelSize = 0.0, halfWidth = 0.0;
    std::size_t activeVoxels = 0, leafNodes = 0, memoryBytes = 0;
    Box bounds; // world box of the active voxels
    double volume = 0.0, area = 0.0;
    int eulerCharacteristic = 0, genus = 0;
    std::size_t components = 0;
};

LevelSetMeasures measureLevelSet(const Grid& grid);

} // namespace sweepers
