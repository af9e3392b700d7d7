// SPDX-License-Identifier: Apache-2.0
#include "levelset/measure.h"

#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/parallel_reduce.h>

#include "levelset/band.h"
#include "levelset/stencils.h"

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
    m.curvatureEuler = measure.eulerCharacteristic();
    m.eulerCharacteristic = topologicalEulerCharacteristic(grid);
    std::vector<GridPtr> parts;
    openvdb::tools::segmentSDF(grid, parts);
    m.components = parts.size();
    m.genus = int(m.components) - m.eulerCharacteristic / 2;
    return m;
}

double levelSetVolume(const Grid& grid) {
    // OpenVDB's, which throws on a grid without voxels where the full measure says 0.
    return grid.activeVoxelCount() == 0 ? 0.0 : openvdb::tools::levelSetVolume(grid);
}

int topologicalEulerCharacteristic(const Grid& grid) {
    // Per block (8 voxels around one dual vertex), in eighths: 8 for the vertex if any voxel
    // is inside, -4 per incident dual edge (4 voxels) touching the inside, +2 per incident
    // dual face (2 voxels), -1 per inside voxel.
    openvdb::tree::LeafManager<const Grid::TreeType> leaves(grid.tree());
    const long eighths = tbb::parallel_reduce(
        leaves.leafRange(), 0L,
        [&](const auto& range, long sum) {
            auto acc = grid.getConstAccessor();
            for (auto leaf = range.begin(); leaf; ++leaf)
                for (auto it = leaf->cbeginValueOn(); it; ++it) {
                    const openvdb::Coord base = it.getCoord();
                    int in = 0; // bit (dx + 2 dy + 4 dz)
                    for (int c = 0; c < 8; ++c)
                        if (acc.getValue(cubeCorner(base, c)) < 0.0f) in |= 1 << c;
                    if (in == 0 || in == 255) continue;
                    long v = 8;
                    for (int a = 0; a < 3; ++a)
                        for (int side = 0; side < 2; ++side) {
                            bool edge = false;
                            for (int c = 0; c < 8; ++c)
                                edge = edge || ((c >> a & 1) == side && (in >> c & 1));
                            v -= edge ? 4 : 0;
                        }
                    for (int c3 = 0; c3 < 3; ++c3) {
                        const int a = (c3 + 1) % 3, b = (c3 + 2) % 3;
                        for (int sa = 0; sa < 2; ++sa)
                            for (int sb = 0; sb < 2; ++sb) {
                                const int c0 = (sa << a) | (sb << b);
                                const bool face = (in >> c0 & 1) || (in >> (c0 | 1 << c3) & 1);
                                v += face ? 2 : 0;
                            }
                    }
                    for (int c = 0; c < 8; ++c)
                        v -= in >> c & 1;
                    sum += v;
                }
            return sum;
        },
        std::plus<long>());
    return int(2 * eighths / 8);
}

} // namespace sweepers
