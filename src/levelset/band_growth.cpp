// SPDX-License-Identifier: Apache-2.0
#include "levelset/band_growth.h"
#include "levelset/band.h"
#include "levelset/dilate.h"
#include "levelset/resample.h"
#include "vdb/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <vector>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace sweepers {

namespace {

// Adds to `mask` (each leaf once) the inactive voxels of `box` for which
// needed(x, v, acc) holds (x the voxel's centre, v its value, acc reading the grid), and
// gives their count.
template <typename Needed>
std::size_t markInactive(const Grid& grid, const openvdb::CoordBBox& box, const Needed& needed,
                         VoxelList& mask) {
    if (box.empty()) return 0;
    const SampleSource source(grid, Grid::create()); // the grid itself, nothing copied
    tbb::enumerable_thread_specific<std::vector<openvdb::Coord>> found;
    const tbb::blocked_range<int> slabs(box.min().x(), box.max().x() + 1);
    parallelFor(slabs, [&](const auto& r) {
        const SampleSource::Accessor acc(source);
        const auto live = grid.getConstAccessor();
        auto& out = found.local();
        for (int i = r.begin(); i != r.end(); ++i)
            for (int j = box.min().y(); j <= box.max().y(); ++j)
                for (int k = box.min().z(); k <= box.max().z(); ++k) {
                    const openvdb::Coord ijk(i, j, k);
                    float v;
                    if (live.probeValue(ijk, v)) continue; // in the band already
                    if (needed(toEigen(grid.indexToWorld(ijk)), v, acc)) out.push_back(ijk);
                }
    });
    std::size_t count = 0;
    openvdb::MaskTree marked;
    openvdb::tree::ValueAccessor<openvdb::MaskTree, false> macc(marked);
    for (const auto& f : found) {
        for (const openvdb::Coord& c : f)
            macc.setValueOn(c);
        count += f.size();
    }
    const VoxelList listed = listLeaves(marked);
    mask.insert(mask.end(), listed.begin(), listed.end());
    mask = eachLeafOnce(std::move(mask)); // switching the band on wants each leaf once
    return count;
}

} // namespace

openvdb::CoordBBox indexBox(const Grid& grid, const Box& world, int pad) {
    if (world.empty()) return {};
    const openvdb::Vec3d lo = grid.worldToIndex(toVdb(world.min));
    const openvdb::Vec3d hi = grid.worldToIndex(toVdb(world.max));
    return openvdb::CoordBBox(openvdb::Coord::floor(lo).offsetBy(-pad),
                              openvdb::Coord::ceil(hi).offsetBy(pad));
}

std::size_t markOpened(const Grid& grid, const StepDeformation& seg, double shell,
                       VoxelList& mask) {
    const double beyond = shell + seg.opening() / 6.0; // how far past the rim to look
    const openvdb::CoordBBox box = indexBox(grid, seg.openedBox().expanded(beyond), 1);
    const auto needed = [&](const Eigen::Vector3d& x, float v, const SampleSource::Accessor& acc) {
        const double depth = seg.openedDepth(x);
        if (depth > 0.0 && v < 0.0f) return true;
        if (depth > shell || depth < -beyond) return false;
        const Eigen::Vector3d p = seg.inverseMap(x);
        return acc.trilinear(grid.worldToIndex(toVdb(p))) + std::max(0.0, depth) < shell;
    };
    return markInactive(grid, box, needed, mask);
}

std::size_t markFilled(const Grid& grid, const StepDeformation& seg, double shell, double from,
                       VoxelList& mask) {
    // A centre deeper than the shell leaves the ball enclosed by the images of the old
    // surface, which the band already grew around: walking its box (the ball's, voxel by
    // voxel) would add nothing.
    if (!seg.fillsWith(from) || from < -shell) return 0;
    const openvdb::CoordBBox box = indexBox(grid, seg.filledBox(from), 1);
    const auto needed = [&](const Eigen::Vector3d& x, float, const SampleSource::Accessor& acc) {
        const double at = acc.trilinear(grid.worldToIndex(toVdb(seg.inverseMap(x))));
        // (The sphere the new surface encloses bounds the depth enough to tell what joins.)
        const double filled = seg.filledValue(x, at, from, nullptr);
        return filled != at && std::abs(filled) < shell;
    };
    return markInactive(grid, box, needed, mask);
}

bool seedsSampled(const Grid& grid, const std::vector<LeafNode*>& leaves,
                  const openvdb::CoordBBox& box) {
    using leafwords::Word;
    std::atomic<bool> all{true};
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& r) {
        const auto acc = grid.getConstAccessor();
        for (std::size_t l = r.begin(); l != r.end() && all; ++l) {
            const LeafNode& leaf = *leaves[l];
            const LeafNode::NodeMaskType crossingAll = crossingVoxels(leaf, acc);
            const leafwords::Words inside = leafwords::inBox(box, leaf.origin());
            Word crossing[8];
            for (int x = 0; x < 8; ++x)
                crossing[x] = crossingAll.getWord<Word>(x) & inside[std::size_t(x)];
            // The leaf's active voxels, and those of a neighbour, as words.
            const auto words = [](const LeafNode& of, Word(&out)[8]) {
                for (int x = 0; x < 8; ++x)
                    out[x] = of.getValueMask().getWord<Word>(x);
            };
            Word on[8], missing[8];
            words(leaf, on);
            for (int x = 0; x < 8; ++x)
                missing[x] = crossing[x] & ~on[x];
            leafwords::forEachFace(
                leaf, acc, [&](auto axis, int dir, const openvdb::Coord&, const LeafNode* next) {
                    constexpr int A = decltype(axis)::value;
                    Word n[8] = {}; // a tile's voxels hold no sample
                    if (next) words(*next, n);
                    for (int x = 0; x < 8; ++x) {
                        const Word neighbourOn =
                            leafwords::stepped<A>(on, x, dir, leafwords::facing<A>(n, x, dir));
                        missing[x] |= crossing[x] & ~neighbourOn;
                    }
                });
            if (std::any_of(missing, missing + 8, [](Word w) { return w != 0; })) all = false;
        }
    });
    return all;
}

VoxelList unsampledSeeds(const Grid& grid, const std::vector<LeafNode*>& leaves,
                         const openvdb::CoordBBox& box) {
    tbb::enumerable_thread_specific<std::vector<openvdb::Coord>> found;
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& r) {
        const auto acc = grid.getConstAccessor();
        auto& out = found.local();
        for (std::size_t l = r.begin(); l != r.end(); ++l) {
            const LeafNode& leaf = *leaves[l];
            const LeafNode::NodeMaskType crossing = crossingVoxels(leaf, acc);
            for (auto it = crossing.beginOn(); it; ++it) {
                const openvdb::Coord c = leaf.offsetToGlobalCoord(it.pos());
                if (!box.isInside(c)) continue;
                if (!leaf.isValueOn(it.pos())) out.push_back(c);
                for (int a = 0; a < 3; ++a)
                    for (const int d : {-1, 1}) {
                        openvdb::Coord n = c;
                        n[a] += d;
                        if (box.isInside(n) && !acc.isValueOn(n)) out.push_back(n);
                    }
            }
        }
    });
    openvdb::MaskTree marked;
    openvdb::tree::ValueAccessor<openvdb::MaskTree, false> macc(marked);
    for (const auto& f : found)
        for (const openvdb::Coord& c : f)
            macc.setValueOn(c);
    return listLeaves(marked);
}

void makeLeavesWithin(Grid& grid, const VoxelList& mask, int beyond,
                      const openvdb::CoordBBox& box) {
    const auto near = [&](int d, int c) {
        return d < 0 ? c < beyond : d > 0 ? c >= 8 - beyond : true;
    };
    std::uint64_t across[3][3] = {}; // the (y, z) bits of a word within reach of (dy, dz)
    for (int y = 0; y < 8; ++y)
        for (int z = 0; z < 8; ++z)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz)
                    if (near(dy, y) && near(dz, z))
                        across[dy + 1][dz + 1] |= std::uint64_t(1) << (8 * y + z);
    // The leaves missing are found in parallel, reading the tree, and made after, on this
    // thread (the tree changes): most of the up to 27 places a mask leaf reaches hold a leaf
    // already, and looking them all up on one thread was a serial part of every segment.
    tbb::enumerable_thread_specific<std::vector<openvdb::Coord>> missing;
    parallelFor(tbb::blocked_range<std::size_t>(0, mask.size()), [&](const auto& r) {
        const auto acc = grid.getConstAccessor();
        auto& out = missing.local();
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const LeafVoxels& leaf = mask[i];
            for (int dx = -1; dx <= 1; ++dx) {
                std::uint64_t rows = 0;
                for (int x = 0; x < 8; ++x)
                    if (near(dx, x)) rows |= leaf.words[std::size_t(x)];
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dz = -1; dz <= 1; ++dz) {
                        if (!(rows & across[dy + 1][dz + 1])) continue;
                        const openvdb::Coord o = leaf.origin.offsetBy(8 * dx, 8 * dy, 8 * dz);
                        if (box.hasOverlap(openvdb::CoordBBox::createCube(o, 8)) &&
                            !acc.probeConstLeaf(o))
                            out.push_back(o);
                    }
            }
        }
    });
    // A leaf two mask entries reach is listed twice: each is made once. The new leaves take
    // the value and state of the tile they replace; they are made in parallel, and only put
    // into the tree on this thread.
    std::vector<openvdb::Coord> origins;
    for (const auto& list : missing)
        origins.insert(origins.end(), list.begin(), list.end());
    std::sort(origins.begin(), origins.end());
    origins.erase(std::unique(origins.begin(), origins.end()), origins.end());
    std::vector<LeafNode*> made(origins.size());
    parallelFor(tbb::blocked_range<std::size_t>(0, origins.size(), grainFor(origins.size(), 16)),
                [&](const auto& r) {
                    const auto acc = grid.getConstAccessor();
                    for (std::size_t i = r.begin(); i != r.end(); ++i)
                        made[i] = new LeafNode(origins[i], acc.getValue(origins[i]),
                                               acc.isValueOn(origins[i]));
                });
    for (LeafNode* leaf : made)
        grid.tree().addLeaf(leaf);
}

} // namespace sweepers
