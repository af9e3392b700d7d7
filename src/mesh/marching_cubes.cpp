// SPDX-License-Identifier: Apache-2.0
#include "mesh/marching_cubes.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <optional>
#include <utility>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <xxhash.h>

#include "levelset/stencils.h"
#include "mesh/mc_table.h"
#include "vdb/leaf_words.h"
#include "vdb/local_tree.h"
#include "vdb/parallel.h"

namespace sweepers {

namespace {

// Edge name: lowest voxel (20 bits per coordinate, +-2^19 voxels) and axis (3: a cycle
// centre, its cycle in the top two bits).
constexpr std::int64_t kKeyOffset = 1 << 19, kKeyMask = (1 << 20) - 1;
std::uint64_t makeKey(const openvdb::Coord& c, int axis) {
    return (std::uint64_t(c.x() + kKeyOffset) << 40) | (std::uint64_t(c.y() + kKeyOffset) << 20) |
           std::uint64_t(c.z() + kKeyOffset) | (std::uint64_t(axis) << 60);
}
int keyAxis(std::uint64_t key) {
    return int(key >> 60 & 3);
}
openvdb::Coord keyVoxel(std::uint64_t key) {
    return openvdb::Coord(int(std::int64_t(key >> 40 & kKeyMask) - kKeyOffset),
                          int(std::int64_t(key >> 20 & kKeyMask) - kKeyOffset),
                          int(std::int64_t(key & kKeyMask) - kKeyOffset));
}

// The values meshing one leaf reads, copied once so that every read is an array lookup:
// the leaf and the voxels from one before it to two past it along each axis (cube corners
// reach one voxel past the leaf, and central differences at those corners one more on
// either side).
class LeafBlock {
  public:
    static constexpr int kDim = int(LeafNode::DIM), kSpan = kDim + 3;

    LeafBlock(const Grid::ConstAccessor& acc, const LeafNode& leaf) : origin_(leaf.origin()) {
        const openvdb::Coord min = origin_.offsetBy(-1);
        copyBox(
            openvdb::CoordBBox(min, min.offsetBy(kSpan - 1)), values_.data(),
            [&](const openvdb::Coord& o) { return acc.probeConstLeaf(o); },
            [&](const openvdb::Coord& o) { return acc.getValue(o); });
    }

    // Where leaf-local voxel (x, y, z) (-1 to 9 each) lies in the block, and the steps of
    // that index along each axis.
    static constexpr int index(int x, int y, int z) {
        return ((x + 1) * kSpan + y + 1) * kSpan + z + 1;
    }
    static constexpr std::array<int, 3> kStep = {kSpan * kSpan, kSpan, 1};
    float at(int i) const { return values_[std::size_t(i)]; }
    // The central-difference gradient at the voxel of index i (see centralGradient).
    Eigen::Vector3f gradientAt(int i, double h) const {
        Eigen::Vector3f g;
        for (int a = 0; a < 3; ++a)
            g[a] =
                centralDifference(at(i - kStep[std::size_t(a)]), at(i + kStep[std::size_t(a)]), h);
        return g;
    }

    // The cubes the surface crosses (those with corners of both signs), as a voxel set of
    // the leaf: the cube of voxel (x, y, z) has its corners from there to (x + 1, y + 1,
    // z + 1), one voxel past the leaf's upper faces. Found a row of eight cubes along z at a
    // time, from the signs of the four rows of corners around it (one compare per corner,
    // where testing each cube read its eight corners).
    leafwords::Words crossingCubes() const {
        constexpr std::size_t kRows = kDim + 1;       // corner rows along x and along y
        std::array<unsigned, kRows * kRows> negative; // per corner row, bit z
        for (std::size_t x = 0; x < kRows; ++x)
            for (std::size_t y = 0; y < kRows; ++y) {
                const float* row = &values_[((x + 1) * kSpan + (y + 1)) * kSpan + 1];
                negative[x * kRows + y] = unsigned(leafwords::negatives(row, kDim + 1));
            }
        leafwords::Words out{};
        for (std::size_t x = 0; x < kDim; ++x)
            for (std::size_t y = 0; y < kDim; ++y) {
                unsigned allNegative = 0xffu, allPositive = 0xffu;
                for (std::size_t c = 0; c < 4; ++c) {
                    const unsigned r = negative[(x + (c & 1)) * kRows + y + (c >> 1)];
                    allNegative &= r & r >> 1;
                    allPositive &= ~r & ~r >> 1;
                }
                out[x] |= leafwords::Word(~(allNegative | allPositive) & 0xffu) << (8 * y);
            }
        return out;
    }

    // A hash of the values, the leaf's active voxels and where the grid puts its voxels:
    // what meshing the leaf reads (never 0, which marks a chunk made from nothing).
    std::uint64_t fingerprint(const LeafNode& leaf, const openvdb::math::Transform& xform) const {
        const openvdb::Vec3d placement[2] = {xform.indexToWorld(openvdb::Vec3d(0.0)),
                                             xform.voxelSize()};
        std::uint64_t seed = XXH3_64bits(placement, sizeof(placement));
        const auto& mask = leaf.getValueMask();
        seed = XXH3_64bits_withSeed(&mask, sizeof(mask), seed);
        return XXH3_64bits_withSeed(values_.data(), sizeof(values_), seed) | 1;
    }

  private:
    openvdb::Coord origin_;
    std::array<float, std::size_t(kSpan) * kSpan * kSpan> values_;
};

// Whether the vertex named `key` may be shared with a chunk of another leaf: a crossing on
// an edge that lies on a face of the leaf `origin`'s cubes (one of the edge's coordinates
// across it is 0 or 8 from the origin; its cubes then belong to two leaves or more).
// Cycle centres are never shared.
bool sharedAcrossLeaves(std::uint64_t key, const openvdb::Coord& origin) {
    const int axis = keyAxis(key);
    if (axis == 3) return false;
    const openvdb::Coord c = keyVoxel(key) - origin;
    for (int a = 0; a < 3; ++a)
        if (a != axis && (c[a] == 0 || c[a] == int(LeafNode::DIM))) return true;
    return false;
}

// A table of N entries emptied for each leaf by a new generation number instead of being
// refilled (one per thread): an entry is claimed the first time it is asked for in a
// generation, and holds what it was given since.
template <typename T, std::size_t N> class LeafTable {
  public:
    void clear() {
        if (++generation_ == 0) { // after 2^32 leaves: stamps could repeat
            stamps_.fill(0);
            generation_ = 1;
        }
    }
    // Whether entry k is new in this generation (it is claimed, its value left to set).
    bool claim(std::size_t k) {
        if (stamps_[k] == generation_) return false;
        stamps_[k] = generation_;
        return true;
    }
    T& operator[](std::size_t k) { return values_[k]; }

  private:
    std::array<std::uint32_t, N> stamps_{};
    std::array<T, N> values_;
    std::uint32_t generation_ = 0;
};

// Cube corners of a leaf, leaf-local (0 to 8 along each axis), numbered x, y, z.
constexpr int kCorners = int(LeafNode::DIM) + 1;
constexpr int cornerIndex(int x, int y, int z) {
    return (x * kCorners + y) * kCorners + z;
}
constexpr std::array<int, 3> kCornerStep = {kCorners * kCorners, kCorners, 1};

// Where corner c of a cube (the numbering of mesh/mc_table: bit 0 along x, 1 along y, 2
// along z) lies from the cube's lowest corner: in the corner numbering and in a LeafBlock.
// A cube is meshed by adding these to its own indices, not by stepping coordinates.
template <typename Index> constexpr std::array<int, 8> cornerOffsets(const Index& index) {
    std::array<int, 8> out{};
    for (int c = 0; c < 8; ++c)
        out[std::size_t(c)] = index(c & 1, c >> 1 & 1, c >> 2 & 1) - index(0, 0, 0);
    return out;
}
constexpr std::array<int, 8> kCornerOffset = cornerOffsets(cornerIndex);
constexpr std::array<int, 8> kBlockOffset = cornerOffsets(LeafBlock::index);

// The vertices a leaf's cubes have made so far, by where they lie: a crossing on the edge
// from a cube corner along an axis, or the centre of one of a cube's cycles (a cube has at
// most four: that many corners of a cube can be pairwise non-adjacent). Array lookups
// instead of a hash map: meshing runs on every stroke segment, and a hash per corner would
// cost more than the cubes.
class LeafVertices {
  public:
    static constexpr int kMaxCycles = 4;
    static constexpr std::size_t kEdges = std::size_t(kCorners) * kCorners * kCorners * 3;
    void clear() { ids_.clear(); }
    // The vertex on the edge from corner `corner` (cornerIndex) along `axis`.
    int& onEdge(int corner, int axis) { return slot(std::size_t(corner) * 3 + std::size_t(axis)); }
    // The centre of cycle `cycle` of the cube of leaf voxel `offset`.
    int& atCentre(int offset, int cycle) {
        return slot(kEdges + std::size_t(offset) * kMaxCycles + std::size_t(cycle));
    }

  private:
    int& slot(std::size_t k) { // -1 until set in this generation
        if (ids_.claim(k)) ids_[k] = -1;
        return ids_[k];
    }
    LeafTable<int, kEdges + std::size_t(LeafNode::SIZE) * kMaxCycles> ids_;
};

// The central-difference gradients at a leaf's cube corners, each computed once per leaf: a
// corner ends up to six crossing edges, and every vertex on an edge blends the gradients at
// both its ends.
class CornerGradients {
  public:
    void clear() { gradients_.clear(); }
    // The gradient at corner `corner` (cornerIndex), which lies at index i of `block`.
    const Eigen::Vector3f& at(int corner, const LeafBlock& block, int i, double h) {
        const auto k = std::size_t(corner);
        if (gradients_.claim(k)) gradients_[k] = block.gradientAt(i, h);
        return gradients_[k];
    }

  private:
    LeafTable<Eigen::Vector3f, std::size_t(kCorners) * kCorners * kCorners> gradients_;
};

// Meshes the leaf at `origin` into `into`, whose vectors keep their storage where it is
// large enough: re-meshing a segment's leaves allocates little once their chunks have grown.
// Returns whether the chunk changed: made again, or emptied (a chunk made from the same
// values, or a leaf without surface that had none, is left as it is).
// What a thread meshes a leaf in: the leaf's triangles before they are copied into its
// chunk, its vertices by edge, and the gradients at its cube corners.
struct LeafScratch {
    MeshChunk chunk;
    LeafVertices vertices;
    CornerGradients gradients;
};

bool meshLeaf(const Grid& grid, const openvdb::Coord& origin, MeshChunk& into,
              LeafScratch& scratch) {
    const Grid::TreeType::LeafNodeType* leaf = grid.tree().probeConstLeaf(origin);
    std::optional<LeafBlock> block;
    leafwords::Words crossing{};
    if (leaf) {
        block.emplace(grid.getConstAccessor(), *leaf);
        crossing = block->crossingCubes();
    }
    if (!leafwords::any(crossing)) {
        // No surface: every corner on one side.
        const bool had = into.madeFrom != 0;
        into = MeshChunk{};
        return had;
    }
    const std::uint64_t madeFrom = block->fingerprint(*leaf, grid.transform());
    if (madeFrom == into.madeFrom) return false; // the same triangles again
    // Made in storage of the thread's, then copied into the chunk at its size: grown a
    // vertex at a time, a new chunk's vectors were allocated again at every doubling (some
    // seven times each for a leaf's sixty or so vertices), and allocating and freeing
    // became a large part of whole-grid meshing.
    MeshChunk& chunk = scratch.chunk;
    chunk.positions.clear();
    chunk.normals.clear();
    chunk.edgeKeys.clear();
    chunk.triangles.clear();
    const LeafBlock& values = *block;
    const VoxelPlacement place(grid.transform());
    const double h = grid.voxelSize()[0];
    LeafVertices& vertices = scratch.vertices;
    vertices.clear();
    CornerGradients& gradients = scratch.gradients;
    gradients.clear();
    // Meshes the cube of leaf voxel `offset` (its lowest corner).
    const auto meshCube = [&](int offset) {
        const openvdb::Coord local = LeafNode::offsetToLocalCoord(openvdb::Index(offset));
        const int x = local.x(), y = local.y(), z = local.z();
        const openvdb::Coord base = origin + local;
        const int inBlock = LeafBlock::index(x, y, z), corner = cornerIndex(x, y, z);
        float v[8];
        int mask = 0;
        for (std::size_t c = 0; c < 8; ++c) {
            v[c] = values.at(inBlock + kBlockOffset[c]);
            if (v[c] < 0.0f) mask |= 1 << c;
        }
        // The vertex on cube edge e, created on first use.
        auto vertexOn = [&](int e) {
            const mc::Edge& edge = mc::kEdges[std::size_t(e)];
            const auto c0 = std::size_t(edge.c0), axis = std::size_t(edge.axis);
            const int from = corner + kCornerOffset[c0];
            int& id = vertices.onEdge(from, edge.axis);
            if (id < 0) {
                id = int(chunk.positions.size());
                // A crossing never sits on a voxel itself (a value of exactly zero there, or a
                // division that rounds): every edge through that voxel would put its own
                // vertex at the same point, and the triangles between them would have no
                // area. A thousandth of a voxel along the edge keeps them apart.
                constexpr float kOffVoxel = 1e-3f;
                const float a = v[c0], b = v[std::size_t(edge.c1)];
                const float t = std::clamp(a / (a - b), kOffVoxel, 1.0f - kOffVoxel);
                const openvdb::Coord ijk = cubeCorner(base, edge.c0);
                openvdb::Vec3d p(ijk.x(), ijk.y(), ijk.z());
                p[axis] += t;
                const openvdb::Vec3d w = place.toWorld(p);
                chunk.positions.emplace_back(float(w.x()), float(w.y()), float(w.z()));
                const int at0 = inBlock + kBlockOffset[c0];
                const Eigen::Vector3f n = (1 - t) * gradients.at(from, values, at0, h) +
                                          t * gradients.at(from + kCornerStep[axis], values,
                                                           at0 + LeafBlock::kStep[axis], h);
                const float len = n.norm();
                chunk.normals.push_back(len > 0 ? Eigen::Vector3f(n / len)
                                                : Eigen::Vector3f(0, 0, 1));
                chunk.edgeKeys.push_back(makeKey(ijk, edge.axis));
            }
            return id;
        };
        const mc::Case& cube = mc::lookup(mask);
        int ids[3];
        for (const auto& tri : cube.triangles) {
            for (int k = 0; k < 3; ++k) {
                const int e = tri[std::size_t(k)];
                if (e >= mc::kCentre) {
                    // A cycle's centre: never shared with another cube.
                    const int cycle = e - mc::kCentre;
                    int& id = vertices.atCentre(offset, cycle);
                    if (id < 0) {
                        Eigen::Vector3f p = Eigen::Vector3f::Zero(), nrm = Eigen::Vector3f::Zero();
                        for (std::uint8_t ce : cube.cycles[std::size_t(cycle)]) {
                            const int vi = vertexOn(ce);
                            p += chunk.positions[std::size_t(vi)];
                            nrm += chunk.normals[std::size_t(vi)];
                        }
                        id = int(chunk.positions.size());
                        chunk.positions.push_back(p /
                                                  float(cube.cycles[std::size_t(cycle)].size()));
                        chunk.normals.push_back(nrm.normalized());
                        chunk.edgeKeys.push_back(makeKey(base, 3) | (std::uint64_t(cycle) << 62));
                    }
                    ids[k] = id;
                } else {
                    ids[k] = vertexOn(e);
                }
            }
            chunk.triangles.emplace_back(ids[0], ids[1], ids[2]);
        }
    };
    // The cubes of the leaf's active voxels that the surface crosses, in offset order.
    for (int x = 0; x < 8; ++x)
        for (leafwords::Word cubes =
                 crossing[std::size_t(x)] & leaf->getValueMask().getWord<leafwords::Word>(x);
             cubes; cubes &= cubes - 1)
            meshCube(x * 64 + __builtin_ctzll(cubes));
    // (assign keeps the chunk's storage where it is large enough, as re-meshing wants.)
    into.positions.assign(chunk.positions.begin(), chunk.positions.end());
    into.normals.assign(chunk.normals.begin(), chunk.normals.end());
    into.edgeKeys.assign(chunk.edgeKeys.begin(), chunk.edgeKeys.end());
    into.triangles.assign(chunk.triangles.begin(), chunk.triangles.end());
    into.volume = enclosedVolume(into.positions, into.triangles);
    into.madeFrom = madeFrom;
    return true;
}

} // namespace

struct SurfaceMesher::Scratch : tbb::enumerable_thread_specific<LeafScratch> {};

SurfaceMesher::SurfaceMesher() : scratch_(std::make_unique<Scratch>()) {}
SurfaceMesher::~SurfaceMesher() = default;
SurfaceMesher::SurfaceMesher(SurfaceMesher&&) noexcept = default;
SurfaceMesher& SurfaceMesher::operator=(SurfaceMesher&&) noexcept = default;

std::size_t SurfaceMesher::meshLeaves(const Grid& grid, const std::vector<openvdb::Coord>& origins,
                                      Interrupter* interrupter) {
    // Each leaf into the chunk it has (its storage reused) or into a new one, which joins
    // the map only when it holds a triangle (a map's elements stay where they are, so the
    // chunks are written in parallel); chunks left without a triangle go. The chunks are
    // looked up in the parallel loop too (nothing changes the map meanwhile): done on one
    // thread before the loop, they were a serial part of every segment's meshing.
    std::vector<MeshChunk*> into(origins.size());
    std::vector<MeshChunk> fresh(origins.size());
    std::atomic<std::size_t> meshed{0};
    parallelFor(tbb::blocked_range<std::size_t>(0, origins.size(), grainFor(origins.size(), 16)),
                [&](const auto& r) {
                    pollInterrupt(interrupter);
                    std::size_t n = 0;
                    for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const auto it =
                            chunks_.find(origins[i]); // (find counts as const for races)
                        if (it != chunks_.end()) {
                            into[i] = &it->second;
                        } else if (grid.tree().probeConstLeaf(origins[i])) {
                            into[i] = &fresh[i];
                        } else {
                            continue; // neither a leaf nor a chunk: nothing to mesh or to empty
                        }
                        n += meshLeaf(grid, origins[i], *into[i], scratch_->local());
                    }
                    meshed += n;
                });
    for (std::size_t i = 0; i < origins.size(); ++i) {
        if (!into[i]) continue;
        if (into[i] == &fresh[i]) {
            if (!fresh[i].triangles.empty()) chunks_.emplace(origins[i], std::move(fresh[i]));
        } else if (into[i]->triangles.empty()) {
            chunks_.erase(origins[i]);
        }
    }
    return meshed;
}

MeshChanges SurfaceMesher::takeChanges() {
    return std::exchange(changes_, MeshChanges{});
}

void SurfaceMesher::rebuild(const Grid& grid, Interrupter* interrupter) {
    std::vector<openvdb::Coord> origins;
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf)
        origins.push_back(leaf->origin());
    // Meshed into a new mesher first: a cancelled rebuild leaves this one as it was.
    SurfaceMesher fresh;
    fresh.meshLeaves(grid, origins, interrupter);
    chunks_ = std::move(fresh.chunks_);
    changes_.all = true;
}

std::size_t SurfaceMesher::update(const Grid& grid, const openvdb::CoordBBox& touched) {
    // A leaf's cubes read one voxel past its upper faces, and their normals one more, and
    // one before its lower faces.
    openvdb::CoordBBox box = touched;
    box.expand(2);
    changes_.box.expand(box);
    // Forget the chunks of the box whose leaves are gone (chunks are keyed by leaf origin,
    // in x, y, z order: one row of them at a time), then mesh the leaves there now into
    // the chunks they had.
    constexpr int kDim = int(LeafNode::DIM);
    const openvdb::Coord first = floorToMultiple(box.min(), kDim);
    std::size_t emptied = 0;
    for (int x = first.x(); x <= box.max().x(); x += kDim)
        for (int y = first.y(); y <= box.max().y(); y += kDim)
            for (auto it = chunks_.lower_bound(openvdb::Coord(x, y, first.z()));
                 it != chunks_.end() && it->first.x() == x && it->first.y() == y &&
                 it->first.z() <= box.max().z();) {
                const bool gone = !grid.tree().probeConstLeaf(it->first);
                emptied += gone;
                it = gone ? chunks_.erase(it) : std::next(it);
            }
    std::vector<openvdb::Coord> origins;
    for (const LeafNode* leaf : leavesIn(std::as_const(grid.tree()), box))
        origins.push_back(leaf->origin());
    return emptied + meshLeaves(grid, origins);
}

std::size_t SurfaceMesher::update(const Grid& grid,
                                  const std::vector<openvdb::CoordBBox>& changed) {
    // The leaf at o reads its voxels and those from o - 1 to o + 9 along each axis (LeafBlock):
    // a voxel v is read by the leaves with o from v - 9 to v + 1, the multiples of 8 from
    // floor8(v - 2) to floor8(v + 1). In leaf units (o / 8, o >> 3), per box:
    constexpr int kDim = int(LeafNode::DIM), kLog2 = int(LeafNode::LOG2DIM);
    // (The origin of a leaf from its place in leaf units: multiplied, since shifting a
    // negative value left is undefined.)
    const auto originAt = [&](const openvdb::Coord& c) {
        return openvdb::Coord(c.x() * kDim, c.y() * kDim, c.z() * kDim);
    };
    const auto readers = [&](const openvdb::CoordBBox& box) {
        return openvdb::CoordBBox(box.min().offsetBy(-2) >> kLog2, box.max().offsetBy(1) >> kLog2);
    };
    // Per box, the leaves (in leaf units) that read it.
    std::vector<openvdb::CoordBBox> read;
    read.reserve(changed.size());
    openvdb::CoordBBox extent;
    std::size_t marks = 0;
    for (const openvdb::CoordBBox& box : changed) {
        if (box.empty()) continue;
        openvdb::CoordBBox around = box;
        around.expand(2);
        changes_.box.expand(around);
        read.push_back(readers(box));
        extent.expand(read.back());
        marks += read.back().volume();
    }
    // The origins, each once: marked in a dense array over the extent of the boxes, unless the
    // boxes lie so far apart that the array would hold many more entries than marks. (A
    // segment reports thousands of boxes, each read by up to 27 leaves: sorting that many
    // origins would cost more than meshing them.)
    std::vector<openvdb::Coord> origins;
    const std::size_t cells = extent.empty() ? 0 : extent.volume();
    if (cells <= 2 * marks + 4096) {
        // Marked by the boxes in parallel (boxes overlap: each mark is an atomic store of the
        // same 1), then listed an x-slab of the extent per task, in the extent's order.
        const openvdb::Coord lo = extent.min(), n = extent.dim();
        const auto slot = [&](const openvdb::Coord& c) {
            const openvdb::Coord d = c - lo;
            return (std::size_t(d.x()) * std::size_t(n.y()) + std::size_t(d.y())) *
                       std::size_t(n.z()) +
                   std::size_t(d.z());
        };
        std::unique_ptr<std::atomic<std::uint8_t>[]> marked(new std::atomic<std::uint8_t>[cells]);
        parallelFor(tbb::blocked_range<std::size_t>(0, cells, grainFor(cells, 4096)),
                    [&](const auto& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i)
                            marked[i].store(0, std::memory_order_relaxed);
                    });
        parallelFor(tbb::blocked_range<std::size_t>(0, read.size(), grainFor(read.size(), 64)),
                    [&](const auto& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i)
                            for (auto it = read[i].begin(); it; ++it)
                                marked[slot(*it)].store(1, std::memory_order_relaxed);
                    });
        std::vector<std::vector<openvdb::Coord>> slabs(std::size_t(n.x()));
        parallelFor(std::size_t(0), slabs.size(), [&](std::size_t x) {
            for (int y = 0; y < n.y(); ++y)
                for (int z = 0; z < n.z(); ++z) {
                    const openvdb::Coord c = lo.offsetBy(int(x), y, z);
                    if (marked[slot(c)].load(std::memory_order_relaxed))
                        slabs[x].push_back(originAt(c));
                }
        });
        for (const auto& slab : slabs)
            origins.insert(origins.end(), slab.begin(), slab.end());
    } else {
        for (const openvdb::CoordBBox& r : read)
            for (auto it = r.begin(); it; ++it)
                origins.push_back(originAt(*it));
        std::sort(origins.begin(), origins.end());
        origins.erase(std::unique(origins.begin(), origins.end()), origins.end());
    }
    // (Leaves gone since keep their origins here, so that their chunks are emptied.)
    return meshLeaves(grid, origins);
}

std::size_t SurfaceMesher::triangleCount() const {
    std::size_t n = 0;
    for (const auto& [o, c] : chunks_)
        n += c.triangles.size();
    return n;
}

double SurfaceMesher::enclosedVolume() const {
    double v = 0.0;
    for (const auto& [o, c] : chunks_)
        v += c.volume;
    return v;
}

TriangleMesh SurfaceMesher::weld() const {
    // The chunks in order; vertices are numbered in that order, each chunk's in its own, and
    // a vertex shared with an earlier chunk takes the number it got there. Vertex i of chunk
    // c is vertex first[c] + i of all the chunks' vertices put end to end.
    std::vector<std::pair<openvdb::Coord, const MeshChunk*>> list;
    list.reserve(chunks_.size());
    for (const auto& [origin, chunk] : chunks_)
        list.emplace_back(origin, &chunk);
    const std::size_t n = list.size();
    const auto forEachChunk = [&](const auto& body) {
        parallelFor(tbb::blocked_range<std::size_t>(0, n, grainFor(n, 64)), [&](const auto& r) {
            for (std::size_t c = r.begin(); c != r.end(); ++c)
                body(c, *list[c].second);
        });
    };
    std::vector<std::size_t> first(n + 1, 0), firstTriangle(n + 1, 0), shared(n + 1, 0);
    for (std::size_t c = 0; c < n; ++c) {
        first[c + 1] = first[c] + list[c].second->positions.size();
        firstTriangle[c + 1] = firstTriangle[c] + list[c].second->triangles.size();
    }
    // 1. Only vertices on the faces of a leaf's cubes can appear in two chunks: those are
    //    listed by name and sorted (then by chunk), and the first chunk with a name owns it.
    std::vector<std::uint32_t> owner(first[n]);
    std::vector<char> onFace(first[n]);
    forEachChunk([&](std::size_t c, const MeshChunk& chunk) {
        for (std::size_t i = 0; i < chunk.edgeKeys.size(); ++i) {
            const std::size_t v = first[c] + i;
            owner[v] = std::uint32_t(v);
            onFace[v] = sharedAcrossLeaves(chunk.edgeKeys[i], list[c].first);
            shared[c + 1] += onFace[v];
        }
    });
    for (std::size_t c = 0; c < n; ++c)
        shared[c + 1] += shared[c];
    std::vector<std::pair<std::uint64_t, std::uint32_t>> named(shared[n]); // name, vertex
    forEachChunk([&](std::size_t c, const MeshChunk& chunk) {
        std::size_t k = shared[c];
        for (std::size_t i = 0; i < chunk.edgeKeys.size(); ++i)
            if (onFace[first[c] + i]) named[k++] = {chunk.edgeKeys[i], std::uint32_t(first[c] + i)};
    });
    tbb::parallel_sort(named.begin(), named.end());
    for (std::size_t i = 1; i < named.size(); ++i)
        if (named[i].first == named[i - 1].first)
            owner[named[i].second] = owner[named[i - 1].second];
    // 2. Numbers for the vertices each chunk owns, from where the chunks before it end.
    std::vector<std::size_t> owned(n + 1, 0);
    forEachChunk([&](std::size_t c, const MeshChunk&) {
        for (std::size_t v = first[c]; v < first[c + 1]; ++v)
            owned[c + 1] += owner[v] == v;
    });
    for (std::size_t c = 0; c < n; ++c)
        owned[c + 1] += owned[c];
    TriangleMesh mesh;
    mesh.positions.resize(owned[n]);
    mesh.normals.resize(owned[n]);
    mesh.triangles.resize(firstTriangle[n]);
    std::vector<int> number(first[n]);
    forEachChunk([&](std::size_t c, const MeshChunk& chunk) {
        std::size_t next = owned[c];
        for (std::size_t i = 0; i < chunk.positions.size(); ++i) {
            const std::size_t v = first[c] + i;
            if (owner[v] != v) continue;
            number[v] = int(next);
            mesh.positions[next] = chunk.positions[i];
            mesh.normals[next] = chunk.normals[i];
            ++next;
        }
    });
    // 3. The others take their owners' numbers, and triangles are renumbered.
    forEachChunk([&](std::size_t c, const MeshChunk& chunk) {
        for (std::size_t v = first[c]; v < first[c + 1]; ++v)
            if (owner[v] != v) number[v] = number[owner[v]];
        std::size_t t = firstTriangle[c];
        const int* local = &number[first[c]];
        for (const Eigen::Vector3i& tri : chunk.triangles)
            mesh.triangles[t++] = Eigen::Vector3i(local[tri[0]], local[tri[1]], local[tri[2]]);
    });
    return mesh;
}

TriangleMesh meshLevelSet(const Grid& grid) {
    SurfaceMesher m;
    m.rebuild(grid);
    return m.weld();
}

} // namespace sweepers
