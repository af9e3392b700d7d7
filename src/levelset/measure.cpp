#include "levelset/measure.h"

#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/LevelSetUtil.h>

#include "levelset/level_set.h"

namespace sweepers {

LevelSetMeasures measureLevelSet(const Grid& grid) {
    LevelSetMeasures m;
    m.voxelSize = grid.voxelSize()[0];
    m.halfWidth = halfWidthOf(grid);
    m.activeVoxels = grid.activeVoxelCount();
    m.leafNodes = grid.tree().leafCount();
    m.memoryBytes = grid.memUsage();
    m.bounds = activeWorldBox(grid);
    if (m.activeVoxels == 0) return m;
    openvdb::tools::LevelSetMeasure<Grid> measure(grid);
    m.volume = measure.volume(true);
    m.area = measure.area(true);
    m.eulerCharacteristic = measure.eulerCharacteristic();
    m.genus = measure.genus();
    std::vector<GridPtr> parts;
    openvdb::tools::segmentSDF(grid, parts);
    m.components = parts.size();
    return m;
}

} // namespace sweepers
