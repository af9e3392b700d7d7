#include "levelset/level_set.h"

#include <atomic>
#include <mutex>

#include <openvdb/tools/Diagnostics.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

namespace sweepers {

void initVdb() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::math::Transform::Ptr documentTransform(double voxelSize) {
    auto xform = openvdb::math::Transform::createLinearTransform(voxelSize);
    xform->postTranslate(openvdb::Vec3d(0.5 * voxelSize));
    return xform;
}

GridPtr makeSphere(const Eigen::Vector3d& center, double radius, double voxelSize,
                   double halfWidth) {
    initVdb();
    // OpenVDB builds it on the plain lattice; shifting the centre by half a voxel there and
    // then the lattice by half a voxel puts it back where it belongs.
    const Eigen::Vector3d c = center - Eigen::Vector3d::Constant(0.5 * voxelSize);
    GridPtr g = openvdb::tools::createLevelSetSphere<Grid>(
        float(radius), openvdb::Vec3f(float(c.x()), float(c.y()), float(c.z())), float(voxelSize),
        float(halfWidth));
    g->setTransform(documentTransform(voxelSize));
    markAsDocument(*g);
    return g;
}

GridPtr levelSetFromMesh(const std::vector<Eigen::Vector3f>& vertices,
                         const std::vector<Eigen::Vector3i>& triangles, double voxelSize,
                         double halfWidth, Interrupter* interrupter) {
    initVdb();
    const auto xform = documentTransform(voxelSize);
    std::vector<openvdb::Vec3s> points; // world space
    points.reserve(vertices.size());
    for (const auto& v : vertices)
        points.emplace_back(v.x(), v.y(), v.z());
    std::vector<openvdb::Vec3I> tris;
    tris.reserve(triangles.size());
    for (const auto& t : triangles)
        tris.emplace_back(t.x(), t.y(), t.z());
    Interrupter never;
    Interrupter& stop = interrupter ? *interrupter : never;
    GridPtr g = openvdb::tools::meshToLevelSet<Grid>(stop, *xform, points, tris, float(halfWidth));
    // OpenVDB returns what it had when interrupted: not a level set to keep.
    pollInterrupt(interrupter);
    markAsDocument(*g);
    return g;
}

void markAsDocument(Grid& grid) {
    grid.setName("surface");
    grid.setGridClass(openvdb::GRID_LEVEL_SET);
    grid.insertMeta("creator", openvdb::StringMetadata("sweepers " SWEEPERS_VERSION));
    grid.insertMeta("half_width", openvdb::FloatMetadata(float(halfWidthOf(grid))));
}

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
                    bool crossing = false;
                    float g[3];
                    for (int a = 0; a < 3; ++a) {
                        openvdb::Coord lo = ijk, hi = ijk;
                        lo[a] -= 1;
                        hi[a] += 1;
                        const float vl = acc_.getValue(lo), vh = acc_.getValue(hi);
                        crossing = crossing || (vl < 0) != (v < 0) || (vh < 0) != (v < 0);
                        g[a] = float((vh - vl) / (2 * h));
                    }
                    if (!crossing) continue;
                    ++acc.near;
                    const double len = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
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
