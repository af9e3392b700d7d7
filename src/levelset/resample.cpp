// SPDX-License-Identifier: Apache-2.0
#include "levelset/resample.h"
#include "levelset/cell_interpolation.h"
#include "levelset/monotone_cubic.h"
#include "vdb/local_tree.h"
#include "vdb/parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace sweepers {

namespace {

// How far from the surface (in voxels) Sampling::Corrected corrects: farther out, the second
// differences read the band's clamp.
constexpr double kCorrectedReach = 2.5;

// How far from the surface (in voxels) sampling records the norm of the old values'
// gradient that a seed is divided by (RenormalizeOptions::gradientBefore): as far as the corrected
// sample reads its corners' differences. A seed's value is within a voxel and a half where the
// field is still a distance, but a field the segment compressed puts it farther out (two voxels and
// more on a pinch's hole wall, at a pulled tip), and such a seed, divided by its own
// gradient's norm, took a value the eikonal test refused.
constexpr double kSeedValues = kCorrectedReach;

// The source values around one leaf, in a dense block: a leaf's pre-images of a drag lie
// within a voxel or two of it, and their trilinear samples read the block by strides,
// where each of them took a tree lookup, and eight where the cell crosses a leaf border.
// Corrected samples read a voxel more around their cell: the rim of three voxels holds
// those of pre-images up to two voxels out, as trilinear samples' were with two.
class SourceBlock {
  public:
    static constexpr int kRim = 3, kDim = int(LeafNode::DIM) + 2 * kRim;

    // Fills the block around the leaf at `origin` from the source.
    void fill(const SampleSource::Accessor& acc, const openvdb::Coord& origin) {
        min_ = origin.offsetBy(-kRim);
        copyBox(
            openvdb::CoordBBox(min_, min_.offsetBy(kDim - 1)), values_.data(),
            [&](const openvdb::Coord& o) { return acc.leafAt(o); },
            [&](const openvdb::Coord& o) { return acc.getValue(o); });
    }

    // Whether the cell with lowest corner ijk lies in the block.
    bool holds(const openvdb::Coord& ijk) const {
        const openvdb::Coord d = ijk - min_;
        return d.x() >= 0 && d.y() >= 0 && d.z() >= 0 && d.x() < kDim - 1 && d.y() < kDim - 1 &&
               d.z() < kDim - 1;
    }
    // Trilinear interpolation in the cell with lowest corner ijk (held), at offset uvw.
    float trilinear(const openvdb::Coord& ijk, const openvdb::Vec3d& uvw) const {
        float data[2][2][2];
        const std::size_t o = index(ijk);
        for (std::size_t i = 0; i < 2; ++i)
            for (std::size_t j = 0; j < 2; ++j)
                for (std::size_t k = 0; k < 2; ++k)
                    data[i][j][k] = values_[o + i * kDim * kDim + j * kDim + k];
        return trilinearIn(data, uvw);
    }

    // The value at ijk, within kRim voxels of the leaf.
    float at(const openvdb::Coord& ijk) const { return values_[index(ijk)]; }
    // Whether the cell with lowest corner ijk and a voxel around it lie in the block.
    bool holdsAround(const openvdb::Coord& ijk) const {
        const openvdb::Coord d = ijk - min_;
        return d.x() >= 1 && d.y() >= 1 && d.z() >= 1 && d.x() < kDim - 2 && d.y() < kDim - 2 &&
               d.z() < kDim - 2;
    }
    // Sampling::Corrected in the cell with lowest corner ijk (held with a voxel around it).
    // Kept out of the sampling loop: inlined there, its many live values crowd the loop's
    // registers, and the loop as a whole runs slower.
    __attribute__((noinline)) float corrected(const openvdb::Coord& ijk, const openvdb::Vec3d& uvw,
                                              float reach, float* slope = nullptr) const {
        const std::size_t o = index(ijk);
        return correctedIn(
            [&](int i, int j, int k) {
                const std::ptrdiff_t step = (std::ptrdiff_t(i) * kDim + j) * kDim + k;
                return values_[std::size_t(std::ptrdiff_t(o) + step)];
            },
            uvw, reach, slope);
    }

  private:
    std::size_t index(const openvdb::Coord& ijk) const {
        const openvdb::Coord d = ijk - min_;
        return (std::size_t(d.x()) * kDim + std::size_t(d.y())) * kDim + std::size_t(d.z());
    }
    openvdb::Coord min_;
    std::array<float, std::size_t(kDim) * kDim * kDim> values_;
};

// Per thread, what sampling a leaf uses: the block of source values around it, and its
// voxels to sample with their places and pre-images.
struct ResampleScratch {
    MapScratch maps;
    SourceBlock block;
    std::array<std::uint16_t, LeafNode::SIZE> at;
    std::array<Eigen::Vector3d, LeafNode::SIZE> x, y;
};
} // namespace

void Staged::reserve(std::size_t leaves, std::atomic<std::size_t>& growths) {
    const std::size_t n = leaves * LeafNode::SIZE;
    if (n <= capacity) return;
    capacity = std::max(2 * n, 2 * capacity);
    values.reset(new float[capacity]);
    ++growths;
}

void Staged::swapInto(const std::vector<LeafNode*>& leaves) {
    parallelFor(std::size_t(0), leaves.size(), [&](std::size_t l) {
        forEachChanged(l, leaves[l]->buffer().data(), [](float* to, float* from, std::size_t pos) {
            std::swap(to[pos], from[pos]);
        });
    });
}

std::shared_ptr<SampleSource> SampleSource::copyOnWrite(const Grid& live,
                                                        const std::vector<LeafNode*>& leaves) {
    return std::make_shared<SampleSource>(live, copyLeaves(live, leaves));
}

std::shared_ptr<SampleSource> SampleSource::live(const Grid& live) {
    return std::make_shared<SampleSource>(live, copyLeaves(live, std::vector<LeafNode*>{}));
}

namespace {

// Copied in parallel, then put in the tree (which is not safe to grow in parallel).
template <typename Leaves> void addCopiesOf(Grid& copies, const Leaves& leaves) {
    std::vector<LeafNode*> made(leaves.size());
    parallelFor(std::size_t(0), leaves.size(),
                [&](std::size_t i) { made[i] = new LeafNode(*leaves[i]); });
    for (LeafNode* leaf : made)
        copies.tree().addLeaf(leaf);
}

} // namespace

void SampleSource::addCopies(Grid& copies, const std::vector<LeafNode*>& leaves) {
    addCopiesOf(copies, leaves);
}

void SampleSource::addCopies(Grid& copies, const std::vector<const LeafNode*>& leaves) {
    addCopiesOf(copies, leaves);
}

void SampleSource::freeCopies() {
    if (copies_.use_count() == 1) freeOnThisThread(copies_->tree());
}

void SampleSource::copyAlso(const std::vector<LeafNode*>& leaves, const Staged& staged) {
    std::vector<LeafNode*> made(leaves.size());
    parallelFor(std::size_t(0), leaves.size(), [&](std::size_t l) {
        made[l] = new LeafNode(*leaves[l]);
        staged.forEachChanged(
            l, made[l]->buffer().data(),
            [](float* to, const float* from, std::size_t pos) { to[pos] = from[pos]; });
    });
    for (LeafNode* leaf : made)
        copies_->tree().addLeaf(leaf);
}

void farWithSigns(LeafNode& leaf, float far, const Grid::ConstAccessor& live) {
    for (auto it = leaf.beginValueAll(); it; ++it)
        it.setValue(live.getValue(it.getCoord()) < 0.0f ? -far : far);
}

struct Resampler::Scratch {
    tbb::enumerable_thread_specific<ResampleScratch> threads;
};

Resampler::Resampler() : scratch_(std::make_unique<Scratch>()) {}
Resampler::~Resampler() = default;
Resampler::Resampler(Resampler&&) noexcept = default;
Resampler& Resampler::operator=(Resampler&&) noexcept = default;

namespace {

// How far p (index space) lies from the surface the grid's values place, in voxels: the
// distance to the nearest crossing of an edge between active voxels (linearly placed), or
// `most` when none is nearer. Only the leaves within `most` of p are read.
double depthBelowSurface(const Grid& grid, const openvdb::Vec3d& p, double most) {
    const openvdb::CoordBBox box(openvdb::Coord::floor(p - openvdb::Vec3d(most)),
                                 openvdb::Coord::floor(p + openvdb::Vec3d(most)) +
                                     openvdb::Coord(1));
    std::vector<const LeafNode*> near;
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf)
        if (box.hasOverlap(leaf->getNodeBoundingBox())) near.push_back(leaf.getLeaf());
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, near.size()), most,
        [&](const tbb::blocked_range<std::size_t>& r, double nearest) {
            const Grid::ConstAccessor acc = grid.getConstAccessor();
            for (std::size_t l = r.begin(); l != r.end(); ++l)
                for (auto it = near[l]->cbeginValueOn(); it; ++it) {
                    const openvdb::Coord c = it.getCoord();
                    const float v = *it;
                    for (int a = 0; a < 3; ++a) {
                        openvdb::Coord n = c;
                        ++n[a];
                        const float w = acc.getValue(n);
                        if ((v < 0.0f) == (w < 0.0f)) continue;
                        openvdb::Vec3d at = c.asVec3d();
                        at[a] += double(v) / (double(v) - double(w));
                        nearest = std::min(nearest, (at - p).length());
                    }
                }
            return nearest;
        },
        [](double x, double y) { return std::min(x, y); });
}

} // namespace

SurfaceExit GridProbe::firstExit(const Eigen::Vector3d& from, const Eigen::Vector3d& direction,
                                 double start, double most) const {
    // Steps of the value's own size (a distance: no crossing is nearer), a quarter voxel at
    // least, then the crossing between the last two samples, linearly, and the central
    // differences there. (A ray that enters the shape within a quarter voxel of `start` is
    // taken as starting inside: the gap it crossed first is far below what the grid resolves
    // once the map blows it up.)
    const auto at = [&](const Eigen::Vector3d& p) {
        return double(acc_.trilinear(place_.toIndex(toVdb(p))));
    };
    const auto exitAt = [&](double t) {
        SurfaceExit e{t, Eigen::Vector3d::Zero()};
        const Eigen::Vector3d p = from + t * direction;
        for (int a = 0; a < 3; ++a) {
            const Eigen::Vector3d d = h_ * Eigen::Vector3d::Unit(a);
            e.gradient[a] = (at(p + d) - at(p - d)) / (2.0 * h_);
        }
        return e;
    };
    double t = start, v = at(from + t * direction);
    if (v >= 0.0) {
        // From the surface itself, a ray into the shape meets it again where it leaves.
        const double in = start + 0.25 * h_, w = at(from + in * direction);
        if (w >= 0.0) return exitAt(t);
        t = in;
        v = w;
    }
    while (t < most) {
        const double next = std::min(most, t + std::max(-v, 0.25 * h_));
        const double w = at(from + next * direction);
        if (w >= 0.0) return exitAt(t - v * (next - t) / (w - v));
        t = next;
        v = w;
    }
    return {most, Eigen::Vector3d::Zero()};
}

double filledFromValue(const Grid& grid, const StepDeformation& seg, Sampling sampling) {
    const SampleSource source(grid, Grid::create());
    const SampleSource::Accessor acc(source);
    const openvdb::Vec3d p = VoxelPlacement(grid.transform()).toIndex(toVdb(seg.filledFrom()));
    const double h = grid.voxelSize()[0];
    const float reach = float(kCorrectedReach * h);
    const double v = sampling == Sampling::MonotoneCubic ? sampleMonotoneCubic(acc, p)
                     : sampling == Sampling::Corrected   ? acc.corrected(p, reach)
                                                         : acc.trilinear(p);
    // Deeper than the band, the values say only that: the depth is found from the surface.
    if (v > -0.999 * double(grid.background()) || !(seg.deepestFill() > 0.0)) return v;
    const double most = seg.deepestFill() / h + 1.0;
    const double depth = depthBelowSurface(grid, p, most);
    return depth < most ? -depth * h : v;
}

std::size_t Resampler::run(Grid& grid, const std::vector<LeafNode*>& leaves,
                           const SampleSource& source, const ResamplePlan& plan,
                           const ResampleOutput& out) {
    // Read once: the loops below write floats, which the compiler must otherwise assume may
    // change the plan's and output's numbers.
    const openvdb::CoordBBox& box = plan.box;
    const bool sourceIsGrid = plan.sourceIsGrid;
    const float nudge = out.nudge;
    const Sampling sampling = plan.sampling;
    const StepDeformation* seg = plan.tearsOrFills;
    const double tornWindow = plan.tornWindow;
    Staged* const staged = out.staged;
    VoxelValues* const gradientBefore = out.gradientBefore;
    // Per leaf, the voxels whose value changed and those that moved (a word per x, as the
    // leaf's mask holds them): written by the leaf's own task, then listed.
    std::vector<leafwords::Words> changedWords(leaves.size()), movedWords(leaves.size());
    std::atomic<std::size_t> count{0};
    const VoxelPlacement place(grid.transform());
    const StepDeformation* tearing = seg && seg->tears() ? seg : nullptr;
    const double fromValue = plan.filledFrom;
    // (Where the fill does not apply, no voxel looks at it.)
    const StepDeformation* filling = seg && seg->fillsWith(fromValue) ? seg : nullptr;
    const Box filledBox = filling ? filling->filledBox(fromValue) : Box();
    const bool windowPastRim = tearing && tearing->windowPastRim();
    const double h = grid.voxelSize()[0];
    const float carryBelow = float(0.999 * std::abs(grid.background()));
    const Box carriedBox = filling ? filling->carriedReach() : Box();
    const float reach = float(kCorrectedReach * h), seedReach = float(kSeedValues * h);
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& range) {
        const SampleSource::Accessor acc(source);
        const GridProbe probe(acc, grid.transform());
        ResampleScratch& s = scratch_->threads.local();
        SourceBlock& block = s.block;
        std::size_t n = 0;
        pollInterrupt(plan.interrupter);
        for (std::size_t l = range.begin(); l != range.end(); ++l) {
            LeafNode& leaf = *leaves[l];
            // The leaf as the source holds it (a copy where sampling writes this one), to tell
            // which voxels the band grew into.
            const LeafNode* before = acc.leafAt(leaf.origin());
            if (gradientBefore) {
                LeafValues& g = (*gradientBefore)[l];
                g.origin = leaf.origin();
                g.values.fill(std::numeric_limits<float>::quiet_NaN());
            }
            // With `only`, just the active voxels it holds are sampled.
            const auto* wanted = plan.only ? plan.only->probeConstLeaf(leaf.origin()) : nullptr;
            if (plan.only && !wanted) continue;
            // The leaf's pre-images first, all of them, then its samples: each loop's steps
            // are independent from one voxel to the next, so the processor overlaps them,
            // where a sample waited on its map's call and the next map on the sample.
            const leafwords::Words inBox = leafwords::inBox(box, leaf.origin());
            int listed = 0;
            for (int wx = 0; wx < 8; ++wx) {
                leafwords::Word word =
                    leaf.getValueMask().getWord<leafwords::Word>(wx) & inBox[std::size_t(wx)];
                if (wanted) word &= wanted->getValueMask().getWord<leafwords::Word>(wx);
                for (; word; word &= word - 1)
                    s.at[std::size_t(listed++)] = std::uint16_t(wx * 64 + __builtin_ctzll(word));
            }
            for (int i = 0; i < listed; ++i) {
                const openvdb::Coord ijk = LeafNode::offsetToLocalCoord(s.at[std::size_t(i)]);
                s.x[std::size_t(i)] = toEigen(place.toWorld((leaf.origin() + ijk).asVec3d()));
            }
            plan.map(s.x.data(), std::size_t(listed), s.y.data(), s.maps);
            bool filled = false; // the block is filled for the leaf's first sample
            const float* values = leaf.buffer().data();
            float* const written =
                staged ? &staged->values[l * LeafNode::SIZE] : leaf.buffer().data();
            for (int i = 0; i < listed; ++i) {
                const int pos = s.at[std::size_t(i)];
                const Eigen::Vector3d& x = s.x[std::size_t(i)];
                const Eigen::Vector3d& y = s.y[std::size_t(i)];
                const float old = values[pos];
                float v = old;
                float slope[3] = {std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f};
                bool madeDistance = false; // by the fill of what has no pre-image
                if (y != x || !sourceIsGrid) {
                    const auto sample = [&](const Eigen::Vector3d& at, float* slopeAt = nullptr) {
                        const openvdb::Vec3d p = place.toIndex(toVdb(at));
                        if (sampling == Sampling::MonotoneCubic)
                            return float(sampleMonotoneCubic(acc, p));
                        const openvdb::Coord cell = cellOf(p);
                        if (!filled) {
                            block.fill(acc, leaf.origin());
                            filled = true;
                        }
                        if (sampling == Sampling::Corrected)
                            return block.holdsAround(cell)
                                       ? block.corrected(cell, p - cell.asVec3d(), reach, slopeAt)
                                       : acc.corrected(p, reach, slopeAt);
                        return block.holds(cell) ? block.trilinear(cell, p - cell.asVec3d())
                                                 : acc.trilinear(p);
                    };
                    const bool carries = filling && carriedBox.contains(x);
                    v = sample(y, gradientBefore || carries ? slope : nullptr);
                    if (tearing) {
                        const double depth = tearing->openedDepth(x);
                        if (depth > 0.0 || (windowPastRim && depth > -tornWindow)) {
                            const Eigen::Vector3d along =
                                tearing->alongTorn(x) * (0.5 * tornWindow);
                            float window = v;
                            for (int t = -2; t <= 2; ++t)
                                if (t != 0)
                                    window = std::max(window, sample(y + double(t) * along));
                            // Past the rim the window's value falls off as the distance to the
                            // rim, as a distance would from a wall on the rim (1-Lipschitz).
                            v = std::max(v, window + float(std::min(0.0, depth)));
                        }
                        v = std::max(v, float(tearing->leastValue(y))) +
                            float(std::max(0.0, depth));
                    }
                    if (carries && std::abs(v) < carryBelow) {
                        // (A value the source holds at its background carries no distance.)
                        // The gradient at the pre-image: the sample's own central differences
                        // where it read them, else the samples a voxel either way.
                        Eigen::Vector3d g;
                        for (int a = 0; a < 3; ++a) {
                            const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(a);
                            g[a] = std::isnan(slope[0])
                                       ? double(sample(y + e) - sample(y - e)) / (2.0 * h)
                                       : double(slope[a]) / h;
                        }
                        const float carried = float(filling->carriedValue(x, v, g));
                        madeDistance = carried != v;
                        v = carried;
                    }
                    if (filling && filledBox.contains(x)) {
                        const float filled = float(filling->filledValue(x, v, fromValue, &probe));
                        madeDistance = madeDistance || filled != v;
                        v = filled;
                    }
                }
                if (madeDistance && gradientBefore && std::abs(v) < seedReach) {
                    // A filled value is a distance already: no stretch to divide it by.
                    (*gradientBefore)[l].values[std::size_t(pos)] = 1.0f;
                } else if (gradientBefore && std::abs(v) < seedReach) {
                    // The source's central differences at the pre-image
                    // (RenormalizeOptions::gradientBefore): from the sample's own reads, or, for a
                    // voxel that kept its value, its neighbours'.
                    if (std::isnan(slope[0])) {
                        if (!filled) {
                            block.fill(acc, leaf.origin());
                            filled = true;
                        }
                        const openvdb::Coord c = leaf.offsetToGlobalCoord(openvdb::Index(pos));
                        for (int a = 0; a < 3; ++a) {
                            openvdb::Coord e(0);
                            e[a] = 1;
                            slope[a] = 0.5f * (block.at(c + e) - block.at(c - e));
                        }
                    }
                    const float norm =
                        std::sqrt(slope[0] * slope[0] + slope[1] * slope[1] + slope[2] * slope[2]);
                    (*gradientBefore)[l].values[std::size_t(pos)] = norm / float(h);
                }
                const bool joined =
                    !(before ? before->isValueOn(openvdb::Index(pos))
                             : acc.isValueOn(leaf.offsetToGlobalCoord(openvdb::Index(pos))));
                const leafwords::Word bit = leafwords::Word(1) << (pos & 63);
                if (v != old || joined) changedWords[l][std::size_t(pos >> 6)] |= bit;
                if (std::abs(v - old) > nudge || joined)
                    movedWords[l][std::size_t(pos >> 6)] |= bit;
                written[pos] = v;
            }
            n += std::size_t(listed);
        }
        count += n;
    });
    for (std::size_t l = 0; l < leaves.size(); ++l) {
        if (leafwords::any(changedWords[l]))
            out.changed->push_back({leaves[l]->origin(), changedWords[l]});
        if (leafwords::any(movedWords[l]))
            out.moved->push_back({leaves[l]->origin(), movedWords[l]});
    }
    if (staged) staged->changed = std::move(changedWords);
    return count;
}

} // namespace sweepers
