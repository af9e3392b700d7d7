// SPDX-License-Identifier: Apache-2.0
// Analytic level sets for the engine tests, built voxel by voxel from exact distances.
#pragma once

#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <openvdb/tools/SignedFloodFill.h>

#include "io/film_files.h"
#include "levelset/create.h"

namespace sweepers::test {

// Narrow band of the given signed distance function over the index box.
inline GridPtr gridFromSdf(const std::function<double(const Eigen::Vector3d&)>& sdf,
                           double voxelSize, double halfWidth, const openvdb::CoordBBox& box) {
    initVdb();
    GridPtr g = Grid::create(float(voxelSize * halfWidth));
    g->setTransform(documentTransform(voxelSize));
    auto acc = g->getAccessor();
    for (auto it = box.begin(); it; ++it) {
        const double d = sdf(toEigen(g->indexToWorld(*it)));
        if (std::abs(d) < voxelSize * halfWidth) acc.setValueOn(*it, float(d));
    }
    openvdb::tools::signedFloodFill(g->tree());
    markAsDocument(*g);
    return g;
}

inline double torusSdf(const Eigen::Vector3d& p, double R, double r) {
    const double q = std::hypot(p.x(), p.y()) - R;
    return std::hypot(q, p.z()) - r;
}

// Every voxel of the union of both grids' active boxes (grown by a leaf): same value,
// same state. 0 when the grids are identical there.
inline std::size_t differingVoxels(const Grid& a, const Grid& b) {
    openvdb::CoordBBox box = a.evalActiveVoxelBoundingBox();
    box.expand(b.evalActiveVoxelBoundingBox());
    box.expand(8);
    auto ca = a.getConstAccessor();
    auto cb = b.getConstAccessor();
    std::size_t n = 0;
    for (auto it = box.begin(); it; ++it)
        n += ca.getValue(*it) != cb.getValue(*it) || ca.isValueOn(*it) != cb.isValueOn(*it);
    return n;
}

// The voxels whose value (to the bit) or state differ, the tiles' values included: 0 when
// the grids are the same grid.
inline std::size_t differingBits(const Grid& a, const Grid& b) {
    std::size_t n = 0;
    const auto count = [&](const Grid& x, const Grid& y, bool both) {
        const auto acc = y.getConstAccessor();
        for (auto it = x.cbeginValueAll(); it; ++it) {
            openvdb::CoordBBox box;
            it.getBoundingBox(box);
            const float v = *it;
            const bool on = it.isValueOn();
            // A tile is compared at its first voxel (a tile against leaves differs there, or
            // at one of the leaves' voxels, which the other side's walk finds).
            const openvdb::Coord c = box.min();
            const float w = acc.getValue(c);
            const bool different = std::memcmp(&v, &w, sizeof v) != 0 || on != acc.isValueOn(c);
            if (different && (both || !it.isVoxelValue())) ++n;
        }
    };
    count(a, b, true);
    count(b, a, false);
    return n;
}

// The voxels active in either grid whose value (to the bit) or state differs, that lie in
// none of `boxes`.
inline std::size_t changedOutside(const Grid& a, const Grid& b,
                                  const std::vector<openvdb::CoordBBox>& boxes) {
    openvdb::MaskTree inside;
    for (const openvdb::CoordBBox& box : boxes)
        inside.sparseFill(box, true, true);
    openvdb::CoordBBox all = a.evalActiveVoxelBoundingBox();
    all.expand(b.evalActiveVoxelBoundingBox());
    all.expand(8);
    auto ca = a.getConstAccessor();
    auto cb = b.getConstAccessor();
    openvdb::tree::ValueAccessor<const openvdb::MaskTree> in(inside);
    std::size_t n = 0;
    for (auto it = all.begin(); it; ++it) {
        const bool onA = ca.isValueOn(*it), onB = cb.isValueOn(*it);
        const float va = ca.getValue(*it), vb = cb.getValue(*it);
        n += (onA || onB) && (std::memcmp(&va, &vb, sizeof va) != 0 || onA != onB) &&
             !in.isValueOn(*it);
    }
    return n;
}

// A digest of every value of the grid (voxels and tiles, to the bit), its state, and where it
// lies: the films' 16 hex digits (64-bit FNV-1a, io/film_files.h) over the tree's walk. Two
// grids with the same digest hold the same values; a grid written before a change of the code
// and one written after it are compared by their digests alone.
inline std::string gridDigest(const Grid& g) {
    std::string bytes;
    for (auto it = g.cbeginValueAll(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        const float v = *it;
        const std::int32_t at[5] = {c.x(), c.y(), c.z(), int(it.getDepth()), int(it.isValueOn())};
        bytes.append(reinterpret_cast<const char*>(at), sizeof at);
        bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
    }
    return scriptDigest(bytes);
}

} // namespace sweepers::test
