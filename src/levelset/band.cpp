#include "levelset/band.h"

#include <openvdb/tools/Diagnostics.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "levelset/stencils.h"

namespace sweepers {

bool nextToCrossing(const Grid::ConstAccessor& acc, const openvdb::Coord& ijk, float v) {
    for (int a = 0; a < 3; ++a)
        for (int d : {-1, 1}) {
            openvdb::Coord n = ijk;
            n[a] += d;
            if ((acc.getValue(n) < 0.0f) != (v < 0.0f)) return true;
        }
    return false;
}

BandReport checkBand(const Grid& grid) {
    BandReport r;
    openvdb::tools::CheckLevelSet<Grid> check(grid);
    r.vdbCheck = check.check(/*updateMask=*/false);
    const double h = grid.voxelSize()[0];
    const float limit = float(grid.background() + h);
    openvdb::tree::LeafManager<const Grid::TreeType> leaves(grid.tree());
    struct Counts {
        std::size_t active = 0, near = 0, unit = 0, beyond = 0;
    };
    const Counts c = tbb::parallel_reduce(
        leaves.leafRange(), Counts(),
        [&](const auto& range, Counts acc) {
            auto acc_ = grid.getConstAccessor();
            for (auto leaf = range.begin(); leaf; ++leaf) {
                for (auto it = leaf->cbeginValueOn(); it; ++it) {
                    ++acc.active;
                    const float v = *it;
                    if (std::abs(v) > limit) ++acc.beyond;
                    const openvdb::Coord ijk = it.getCoord();
                    if (!nextToCrossing(acc_, ijk, v)) continue;
                    ++acc.near;
                    const double len = centralGradient(acc_, ijk, h).norm();
                    if (len >= 0.9 && len <= 1.1) ++acc.unit;
                }
            }
            return acc;
        },
        [](Counts a, const Counts& b) {
            a.active += b.active;
            a.near += b.near;
            a.unit += b.unit;
            a.beyond += b.beyond;
            return a;
        });
    r.activeVoxels = c.active;
    r.nearInterface = c.near;
    r.unitGradient = c.unit;
    r.beyondBand = c.beyond;
    return r;
}

Box activeWorldBox(const Grid& grid) {
    Box b;
    const openvdb::CoordBBox bb = grid.evalActiveVoxelBoundingBox();
    if (bb.empty()) return b;
    b.add(toEigen(grid.indexToWorld(bb.min())));
    b.add(toEigen(grid.indexToWorld(bb.max())));
    return b;
}

} // namespace sweepers
