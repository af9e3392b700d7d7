#include "levelset/dilate.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>

namespace sweepers {

namespace {

using Leaf = openvdb::MaskTree::LeafNodeType;
constexpr int kDim = int(Leaf::DIM); // 8
// A leaf's mask as eight words, one per x; bit y * 8 + z of word x is voxel (x, y, z).
using Bits = std::array<std::uint64_t, kDim>;
using Leaves = std::unordered_map<openvdb::Coord, Bits>;

Bits& at(Leaves& leaves, const openvdb::Coord& origin) {
    return leaves.try_emplace(origin, Bits{}).first->second;
}

// Dilation along z: within each row of eight bits, spilling into the leaves before and after.
Leaves dilateZ(const Leaves& in, int r) {
    Leaves out;
    for (const auto& [origin, bits] : in) {
        Bits& own = at(out, origin);
        Bits* before = nullptr;
        Bits* after = nullptr;
        for (int x = 0; x < kDim; ++x)
            for (int y = 0; y < kDim; ++y) {
                const std::uint32_t row = std::uint32_t(bits[x] >> (8 * y)) & 0xffu;
                if (!row) continue;
                // The row in the middle of 24 bits: the leaf before, this one, the one after.
                std::uint32_t wide = row << 8;
                for (int s = 1; s <= r; ++s)
                    wide |= (row << (8 + s)) | (row << (8 - s));
                own[x] |= std::uint64_t((wide >> 8) & 0xffu) << (8 * y);
                if (wide & 0xffu) {
                    if (!before) before = &at(out, origin.offsetBy(0, 0, -kDim));
                    (*before)[x] |= std::uint64_t(wide & 0xffu) << (8 * y);
                }
                if (wide >> 16) {
                    if (!after) after = &at(out, origin.offsetBy(0, 0, kDim));
                    (*after)[x] |= std::uint64_t(wide >> 16) << (8 * y);
                }
            }
    }
    return out;
}

// Dilation along y (rows of a word) or x (words of a leaf): unit u of the leaf spreads to
// units u - r ... u + r, those past either end landing in the neighbouring leaf.
template <int Axis> Leaves dilateRows(const Leaves& in, int r) {
    Leaves out;
    const auto unit = [](const Bits& b, int x, int u) -> std::uint64_t {
        return Axis == 1 ? (b[x] >> (8 * u)) & 0xffu : b[u];
    };
    const auto merge = [](Bits& b, int x, int u, std::uint64_t v) {
        if (Axis == 1)
            b[x] |= v << (8 * u);
        else
            b[u] |= v;
    };
    for (const auto& [origin, bits] : in) {
        Bits* leaf[3] = {nullptr, &at(out, origin), nullptr};
        // For rows (y) every word x is its own line; for words (x) there is one line.
        for (int x = 0; x < (Axis == 1 ? kDim : 1); ++x)
            for (int u = 0; u < kDim; ++u) {
                const std::uint64_t v = unit(bits, x, u);
                if (!v) continue;
                for (int t = u - r; t <= u + r; ++t) {
                    const int side = t < 0 ? 0 : (t < kDim ? 1 : 2);
                    if (!leaf[side]) {
                        openvdb::Coord o = origin;
                        o[Axis] += side == 0 ? -kDim : kDim;
                        leaf[side] = &at(out, o);
                    }
                    merge(*leaf[side], x, t - (side - 1) * kDim, v);
                }
            }
    }
    return out;
}

} // namespace

void dilateByCube(openvdb::MaskTree& tree, int radius) {
    if (radius < 0) throw std::invalid_argument("dilateByCube: a negative radius");
    if (radius == 0) return;
    Leaves leaves;
    for (auto it = tree.cbeginLeaf(); it; ++it) {
        Bits& b = leaves[it->origin()];
        for (int x = 0; x < kDim; ++x)
            b[x] = it->getValueMask().getWord<std::uint64_t>(x);
    }
    // Cubes add up: past a leaf's width, dilate one leaf's width at a time.
    for (int left = radius; left > 0; left -= kDim) {
        const int r = std::min(left, kDim);
        leaves = dilateRows<0>(dilateRows<1>(dilateZ(leaves, r), r), r);
    }
    for (const auto& [origin, bits] : leaves) {
        Leaf* leaf = tree.touchLeaf(origin);
        for (int x = 0; x < kDim; ++x)
            leaf->getValueMask().getWord<std::uint64_t>(x) |= bits[x];
    }
}

} // namespace sweepers
