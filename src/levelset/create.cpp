// SPDX-License-Identifier: Apache-2.0
#include "levelset/create.h"

#include <mutex>

#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/MeshToVolume.h>

#include "levelset/renormalize.h"

namespace sweepers {

void initVdb() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::math::Transform::Ptr documentTransform(double voxelSize) {
    auto xform = openvdb::math::Transform::createLinearTransform(voxelSize);
    xform->postTranslate(openvdb::Vec3d(0.5 * voxelSize));
    // Every copy of a transform (Grid::deepCopy, reading a file) rebuilds its map through an
    // affine matrix, which moves a voxel size like 1/24 by one unit in the last place; a
    // second copy changes nothing. Documents start from that settled form, so a grid and its
    // copies (a checkpoint read back, an undo snapshot) sample at the very same points and
    // sculpt to the same voxels.
    return xform->copy();
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
    // OpenVDB's band misses voxels up to a voxel inside its edge (its closing smoothing
    // raises distances near the edges between triangles past the half-width, and its
    // expansion leaves gaps without it): marched again from the surface, it holds every voxel
    // nearer the surface than its edge, as a sculpted band does.
    RenormalizeOptions whole;
    whole.interrupter = interrupter;
    renormalize(*g, whole);
    return g;
}

void markAsDocument(Grid& grid) {
    // A band of the half-width its background says, as the float that holds it reads back:
    // tools that require a band of some width (OpenVDB's checkLevelSet, its trackers and
    // filters) divide the background by the voxel size. Raised by a unit in the last place
    // where needed; only inactive values change.
    const float background = bandBackground(grid.voxelSize()[0], halfWidthOf(grid));
    if (grid.background() < background)
        openvdb::tools::changeLevelSetBackground(grid.tree(), background);
    grid.setName("surface");
    grid.setGridClass(openvdb::GRID_LEVEL_SET);
    grid.insertMeta("creator", openvdb::StringMetadata("sweepers " SWEEPERS_VERSION));
    grid.insertMeta("half_width", openvdb::FloatMetadata(float(halfWidthOf(grid))));
}

} // namespace sweepers
