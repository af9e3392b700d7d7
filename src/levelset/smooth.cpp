#include "levelset/smooth.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/enumerable_thread_specific.h>

#include "core/falloff.h"
#include "core/format.h"
#include "core/limits.h"
#include "levelset/dilate.h"
#include "levelset/fast_marching.h"
#include "levelset/parallel.h"

namespace sweepers {

namespace {

using Leaf = Grid::TreeType::LeafNodeType;

// A leaf's values and the layer of voxels around it (10 x 10 x 10, x slowest): the
// stencils of a step read this block instead of the tree. The 26 leaves around are found
// once (their buffers, or the one value of a tile or of empty space) and read directly.
struct PaddedLeaf {
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

// kappa |grad phi| by central differences at (x, y, z) of the block (the curvature term of
// the level-set equation for mean-curvature flow), in world units:
//   (phi_xx (phi_y^2 + phi_z^2) + ... - 2 (phi_x phi_y phi_xy + ...)) / |grad phi|^2.
double curvatureTerm(const PaddedLeaf& b, int x, int y, int z, double h) {
    const auto v = [&](int dx, int dy, int dz) { return double(b.at(x + dx, y + dy, z + dz)); };
    const double p = v(0, 0, 0);
    const double gx = 0.5 * (v(1, 0, 0) - v(-1, 0, 0)), gy = 0.5 * (v(0, 1, 0) - v(0, -1, 0)),
                 gz = 0.5 * (v(0, 0, 1) - v(0, 0, -1));
    const double xx = v(1, 0, 0) - 2 * p + v(-1, 0, 0), yy = v(0, 1, 0) - 2 * p + v(0, -1, 0),
                 zz = v(0, 0, 1) - 2 * p + v(0, 0, -1);
    const double xy = 0.25 * (v(1, 1, 0) - v(1, -1, 0) - v(-1, 1, 0) + v(-1, -1, 0));
    const double xz = 0.25 * (v(1, 0, 1) - v(1, 0, -1) - v(-1, 0, 1) + v(-1, 0, -1));
    const double yz = 0.25 * (v(0, 1, 1) - v(0, 1, -1) - v(0, -1, 1) + v(0, -1, -1));
    const double g2 = gx * gx + gy * gy + gz * gz;
    if (g2 < 1e-12 * h * h) return 0.0;
    const double num = xx * (gy * gy + gz * gz) + yy * (gx * gx + gz * gz) +
                       zz * (gx * gx + gy * gy) -
                       2.0 * (gx * gy * xy + gx * gz * xz + gy * gz * yz);
    return num / g2 / (h * h); // the differences are per voxel: h^2 kappa |grad phi|
}

} // namespace

CurvatureSmoother::CurvatureSmoother(Grid& grid, const SmoothBrush& brush, Interrupter* interrupter)
    : grid_(grid), brush_(brush), interrupter_(interrupter) {
    const double h = grid.voxelSize()[0];
    const openvdb::Vec3d c =
        grid.worldToIndex({brush.center.x(), brush.center.y(), brush.center.z()});
    // The brush's reach, the band around it (renormalization rebuilds the band there) and
    // the voxel the central differences read beyond it.
    const double margin = reachRadius() / h + 2.0;
    reach_ = openvdb::CoordBBox(openvdb::Coord::floor(c - openvdb::Vec3d(margin)),
                                openvdb::Coord::ceil(c + openvdb::Vec3d(margin)));
}

double CurvatureSmoother::renormalizedRadius() const {
    return reachRadius() / grid_.voxelSize()[0] - 1.0;
}

SmoothStats CurvatureSmoother::run() {
    stats_ = SmoothStats();
    stats_.changed = reach_;
    if (!(brush_.time > 0.0) || !(brush_.radius > 0.0)) return stats_;
    collectLeaves();
    weigh();
    requireAffordable();
    widenBand();
    pollInterrupt(interrupter_);
    flow();
    pollInterrupt(interrupter_);
    renormalizeReach();
    return stats_;
}

void CurvatureSmoother::collectLeaves() {
    leaves_.clear();
    // Leaf by leaf origin inside the reach: the work is the brush's, not the grid's. A
    // brush larger than the shape would probe mostly empty space: then the grid's own
    // leaves are walked instead, so the work is the smaller of the two.
    const openvdb::Coord lo = reach_.min() & ~(Leaf::DIM - 1), hi = reach_.max();
    const openvdb::Coord slots = ((hi - lo) >> Leaf::LOG2DIM) + openvdb::Coord(1);
    const double probes = double(slots.x()) * slots.y() * slots.z();
    if (probes > double(grid_.tree().leafCount())) {
        for (auto it = grid_.tree().beginLeaf(); it; ++it) {
            ++stats_.leavesVisited;
            if (reach_.hasOverlap(it->getNodeBoundingBox())) leaves_.push_back(&*it);
        }
    } else {
        for (int x = lo.x(); x <= hi.x(); x += Leaf::DIM)
            for (int y = lo.y(); y <= hi.y(); y += Leaf::DIM)
                for (int z = lo.z(); z <= hi.z(); z += Leaf::DIM) {
                    ++stats_.leavesVisited;
                    if (Leaf* leaf = grid_.tree().probeLeaf({x, y, z})) leaves_.push_back(leaf);
                }
    }
    stats_.leaves = leaves_.size();
}

void CurvatureSmoother::weigh() {
    const double r = brush_.radius, f = brush_.falloff;
    const float bg = grid_.background();
    // Band voxels within the falloff's reach (not those at +-background: they hold no
    // distance).
    std::vector<std::array<float, Leaf::SIZE>> weight(leaves_.size());
    std::vector<char> reached(leaves_.size(), 0);
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves_.size()), [&](const auto& range) {
        for (std::size_t l = range.begin(); l != range.end(); ++l) {
            const Leaf& leaf = *leaves_[l];
            for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
                weight[l][i] = 0.0f;
                if (!leaf.isValueOn(i) || std::abs(leaf.getValue(i)) >= bg) continue;
                const openvdb::Vec3d w = grid_.indexToWorld(leaf.offsetToGlobalCoord(i));
                const double d = (Eigen::Vector3d(w.x(), w.y(), w.z()) - brush_.center).norm() - r;
                weight[l][i] = float(falloffMu(d, f));
                reached[l] |= weight[l][i] > 0.0f;
            }
        }
    });
    flowing_.clear();
    weight_.clear();
    weighted_.clear();
    for (std::size_t l = 0; l < leaves_.size(); ++l) {
        if (!reached[l]) continue;
        flowing_.push_back(l);
        weight_.push_back(weight[l]);
        LeafVoxels lv{leaves_[l]->origin(), {}};
        for (openvdb::Index i = 0; i < Leaf::SIZE; ++i)
            if (weight[l][i] > 0.0f) lv.words[i >> 6] |= leafwords::Word(1) << (i & 63);
        weighted_.push_back(lv);
    }
}

// A dab may move the surface by two voxels: the band grows by two voxels around the voxels
// that flow (within the renormalized ball), so that the renormalization finds band on
// whichever side the surface moved to. The new voxels keep the value they held
// (+-background, of the right sign) and take no part in the flow; the renormalization gives
// them distances, or drops them past the half-width.
void CurvatureSmoother::widenBand() {
    const openvdb::Vec3d c =
        grid_.worldToIndex({brush_.center.x(), brush_.center.y(), brush_.center.z()});
    const double r = renormalizedRadius();
    for (const LeafVoxels& lv : dilatedByCube(weighted_, 2)) {
        Leaf* leaf = grid_.tree().probeLeaf(lv.origin);
        const bool made = !leaf;
        for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
            if (!((lv.words[i >> 6] >> (i & 63)) & 1)) continue;
            if (((lv.origin + Leaf::offsetToLocalCoord(i)).asVec3d() - c).lengthSqr() > r * r)
                continue;
            if (!leaf) leaf = grid_.tree().touchLeaf(lv.origin);
            leaf->setValueOn(i);
        }
        if (made && leaf) leaves_.push_back(leaf); // renormalized with the others
    }
}

double CurvatureSmoother::stepCount() const {
    const double h = grid_.voxelSize()[0];
    // Explicit steps of the central scheme are stable for dt <= h^2 / 4: along the surface
    // (|grad phi| = 1) the flow is a diffusion in two dimensions, whose fastest mode (the
    // checkerboard) decays at 8 / h^2. A little under it.
    const double dtMax = 0.9 * h * h / 4.0;
    return std::max(1.0, std::ceil(brush_.time / dtMax));
}

// Before the grid changes: the flow's steps times the voxels that flow, against the work
// limit (a ball far larger than the shape, or far finer a grid, would flow for hours).
void CurvatureSmoother::requireAffordable() const {
    double voxels = 0.0;
    for (const LeafVoxels& lv : weighted_)
        for (const leafwords::Word w : lv.words)
            voxels += double(__builtin_popcountll(w));
    requireWork(stepCount() * voxels, "a smooth dab of radius " + formatNumber(brush_.radius) +
                                          " (" + formatNumber(stepCount()) + " steps of " +
                                          formatNumber(voxels) + " voxels)");
}

void CurvatureSmoother::flow() {
    const double h = grid_.voxelSize()[0];
    const int steps = int(stepCount()); // (within the work limit: far below INT_MAX)
    const double dt = brush_.time / steps;
    stats_.steps = steps;
    // The whole band flows, so that the differences read consistent values; no value moves
    // more than two voxels in a dab, so the surface stays inside the band that holds it.
    const float most = float(2.0 * h);
    std::vector<std::array<float, Leaf::SIZE>> next(flowing_.size()), start(flowing_.size());
    for (std::size_t k = 0; k < flowing_.size(); ++k) {
        const float* values = leaves_[flowing_[k]]->buffer().data();
        std::copy(values, values + Leaf::SIZE, start[k].begin());
    }
    std::vector<PaddedLeaf::Around> around(flowing_.size());
    parallelFor(tbb::blocked_range<std::size_t>(0, flowing_.size()), [&](const auto& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k)
            around[k] = PaddedLeaf::around(grid_, *leaves_[flowing_[k]]);
    });
    tbb::enumerable_thread_specific<std::size_t> updates(0);
    for (int s = 0; s < steps; ++s) {
        parallelFor(tbb::blocked_range<std::size_t>(0, flowing_.size()), [&](const auto& range) {
            PaddedLeaf block;
            std::size_t n = 0;
            for (std::size_t k = range.begin(); k != range.end(); ++k) {
                block.load(around[k]);
                for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
                    const int x = int(i >> 6), y = int((i >> 3) & 7), z = int(i & 7);
                    const float p = block.at(x, y, z);
                    next[k][i] = p;
                    if (weight_[k][i] == 0.0f) continue;
                    const double moved = p + dt * weight_[k][i] * curvatureTerm(block, x, y, z, h);
                    next[k][i] = std::clamp(float(moved), start[k][i] - most, start[k][i] + most);
                    ++n;
                }
            }
            updates.local() += n;
        });
        parallelFor(tbb::blocked_range<std::size_t>(0, flowing_.size()), [&](const auto& range) {
            for (std::size_t k = range.begin(); k != range.end(); ++k)
                std::copy(next[k].begin(), next[k].end(), leaves_[flowing_[k]]->buffer().data());
        });
        pollInterrupt(interrupter_);
    }
    stats_.updates = updates.combine(std::plus<>());
}

void CurvatureSmoother::renormalizeReach() {
    // The voxels within the reach less a voxel: beyond them every value stays as it was (the
    // box's corners too) but for an inactive voxel next to them that the band takes in.
    const openvdb::Vec3d c =
        grid_.worldToIndex({brush_.center.x(), brush_.center.y(), brush_.center.z()});
    const double r = renormalizedRadius();
    VoxelList inside;
    inside.reserve(leaves_.size());
    for (const Leaf* leaf : leaves_) {
        LeafVoxels lv{leaf->origin(), {}};
        for (openvdb::Index i = 0; i < Leaf::SIZE; ++i)
            if ((leaf->offsetToGlobalCoord(i).asVec3d() - c).lengthSqr() <= r * r)
                lv.words[i >> 6] |= leafwords::Word(1) << (i & 63);
        if (leafwords::any(lv.words)) inside.push_back(lv);
    }
    renormalize(grid_, reach_, inside, FmmOrder::Second, interrupter_);
}

SmoothStats smoothLevelSet(Grid& grid, const SmoothBrush& brush, Interrupter* interrupter) {
    return CurvatureSmoother(grid, brush, interrupter).run();
}

} // namespace sweepers
