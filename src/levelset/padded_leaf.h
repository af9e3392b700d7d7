// SPDX-License-Identifier: Apache-2.0
// A leaf's values and the layer of voxels around it (10 x 10 x 10, x slowest): stencils that
// read a voxel's neighbours read this block instead of the tree. The 26 leaves around are
// found once (their buffers, or the one value of a tile or of empty space) and read directly.
#pragma once

#include <array>
#include <cstddef>

#include "vdb/vdb.h"

namespace sweepers {

struct PaddedLeaf {
    using Leaf = Grid::TreeType::LeafNodeType;
    std::array<float, 1000> v;
    // (x, y, z) from -1 to 8 each.
    static std::size_t index(int x, int y, int z) {
        return std::size_t(x + 1) * 100 + std::size_t(y + 1) * 10 + std::size_t(z + 1);
    }
    float at(int x, int y, int z) const { return v[index(x, y, z)]; }

    struct Around {
        std::array<const float*, 27> buffer; // (dx + 1) * 9 + (dy + 1) * 3 + dz + 1
        std::array<float, 27> value;         // where there is no leaf
    };
    static Around around(const Grid& grid, const Leaf& leaf) {
        Around a;
        const Grid::ConstAccessor acc = grid.getConstAccessor();
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    const std::size_t k =
                        std::size_t(dx + 1) * 9 + std::size_t(dy + 1) * 3 + std::size_t(dz + 1);
                    const openvdb::Coord o = leaf.origin().offsetBy(8 * dx, 8 * dy, 8 * dz);
                    const Leaf* n = grid.tree().probeConstLeaf(o);
                    a.buffer[k] = n ? n->buffer().data() : nullptr;
                    a.value[k] = n ? 0.0f : acc.getValue(o);
                }
        return a;
    }

    void load(const Around& a) {
        for (int x = -1; x <= 8; ++x) {
            const int nx = x < 0 ? 0 : x > 7 ? 2 : 1, lx = (x + 8) & 7;
            for (int y = -1; y <= 8; ++y) {
                const int ny = y < 0 ? 0 : y > 7 ? 2 : 1, ly = (y + 8) & 7;
                for (int z = -1; z <= 8; ++z) {
                    const int nz = z < 0 ? 0 : z > 7 ? 2 : 1, lz = (z + 8) & 7;
                    const std::size_t k =
                        std::size_t(nx) * 9 + std::size_t(ny) * 3 + std::size_t(nz);
                    const float* b = a.buffer[k];
                    v[index(x, y, z)] = b ? b[lx * 64 + ly * 8 + lz] : a.value[k];
                }
            }
        }
    }
};

} // namespace sweepers
