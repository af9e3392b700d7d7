// SPDX-License-Identifier: Apache-2.0
#include "io/velocity_file.h"

#include <cmath>
#include <fstream>

#include "core/format.h"
#include "io/input_file.h"
#include "io/isolated_read.h"

namespace sweepers {

namespace {

// Why Sweepers cannot use this velocity grid, or "" when it can.
std::string unusable(const openvdb::Vec3SGrid& grid) {
    const openvdb::Mat4d m = grid.transform().baseMap()->getAffineMap()->getMat4();
    bool aligned = grid.transform().isLinear() && grid.hasUniformVoxels();
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            aligned = aligned && (r == c ? m(r, c) > 0.0 : m(r, c) == 0.0);
    if (!aligned) return "has voxels that are not cubes along the axes";
    if (!grid.background().isZero())
        return "has a background velocity that is not zero (inactive voxels must be at rest)";
    std::size_t bad = 0;
    for (auto it = grid.cbeginValueAll(); it; ++it)
        bad += !std::isfinite((*it)[0]) || !std::isfinite((*it)[1]) || !std::isfinite((*it)[2]);
    if (bad) return "holds " + std::to_string(bad) + " velocities that are not finite numbers";
    const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    if (box.empty()) return "has no active voxel: it moves nothing";
    const double samples = double(box.dim().x()) * box.dim().y() * box.dim().z();
    if (samples > kMostVelocitySamples)
        return "spans " + formatNumber(samples) +
               " voxels; Sweepers reads velocity fields of at most " +
               formatNumber(kMostVelocitySamples);
    return "";
}

} // namespace

VelocityFile readVelocityInProcess(const std::string& path, const std::string& gridName) {
    const openvdb::GridPtrVecPtr grids = readAllGrids(path);
    VelocityFile out;
    for (const openvdb::GridBase::Ptr& base : *grids) {
        const std::string what = describeGrid(*base);
        out.grids.push_back(what);
        if (out.grid || (!gridName.empty() && base->getName() != gridName)) continue;
        auto grid = openvdb::gridPtrCast<openvdb::Vec3SGrid>(base);
        if (!grid) {
            if (gridName.empty()) continue;
            std::string message = path;
            message.append(": grid ").append(what).append(" is not a velocity grid (vec3s)");
            throw FileError(message);
        }
        if (const std::string why = unusable(*grid); !why.empty()) {
            std::string message = path;
            message.append(": velocity grid '").append(grid->getName()).append("' ").append(why);
            throw FileError(message);
        }
        out.name = grid->getName();
        out.grid = grid;
    }
    if (out.grid) return out;
    const std::string holds = holdsClause(out.grids);
    if (!gridName.empty()) throw FileError(path + ": no grid named '" + gridName + "'" + holds);
    throw FileError(path + ": no velocity grid (vec3s) in the file" + holds);
}

VelocitySamples readVelocitySamples(const std::string& path, const std::string& gridName) {
    requireRegularFile(path);
    if (!std::ifstream(path).good()) throw FileError(path + ": cannot open the file");
    return velocitySamples(readVelocityInChild(path, gridName), path);
}

namespace {

// The lattice writeVelocity wrote, when the grid says so and its active voxels lie within it:
// zero samples are stored inactive, so the active voxels alone can give a smaller lattice
// (a solution whose walls are at rest loses its outer layers), and the field made of it a
// smaller support.
openvdb::CoordBBox latticeOf(const openvdb::Vec3SGrid& grid) {
    const openvdb::CoordBBox active = grid.evalActiveVoxelBoundingBox();
    const auto dims = grid.getMetadata<openvdb::Vec3IMetadata>(kLatticeDimsKey);
    if (!dims || active.empty()) return active;
    const openvdb::Vec3i d = dims->value();
    if (d.x() < 1 || d.y() < 1 || d.z() < 1) return active;
    const openvdb::CoordBBox lattice(openvdb::Coord(0),
                                     openvdb::Coord(d.x() - 1, d.y() - 1, d.z() - 1));
    return lattice.isInside(active) ? lattice : active;
}

} // namespace

VelocitySamples storedSamples(VelocitySamples samples) {
    for (Eigen::Vector3f& v : samples.values)
        if (v.isZero()) v = Eigen::Vector3f::Zero(); // -0 too: stored inactive, read as +0
    return samples;
}

VelocitySamples velocitySamples(const VelocityFile& file, const std::string& path) {
    const openvdb::Vec3SGrid& grid = *file.grid;
    // The child checked the grid; its lattice size is checked again before it is allocated.
    const openvdb::CoordBBox box = latticeOf(grid);
    if (box.empty() || double(box.dim().x()) * box.dim().y() * box.dim().z() > kMostVelocitySamples)
        throw FileError(path + ": velocity grid '" + file.name + "' " + unusable(grid));
    VelocitySamples s;
    s.dims = {box.dim().x(), box.dim().y(), box.dim().z()};
    const openvdb::Vec3d origin = grid.indexToWorld(box.min());
    s.origin = Eigen::Vector3d(origin.x(), origin.y(), origin.z());
    s.spacing = grid.voxelSize()[0];
    s.staggered = grid.getGridClass() == openvdb::GRID_STAGGERED;
    s.values.assign(s.count(), Eigen::Vector3f::Zero());
    for (auto it = grid.cbeginValueOn(); it; ++it) {
        const openvdb::Vec3s v = *it;
        openvdb::CoordBBox cover;
        it.getBoundingBox(cover);
        for (auto c = cover.begin(); c; ++c) {
            const openvdb::Coord o = *c - box.min();
            s.values[s.index(o.x(), o.y(), o.z())] = Eigen::Vector3f(v.x(), v.y(), v.z());
        }
    }
    return s;
}

void writeVelocity(const VelocitySamples& samples, const std::string& path, const std::string& name,
                   const openvdb::MetaMap& meta) {
    initVdb();
    auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    grid->setName(name);
    openvdb::math::Transform::Ptr transform =
        openvdb::math::Transform::createLinearTransform(samples.spacing);
    transform->postTranslate(
        openvdb::Vec3d(samples.origin.x(), samples.origin.y(), samples.origin.z()));
    grid->setTransform(transform);
    grid->setGridClass(samples.staggered ? openvdb::GRID_STAGGERED : openvdb::GRID_UNKNOWN);
    grid->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    auto acc = grid->getAccessor();
    for (int k = 0; k < samples.dims[2]; ++k)
        for (int j = 0; j < samples.dims[1]; ++j)
            for (int i = 0; i < samples.dims[0]; ++i) {
                const Eigen::Vector3f& v = samples.values[samples.index(i, j, k)];
                if (!v.isZero())
                    acc.setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(v.x(), v.y(), v.z()));
            }
    for (auto it = meta.beginMeta(); it != meta.endMeta(); ++it)
        grid->insertMeta(it->first, *it->second);
    grid->insertMeta(kLatticeDimsKey, openvdb::Vec3IMetadata(openvdb::Vec3i(
                                          samples.dims[0], samples.dims[1], samples.dims[2])));
    grid->insertMeta("creator", openvdb::StringMetadata("Sweepers"));
    prepareGrids(openvdb::GridCPtrVec{grid}, path).commit();
}

} // namespace sweepers
