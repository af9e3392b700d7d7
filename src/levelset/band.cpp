#include "levelset/band.h"

#include <algorithm>

#include <openvdb/tools/Diagnostics.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "levelset/stencils.h"

namespace sweepers {

bool nextToCrossing(const LeafNode& leaf, openvdb::Index offset, const Grid::ConstAccessor& acc) {
    const bool inside = leaf.getValue(offset) < 0.0f;
    const openvdb::Coord local = LeafNode::offsetToLocalCoord(offset);
    for (int a = 0; a < 3; ++a) {
        const openvdb::Index stride = openvdb::Index(1) << (3 * (2 - a)); // offset = x*64+y*8+z
        for (int d : {-1, 1}) {
            const int c = local[a] + d;
            float q;
            if (c >= 0 && c < int(LeafNode::DIM)) {
                q = leaf.getValue(d > 0 ? offset + stride : offset - stride);
            } else {
                openvdb::Coord n = leaf.offsetToGlobalCoord(offset);
                n[a] += d;
                q = acc.getValue(n);
            }
            if ((q < 0.0f) != inside) return true;
        }
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
                    if (!nextToCrossing(*leaf, it.pos(), acc_)) continue;
                    const openvdb::Coord ijk = it.getCoord();
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

std::vector<Eigen::Vector3d> surfacePoints(const Grid& grid, std::size_t most) {
    std::vector<openvdb::Coord> all;
    const auto acc = grid.getConstAccessor();
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf)
        for (auto it = leaf->cbeginValueOn(); it; ++it)
            if (nextToCrossing(*leaf, it.pos(), acc)) all.push_back(it.getCoord());
    const std::size_t stride = most == 0 ? all.size() + 1 : (all.size() + most - 1) / most;
    std::vector<Eigen::Vector3d> points;
    for (std::size_t i = 0; i < all.size(); i += std::max<std::size_t>(1, stride))
        points.push_back(toEigen(grid.indexToWorld(all[i])));
    return points;
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
