// SPDX-License-Identifier: Apache-2.0
#include "levelset/smooth.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/enumerable_thread_specific.h>

#include "core/falloff.h"
#include "core/format.h"
#include "core/limits.h"
#include "core/stopwatch.h"
#include "levelset/dilate.h"
#include "levelset/padded_leaf.h"
#include "levelset/renormalize.h"
#include "vdb/parallel.h"

namespace sweepers {

namespace {

using Leaf = Grid::TreeType::LeafNodeType;

// The filter's multiply-adds that take as long as a voxel's explicit step (the curvature
// term's differences, about 40 of them, read from a padded leaf): the filter's work is
// counted in explicit updates, so that the two compare.
constexpr double kOperationsPerUpdate = 70.0;

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

CurvatureSmoother::CurvatureSmoother(Grid& grid, const SmoothBrush& brush, Interrupter* interrupter,
                                     const SmoothOptions& options)
    : grid_(grid), brush_(brush), interrupter_(interrupter), options_(options) {
    const double h = grid.voxelSize()[0];
    centre_ = grid.worldToIndex({brush.center.x(), brush.center.y(), brush.center.z()});
    const openvdb::Vec3d c = centre_;
    // The brush's reach, the band around it (renormalization rebuilds the band there) and
    // the voxel the central differences read beyond it.
    const double margin = reachRadius() / h + 2.0;
    reach_ = openvdb::CoordBBox(openvdb::Coord::floor(c - openvdb::Vec3d(margin)),
                                openvdb::Coord::ceil(c + openvdb::Vec3d(margin)));
}

double CurvatureSmoother::renormalizedRadius() const {
    return reachRadius() / grid_.voxelSize()[0] - 1.0;
}

const SmoothStats& CurvatureSmoother::plan() {
    if (planned_) return stats_;
    planned_ = true;
    const auto start = Clock::now();
    stats_ = SmoothStats();
    stats_.changed = reach_;
    if (!(brush_.time > 0.0) || !(brush_.radius > 0.0)) return stats_;
    // The reach and the voxel the differences read beyond it; where the filter may run, the
    // band it reads too, from which those within the reach are taken.
    const double reach = reachRadius() / grid_.voxelSize()[0] + 2.0;
    std::vector<Leaf*> around;
    if (options_.scheme != SmoothScheme::ExplicitFlow &&
        sigmaVoxels() >= DistanceFilter::kSmallestSigma) {
        filter_ =
            std::make_unique<DistanceFilter>(grid_, sigmaVoxels(), openvdb::Coord::round(centre_));
        // The splat's, blur's and slice's reach around the voxels that flow, in voxels.
        const DistanceFilterStats& f = filter_->stats();
        const int grow = (f.radius + 2) * f.spacing + 1;
        around = leavesIn(
            std::max(reach, (brush_.radius + brush_.falloff) / grid_.voxelSize()[0] + 1.0 + grow));
        for (Leaf* leaf : around)
            if (leafNear(leaf->origin(), reach)) leaves_.push_back(leaf);
    } else {
        leaves_ = leavesIn(reach);
    }
    stats_.leaves = leaves_.size();
    weigh();
    estimateWork(around);
    const bool filter = stats_.filterWork > 0.0 && (options_.scheme == SmoothScheme::Filter ||
                                                    stats_.filterWork < stats_.flowWork);
    stats_.scheme = filter ? SmoothScheme::Filter : SmoothScheme::ExplicitFlow;
    stats_.work = stats_.scheme == SmoothScheme::Filter ? stats_.filterWork : stats_.flowWork;
    if (!filter) filter_.reset();
    stats_.planSeconds = secondsSince(start);
    return stats_;
}

SmoothStats CurvatureSmoother::run() {
    plan();
    if (!(brush_.time > 0.0) || !(brush_.radius > 0.0)) return stats_;
    requireWork(stats_.work, workDescription());
    pollInterrupt(interrupter_);
    const auto update = Clock::now();
    if (stats_.scheme == SmoothScheme::Filter) {
        // The filter reads only the band as it is: the band grows afterwards, as far as the
        // surface moved.
        filter();
        widenBand(int(std::ceil(stats_.mostChange / grid_.voxelSize()[0])));
    } else {
        widenBand(2);
        flow();
    }
    pollInterrupt(interrupter_);
    stats_.updateSeconds = secondsSince(update);
    const auto renormalization = Clock::now();
    renormalizeReach();
    stats_.renormalizeSeconds = secondsSince(renormalization);
    return stats_;
}

bool CurvatureSmoother::leafNear(const openvdb::Coord& origin, double radius) const {
    const openvdb::Vec3d c = centre_;
    const openvdb::Vec3d lo = origin.asVec3d(), hi = lo + openvdb::Vec3d(Leaf::DIM - 1);
    const openvdb::Vec3d nearest(std::clamp(c.x(), lo.x(), hi.x()),
                                 std::clamp(c.y(), lo.y(), hi.y()),
                                 std::clamp(c.z(), lo.z(), hi.z()));
    return (nearest - c).lengthSqr() <= radius * radius;
}

std::vector<CurvatureSmoother::Leaf*> CurvatureSmoother::leavesIn(double radius) {
    std::vector<Leaf*> leaves;
    const openvdb::Vec3d c = centre_;
    const openvdb::CoordBBox box(openvdb::Coord::floor(c - openvdb::Vec3d(radius)),
                                 openvdb::Coord::ceil(c + openvdb::Vec3d(radius)));
    const auto near = [&](const openvdb::Coord& origin) { return leafNear(origin, radius); };
    // Leaf by leaf origin inside the ball's box: the work is the brush's, not the grid's. A
    // brush larger than the shape would probe mostly empty space: then the grid's own
    // leaves are walked instead, so the work is the smaller of the two.
    const openvdb::Coord lo = box.min() & ~(Leaf::DIM - 1), hi = box.max();
    const openvdb::Coord slots = ((hi - lo) >> Leaf::LOG2DIM) + openvdb::Coord(1);
    const double probes = double(slots.x()) * slots.y() * slots.z();
    if (probes > double(grid_.tree().leafCount())) {
        for (auto it = grid_.tree().beginLeaf(); it; ++it) {
            ++stats_.leavesVisited;
            if (near(it->origin())) leaves.push_back(&*it);
        }
    } else {
        // Slab by slab along x in parallel, put together in order.
        std::vector<std::vector<Leaf*>> slab(std::size_t(slots.x()));
        std::vector<std::size_t> visited(std::size_t(slots.x()), 0);
        parallelFor(tbb::blocked_range<std::size_t>(0, slab.size()), [&](const auto& range) {
            for (std::size_t k = range.begin(); k != range.end(); ++k) {
                const int x = lo.x() + int(k) * int(Leaf::DIM);
                for (int y = lo.y(); y <= hi.y(); y += Leaf::DIM)
                    for (int z = lo.z(); z <= hi.z(); z += Leaf::DIM) {
                        if (!near({x, y, z})) continue;
                        ++visited[k];
                        if (Leaf* leaf = grid_.tree().probeLeaf({x, y, z})) slab[k].push_back(leaf);
                    }
            }
        });
        for (std::size_t k = 0; k < slab.size(); ++k) {
            stats_.leavesVisited += visited[k];
            leaves.insert(leaves.end(), slab[k].begin(), slab[k].end());
        }
    }
    return leaves;
}

float CurvatureSmoother::weightAt(const openvdb::Coord& ijk) const {
    // Distances in index space times h (the grid's map is a uniform scale, turned and
    // moved).
    const double d = (ijk.asVec3d() - centre_).length() * grid_.voxelSize()[0] - brush_.radius;
    return float(falloffMu(d, brush_.falloff));
}

void CurvatureSmoother::weigh() {
    const float bg = grid_.background();
    // Band voxels within the falloff's reach (not those at +-background: they hold no
    // distance). Leaves wholly beyond it are passed over.
    std::vector<leafwords::Words> words(leaves_.size());
    const double reached = (brush_.radius + brush_.falloff) / grid_.voxelSize()[0] + 1.0;
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves_.size()), [&](const auto& range) {
        for (std::size_t l = range.begin(); l != range.end(); ++l) {
            const Leaf& leaf = *leaves_[l];
            words[l].fill(0);
            if (!leafNear(leaf.origin(), reached)) continue;
            for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
                if (!leaf.isValueOn(i) || std::abs(leaf.getValue(i)) >= bg) continue;
                if (weightAt(leaf.offsetToGlobalCoord(i)) > 0.0f)
                    words[l][i >> 6] |= leafwords::Word(1) << (i & 63);
            }
        }
    });
    flowing_.clear();
    weighted_.clear();
    for (std::size_t l = 0; l < leaves_.size(); ++l) {
        if (!leafwords::any(words[l])) continue;
        flowing_.push_back(l);
        weighted_.push_back({leaves_[l]->origin(), words[l]});
    }
}

// A dab may move the surface by two voxels: the band grows by as many voxels around the
// voxels that flow (within the renormalized ball), so that the renormalization finds band on
// whichever side the surface moved to. The new voxels keep the value they held
// (+-background, of the right sign) and take no part in the flow; the renormalization gives
// them distances, or drops them past the half-width.
void CurvatureSmoother::widenBand(int layers) {
    if (layers <= 0) return;
    const openvdb::Vec3d c = centre_;
    const double r = renormalizedRadius();
    VoxelList grown = dilatedByCube(weighted_, layers); // each leaf once
    std::vector<Leaf*> leaf(grown.size(), nullptr);
    parallelFor(tbb::blocked_range<std::size_t>(0, grown.size()), [&](const auto& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            LeafVoxels& lv = grown[k];
            for (openvdb::Index i = 0; i < Leaf::SIZE; ++i)
                if (((lv.origin + Leaf::offsetToLocalCoord(i)).asVec3d() - c).lengthSqr() > r * r)
                    lv.words[i >> 6] &= ~(leafwords::Word(1) << (i & 63));
            if (leafwords::any(lv.words)) leaf[k] = grid_.tree().probeLeaf(lv.origin);
        }
    });
    // Leaves the band grows into are made one by one (the tree's structure changes) and
    // renormalized with the others; then each leaf's voxels join in parallel.
    for (std::size_t k = 0; k < grown.size(); ++k)
        if (!leaf[k] && leafwords::any(grown[k].words)) {
            leaf[k] = grid_.tree().touchLeaf(grown[k].origin);
            leaves_.push_back(leaf[k]);
        }
    std::vector<leafwords::Words> fresh(grown.size());
    parallelFor(tbb::blocked_range<std::size_t>(0, grown.size()), [&](const auto& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            fresh[k].fill(0);
            if (!leaf[k]) continue;
            for (std::size_t w = 0; w < 8; ++w) {
                const leafwords::Word added =
                    grown[k].words[w] &
                    ~leaf[k]->valueMask().template getWord<leafwords::Word>(openvdb::Index(w));
                fresh[k][w] = added;
            }
            for (openvdb::Index i = 0; i < Leaf::SIZE; ++i)
                if ((fresh[k][i >> 6] >> (i & 63)) & 1) leaf[k]->setValueOn(i);
        }
    });
    for (std::size_t k = 0; k < grown.size(); ++k)
        if (leafwords::any(fresh[k])) fresh_.push_back({grown[k].origin, fresh[k]});
}

double CurvatureSmoother::stepCount() const {
    const double h = grid_.voxelSize()[0];
    // Explicit steps of the central scheme are stable for dt <= h^2 / 4: along the surface
    // (|grad phi| = 1) the flow is a diffusion in two dimensions, whose fastest mode (the
    // checkerboard) decays at 8 / h^2. A little under it.
    const double dtMax = 0.9 * h * h / 4.0;
    return std::max(1.0, std::ceil(brush_.time / dtMax));
}

double CurvatureSmoother::sigmaVoxels() const {
    return std::sqrt(2.0 * brush_.time) / grid_.voxelSize()[0];
}

// The dab's work, checked against the work limit before the grid changes (a ball far larger
// than the shape, or far finer a grid, would run for hours), counted in voxel updates of the
// explicit flow: its steps times the voxels that flow. The filter's splat, blur and
// read-back count kOperationsPerUpdate multiply-adds an update. A dab runs the scheme that
// takes less.
void CurvatureSmoother::estimateWork(const std::vector<Leaf*>& around) {
    double voxels = 0.0;
    for (const LeafVoxels& lv : weighted_)
        for (const leafwords::Word w : lv.words)
            voxels += double(__builtin_popcountll(w));
    stats_.weighted = std::size_t(voxels);
    stats_.flowWork = stepCount() * voxels;
    if (filter_) {
        filter_->plan(std::vector<const Leaf*>(around.begin(), around.end()), weighted_);
        stats_.latticeSpacing = filter_->stats().spacing;
        stats_.filterWork = (filter_->stats().work + 64.0 * voxels) / kOperationsPerUpdate;
    }
}

std::string CurvatureSmoother::workDescription() const {
    const std::string dab = "a smooth dab of radius " + formatNumber(brush_.radius);
    if (stats_.scheme == SmoothScheme::Filter)
        return dab + " (a filter over " + formatNumber(double(stats_.weighted)) + " voxels)";
    return dab + " (" + formatNumber(stepCount()) + " steps of " +
           formatNumber(double(stats_.weighted)) + " voxels)";
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
    // The brush's weight at every voxel that flows, read at each step.
    std::vector<std::array<float, Leaf::SIZE>> weight(flowing_.size());
    std::vector<PaddedLeaf::Around> around(flowing_.size());
    parallelFor(tbb::blocked_range<std::size_t>(0, flowing_.size()), [&](const auto& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            const Leaf& leaf = *leaves_[flowing_[k]];
            around[k] = PaddedLeaf::around(grid_, leaf);
            for (openvdb::Index i = 0; i < Leaf::SIZE; ++i)
                weight[k][i] = ((weighted_[k].words[i >> 6] >> (i & 63)) & 1)
                                   ? weightAt(leaf.offsetToGlobalCoord(i))
                                   : 0.0f;
        }
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
                    if (weight[k][i] == 0.0f) continue;
                    const double moved = p + dt * weight[k][i] * curvatureTerm(block, x, y, z, h);
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

void CurvatureSmoother::filter() {
    const double h = grid_.voxelSize()[0];
    filter_->splat();
    pollInterrupt(interrupter_);
    filter_->blur();
    pollInterrupt(interrupter_);
    // Each voxel under the brush goes w of the way to the filtered distance (at most two
    // voxels); all are computed from the values before the dab, then written.
    const float most = float(2.0 * h), toVoxels = float(1.0 / h);
    // The voxels next to the surface, whose changes bound its motion. A change of less than
    // a hundredth of a voxel is a nudge, left out as advection leaves it out (levelset/
    // advect.h): the values stay distances, and seeding again next to nudges alone would
    // let the surface creep.
    const float bg = grid_.background(), shell = float(1.5 * h), nudge = float(0.01 * h);
    changed_.resize(flowing_.size());
    for (std::size_t k = 0; k < flowing_.size(); ++k)
        changed_[k] = {leaves_[flowing_[k]]->origin(), {}};
    std::vector<std::array<float, Leaf::SIZE>> next(flowing_.size());
    tbb::enumerable_thread_specific<std::size_t> updates(0);
    tbb::enumerable_thread_specific<float> changes(0.0f);
    parallelFor(tbb::blocked_range<std::size_t>(0, flowing_.size()), [&](const auto& range) {
        float& changeMost = changes.local();
        PaddedLeaf block;
        std::array<openvdb::Vec3f, Leaf::SIZE> gradient;
        std::array<float, Leaf::SIZE> u;
        std::size_t n = 0;
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            const Leaf& leaf = *leaves_[flowing_[k]];
            block.load(PaddedLeaf::around(grid_, leaf));
            const leafwords::Words& weighted = weighted_[k].words;
            for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
                if (!((weighted[i >> 6] >> (i & 63)) & 1)) continue;
                const int x = int(i >> 6), y = int((i >> 3) & 7), z = int(i & 7);
                // Central differences, or one-sided ones where a neighbour lies past the band
                // (its value is the background, no distance).
                const float p = block.at(x, y, z);
                const auto slope = [&](float below, float above) {
                    const bool b = std::abs(below) < bg, a = std::abs(above) < bg;
                    return a && b ? 0.5f * (above - below) : a ? above - p : b ? p - below : 0.0f;
                };
                gradient[i] = openvdb::Vec3f(slope(block.at(x - 1, y, z), block.at(x + 1, y, z)),
                                             slope(block.at(x, y - 1, z), block.at(x, y + 1, z)),
                                             slope(block.at(x, y, z - 1), block.at(x, y, z + 1))) *
                              toVoxels;
            }
            filter_->read(leaf.origin(), weighted_[k].words, gradient, u);
            const float* values = leaf.buffer().data();
            for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
                const float p = values[i];
                next[k][i] = p;
                if (!((weighted[i >> 6] >> (i & 63)) & 1) || !std::isfinite(u[i])) continue;
                const float w = weightAt(leaf.offsetToGlobalCoord(i));
                const float moved = std::clamp(p + w * (u[i] * float(h) - p), p - most, p + most);
                if (!(std::abs(moved - p) >= nudge)) continue;
                next[k][i] = moved;
                changed_[k].words[i >> 6] |= leafwords::Word(1) << (i & 63);
                if (std::abs(p) < shell)
                    changeMost = std::max(changeMost, std::abs(next[k][i] - p));
                ++n;
            }
        }
        updates.local() += n;
    });
    parallelFor(tbb::blocked_range<std::size_t>(0, flowing_.size()), [&](const auto& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k)
            std::copy(next[k].begin(), next[k].end(), leaves_[flowing_[k]]->buffer().data());
    });
    stats_.updates = updates.combine(std::plus<>());
    stats_.mostChange = changes.combine([](float a, float b) { return std::max(a, b); });
}

void CurvatureSmoother::renormalizeReach() {
    // The voxels within the reach less a voxel: beyond them every value stays as it was (the
    // box's corners too) but for an inactive voxel next to them that the band takes in.
    const openvdb::Vec3d c = centre_;
    const double r = renormalizedRadius();
    const auto clip = [&](LeafVoxels& lv) {
        for (openvdb::Index i = 0; i < Leaf::SIZE; ++i)
            if (((lv.origin + Leaf::offsetToLocalCoord(i)).asVec3d() - c).lengthSqr() > r * r)
                lv.words[i >> 6] &= ~(leafwords::Word(1) << (i & 63));
    };
    if (stats_.scheme == SmoothScheme::Filter) {
        // Where values changed, and as far as the band reaches from there, as after a
        // segment; seeds again only next to what moved.
        VoxelList freed =
            dilatedByCube(changed_, int(std::ceil(grid_.background() / grid_.voxelSize()[0])) + 1);
        for (LeafVoxels& lv : freed)
            clip(lv);
        VoxelList moved = changed_;
        freed.insert(freed.end(), fresh_.begin(), fresh_.end());
        moved.insert(moved.end(), fresh_.begin(), fresh_.end());
        RenormalizeOptions o;
        o.region = reach_;
        o.only = &freed;
        o.moved = &moved;
        o.interrupter = interrupter_;
        renormalize(grid_, o);
        return;
    }
    VoxelList inside;
    inside.reserve(leaves_.size());
    for (const Leaf* leaf : leaves_) {
        LeafVoxels lv{leaf->origin(), {}};
        lv.words.fill(~leafwords::Word(0));
        clip(lv);
        if (leafwords::any(lv.words)) inside.push_back(lv);
    }
    RenormalizeOptions o;
    o.region = reach_;
    o.only = &inside;
    o.interrupter = interrupter_;
    renormalize(grid_, o);
}

SmoothStats smoothLevelSet(Grid& grid, const SmoothBrush& brush, Interrupter* interrupter,
                           const SmoothOptions& options) {
    return CurvatureSmoother(grid, brush, interrupter, options).run();
}

} // namespace sweepers
