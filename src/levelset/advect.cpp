// SPDX-License-Identifier: Apache-2.0
#include "levelset/advect.h"
#include "core/stopwatch.h"
#include "levelset/band.h"
#include "levelset/dilate.h"
#include "levelset/leaf_words.h"
#include "levelset/local_tree.h"
#include "levelset/monotone_cubic.h"
#include "levelset/parallel.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/Morphology.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace sweepers {

namespace {

// The stretch of the inverse map varies smoothly along the surface: measuring it at one
// interface voxel in four finds its maximum to within the margin the widening adds.
constexpr std::size_t kStretchSampling = 4;

// How far around the images of the surface sampling reaches: a seed of renormalization lies
// within a voxel of the new surface along an axis, and its central differences read one more.
constexpr int kSeedReach = 2;

// How far from the surface (in voxels) Sampling::Corrected corrects: farther out, the second
// differences read the band's clamp.
constexpr double kCorrectedReach = 2.5;

// How far from the surface (in voxels) sampling records the norm of the old values'
// gradient that a seed is divided by (renormalize()): as far as the corrected sample reads
// its corners' differences. A seed's value is within a voxel and a half where the field is
// still a distance, but a field the segment compressed puts it farther out (two voxels and
// more on a pinch's hole wall, at a pulled tip), and such a seed, divided by its own
// gradient's norm, took a value the eikonal test refused.
constexpr double kSeedValues = kCorrectedReach;

// How many interface voxels a thread maps through the sub-steps at once: enough for the
// batched maps to pay, few enough for the points to stay in cache.
constexpr std::size_t kMapBatch = 256;

// Trilinear interpolation of a cell's corner values at offset uvw inside it, in single
// precision (the values are floats; OpenVDB's BoxSampler turns every product into a double
// and back, in the innermost loop of sampling).
float trilinearIn(const float (&c)[2][2][2], const openvdb::Vec3d& uvw) {
    const float u = float(uvw[0]), v = float(uvw[1]), w = float(uvw[2]);
    const auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
    return lerp(lerp(lerp(c[0][0][0], c[0][0][1], w), lerp(c[0][1][0], c[0][1][1], w), v),
                lerp(lerp(c[1][0][0], c[1][0][1], w), lerp(c[1][1][0], c[1][1][1], w), v), u);
}

// Sampling::Corrected at offset uvw in a cell: the trilinear value less half of each axis's
// second differences, interpolated from the cell's corners like the values, times t (1 - t)
// on that axis. `at(i, j, k)` reads the value at offset (i, j, k) from the cell's lowest
// corner, each from -1 to 2 (the corners and one voxel beyond them along each axis). Within
// `reach` of the surface, `slope` (when given) receives the central differences at the
// corners, interpolated likewise: those of the trilinear values one voxel either way.
template <typename At>
float correctedIn(const At& at, const openvdb::Vec3d& uvw, float reach, float* slope = nullptr) {
    float c[2][2][2];
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k)
                c[i][j][k] = at(i, j, k);
    const float linear = trilinearIn(c, uvw);
    if (!(std::abs(linear) < reach)) return linear;
    float d1[3][2][2][2], d2[3][2][2][2];
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k) {
                const int o = 1 - 2 * i, p = 1 - 2 * j, q = 1 - 2 * k; // into the cell
                const float twice = 2.0f * c[i][j][k];
                const float in[3] = {c[1 - i][j][k], c[i][1 - j][k], c[i][j][1 - k]};
                const float out[3] = {at(i - o, j, k), at(i, j - p, k), at(i, j, k - q)};
                const int into[3] = {o, p, q};
                for (int a = 0; a < 3; ++a) {
                    if (slope) d1[a][i][j][k] = 0.5f * float(into[a]) * (in[a] - out[a]);
                    d2[a][i][j][k] = in[a] - twice + out[a];
                }
            }
    float correction = 0.0f;
    for (int a = 0; a < 3; ++a) {
        const float t = float(uvw[a]);
        correction += t * (1.0f - t) * trilinearIn(d2[a], uvw);
        if (slope) slope[a] = trilinearIn(d1[a], uvw);
    }
    return linear - 0.5f * correction;
}

// The cell (its lowest corner) holding index-space point p: the floor on each axis, as a
// truncation and a compare. std::floor is a call into libm in the baseline x86-64 build, on
// every sampled voxel; the integers are the same for any point
// within a grid's coordinates.
openvdb::Coord cellOf(const openvdb::Vec3d& p) {
    const auto down = [](double x) {
        const int i = int(x);
        return i - int(x < double(i));
    };
    return openvdb::Coord(down(p[0]), down(p[1]), down(p[2]));
}

// New values of the leaves a sampling pass resamples, kept beside the grid until every sample
// is taken (samples read the grid as it was), then swapped in: 512 values a leaf, and per
// leaf the voxels whose values changed (only those are written). Writing into the leaves
// instead needed a copy of each one first (copy on write): thousands of leaves a segment,
// allocated, put in a tree on one thread and freed one at a time.
struct Staged {
    std::unique_ptr<float[]> values;
    std::size_t capacity = 0; // values it holds room for
    std::vector<leafwords::Words> changed;

    // Room for n leaves' values, kept from pass to pass; counts in `growths` when it grows.
    void reserve(std::size_t leaves, std::atomic<std::size_t>& growths) {
        const std::size_t n = leaves * LeafNode::SIZE;
        if (n <= capacity) return;
        capacity = std::max(2 * n, 2 * capacity);
        values.reset(new float[capacity]);
        ++growths;
    }

    // Calls body(to, from, pos) for each changed voxel of the l-th leaf: its place in `to`
    // (the leaf's 512 values) and in the staged values.
    template <typename Body> void forEachChanged(std::size_t l, float* to, const Body& body) const {
        float* const from = &values[l * LeafNode::SIZE];
        for (std::size_t x = 0; x < 8; ++x)
            for (leafwords::Word w = changed[l][x]; w; w &= w - 1)
                body(to, from, x * 64 + std::size_t(__builtin_ctzll(w)));
    }

    // Swaps the staged values of the changed voxels with the leaves' (the staged values are
    // then the old ones).
    void swapInto(const std::vector<LeafNode*>& leaves) {
        parallelFor(std::size_t(0), leaves.size(), [&](std::size_t l) {
            forEachChanged(
                l, leaves[l]->buffer().data(),
                [](float* to, float* from, std::size_t pos) { std::swap(to[pos], from[pos]); });
        });
    }
};

// What sampling reads: the grid as it was before sampling began. A segment's first pass reads
// the live grid alone and writes beside it (Staged); otherwise sampling writes the leaves it
// resamples, so those are copied first (copy on write) and every other read goes to the live
// grid, which nothing else changes meanwhile: the cost follows the brush, not the model.
// Where the band had to be widened, the copies hold the widened band.
class SampleSource {
  public:
    SampleSource(const Grid& live, GridPtr copies) : live_(live), copies_(std::move(copies)) {}
    // Copies of these leaves (their values before sampling).
    static std::shared_ptr<SampleSource> copyOnWrite(const Grid& live,
                                                     const std::vector<LeafNode*>& leaves) {
        return std::make_shared<SampleSource>(live, copyLeaves(live, leaves));
    }
    // The live grid alone (sampling writes elsewhere: Staged).
    static std::shared_ptr<SampleSource> live(const Grid& live) {
        return std::make_shared<SampleSource>(live, copyLeaves(live, std::vector<LeafNode*>{}));
    }
    // Adds copies of these leaves (not copied yet), before sampling writes them.
    void copyAlso(const std::vector<LeafNode*>& leaves) { addCopies(*copies_, leaves); }
    // Adds copies of leaves as they were before `staged` was swapped into them.
    void copyAlso(const std::vector<LeafNode*>& leaves, const Staged& staged);
    // A grid holding copies of these leaves, with the live grid's transform and background.
    template <typename Leaves> static GridPtr copyLeaves(const Grid& live, const Leaves& leaves) {
        GridPtr copies = Grid::create(live.background());
        copies->setTransform(live.transform().copy());
        addCopies(*copies, leaves);
        return copies;
    }
    template <typename Leaves> static void addCopies(Grid& copies, const Leaves& leaves) {
        // Copied in parallel, then put in the tree (which is not safe to grow in parallel).
        std::vector<LeafNode*> made(leaves.size());
        parallelFor(std::size_t(0), leaves.size(),
                    [&](std::size_t i) { made[i] = new LeafNode(*leaves[i]); });
        for (LeafNode* leaf : made)
            copies.tree().addLeaf(leaf);
    }

    // Frees the copies, when nothing else holds them (freeOnThisThread).
    void freeCopies() {
        if (copies_.use_count() == 1) freeOnThisThread(copies_->tree());
    }

    // One per thread. The interface of a tree accessor that OpenVDB's samplers read.
    class Accessor {
      public:
        using ValueType = float;
        explicit Accessor(const SampleSource& s)
            : copies_(s.copies_->getConstAccessor()), live_(s.live_.getConstAccessor()) {}
        float getValue(const openvdb::Coord& ijk) const {
            if (const LeafNode* leaf = copy(ijk)) return leaf->getValue(ijk);
            return live_.getValue(ijk);
        }
        bool isValueOn(const openvdb::Coord& ijk) const {
            if (const LeafNode* leaf = copy(ijk)) return leaf->isValueOn(ijk);
            return live_.isValueOn(ijk);
        }
        bool probeValue(const openvdb::Coord& ijk, float& v) const {
            if (const LeafNode* leaf = copy(ijk)) return leaf->probeValue(ijk, v);
            return live_.probeValue(ijk, v);
        }

        // Trilinear interpolation at index-space point p.
        // When the cell lies inside one leaf (343 cells in 512) its eight corners are read
        // from that leaf's buffer, after a single lookup instead of eight.
        float trilinear(const openvdb::Vec3d& p) const {
            const openvdb::Coord ijk = cellOf(p);
            const openvdb::Vec3d uvw = p - ijk.asVec3d();
            float data[2][2][2];
            const LeafNode* leaf = nullptr;
            if ((ijk[0] & 7) < 7 && (ijk[1] & 7) < 7 && (ijk[2] & 7) < 7) {
                leaf = copy(ijk);
                if (!leaf) leaf = live_.probeConstLeaf(ijk);
            }
            if (leaf) {
                const openvdb::Index o = LeafNode::coordToOffset(ijk);
                for (int i = 0; i < 2; ++i)
                    for (int j = 0; j < 2; ++j)
                        for (int k = 0; k < 2; ++k)
                            data[i][j][k] = leaf->getValue(o + i * 64 + j * 8 + k);
            } else {
                for (int i = 0; i < 2; ++i)
                    for (int j = 0; j < 2; ++j)
                        for (int k = 0; k < 2; ++k)
                            data[i][j][k] = getValue(ijk.offsetBy(i, j, k));
            }
            return trilinearIn(data, uvw);
        }

        // Sampling::Corrected at index-space point p (correctedIn), within `reach` (index
        // units) of the surface.
        float corrected(const openvdb::Vec3d& p, float reach, float* slope = nullptr) const {
            const openvdb::Coord ijk = cellOf(p);
            return correctedIn([&](int i, int j, int k) { return getValue(ijk.offsetBy(i, j, k)); },
                               p - ijk.asVec3d(), reach, slope);
        }

        // The source leaf holding ijk (a copy, or the live grid's), or null over a tile.
        const LeafNode* leafAt(const openvdb::Coord& ijk) const {
            if (const LeafNode* leaf = copy(ijk)) return leaf;
            return live_.probeConstLeaf(ijk);
        }

      private:
        const LeafNode* copy(const openvdb::Coord& ijk) const {
            return copies_.probeConstLeaf(ijk);
        }
        Grid::ConstAccessor copies_, live_;
    };

  private:
    const Grid& live_;
    GridPtr copies_;
};

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
    float corrected(const openvdb::Coord& ijk, const openvdb::Vec3d& uvw, float reach,
                    float* slope = nullptr) const {
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

// A leaf of the widened source where the old band did not reach: every voxel at the widened
// background, with the sign the grid has there (a tile of the inside or the outside).
void farWithSigns(LeafNode& leaf, float far, const Grid::ConstAccessor& live) {
    for (auto it = leaf.beginValueAll(); it; ++it)
        it.setValue(live.getValue(it.getCoord()) < 0.0f ? -far : far);
}

// What a sampling pass lists: every voxel whose value changed or that joined the band
// (`changed`), and of them those whose value moved by more than `nudge` (world units) or that
// joined (`moved`): the renormalization seeds again only next to those.
struct Changes {
    VoxelList& changed;
    VoxelList& moved;
    float nudge;
};

// Per thread, what sampling a leaf uses: the block of source values around it, and its
// voxels to sample with their places and pre-images.
struct ResampleScratch {
    MapScratch maps;
    SourceBlock block;
    std::array<std::uint16_t, LeafNode::SIZE> at;
    std::array<Eigen::Vector3d, LeafNode::SIZE> x, y;
};
using ResampleScratches = tbb::enumerable_thread_specific<ResampleScratch>;

// Resamples every active voxel inside `box` of the given leaves of `grid` from `source` at
// the pre-image of x (`map(x, n, y, scratch)` maps a leaf's n voxels x at once, into y), and lists
// in `changes` the voxels whose value changed, and those that moved by more than a nudge, a leaf
// at a time (a leaf resampled again is listed again). When the source holds the grid's own values
// (`sourceIsGrid`: no widened band), a voxel that the map leaves in place keeps its value
// without interpolating: a sample at a voxel centre returns it exactly. With `staged`, the
// new values go there and the leaves keep theirs.
//
// A deformation that tears space (`tearing`) adds how deep x lies in what it opened. A point
// it opened reads the largest value along the torn set within `tornWindow` of the point it
// was torn from: on a grid, what the pinch's needles bring together (or the strangle's noose
// squeezes) keeps a membrane a few voxels thick where the exact surface meets itself at one
// point (the grid rounds off the funnels' tips), and the tear opens through it instead of
// keeping it as the rim of the hole. Where the tear asks (StepDeformation::windowPastRim),
// points within the window's reach past the rim read that value less their distance to the
// rim, when it is more than their own. And no value sampled for a tear lies below the least
// value the tear allows at the pre-image (StepDeformation::leastValue): the funnels the
// needles pull (or the noose squeezes) towards the torn set are thinner than the grid
// resolves, so it reads material next to the set where the shape has none, and the tear,
// which stretches the space around the set by orders of magnitude, would spread that over
// the rim of the hole.
//
// The value a filling deformation's region is made from: at its filledFrom(), before the
// deformation, sampled as `sampling` samples every voxel.
double filledFromValue(const SampleSource& source, const Grid& grid, const StepDeformation& seg,
                       Sampling sampling) {
    const SampleSource::Accessor acc(source);
    const openvdb::Vec3d p = VoxelPlacement(grid.transform()).toIndex(toVdb(seg.filledFrom()));
    const float reach = float(kCorrectedReach * grid.voxelSize()[0]);
    return sampling == Sampling::MonotoneCubic ? sampleMonotoneCubic(acc, p)
           : sampling == Sampling::Corrected   ? acc.corrected(p, reach)
                                               : acc.trilinear(p);
}

// A deformation that fills what has no pre-image (`seg` with fills(): an inflation's ball)
// turns the value sampled there into its filled value. `seg` is the deformation when it
// tears or fills, else null.
template <typename Map>
std::size_t resample(Grid& grid, const std::vector<LeafNode*>& leaves, const SampleSource& source,
                     bool sourceIsGrid, const openvdb::CoordBBox& box, const Map& map,
                     const StepDeformation* seg, double tornWindow, Sampling sampling,
                     Changes changes, Interrupter* interrupter, ResampleScratches& scratch,
                     const openvdb::MaskTree* only = nullptr, Staged* staged = nullptr,
                     VoxelValues* gradientBefore = nullptr) {
    // Per leaf, the voxels whose value changed and those that moved (a word per x, as the
    // leaf's mask holds them): written by the leaf's own task, then listed.
    std::vector<leafwords::Words> changedWords(leaves.size()), movedWords(leaves.size());
    std::atomic<std::size_t> count{0};
    const VoxelPlacement place(grid.transform());
    const StepDeformation* tearing = seg && seg->tears() ? seg : nullptr;
    const double fromValue =
        seg && seg->fills() ? filledFromValue(source, grid, *seg, sampling) : 0.0;
    // (Where the fill does not apply, no voxel looks at it.)
    const StepDeformation* filling = seg && seg->fillsWith(fromValue) ? seg : nullptr;
    const Box filledBox = filling ? filling->filledBox() : Box();
    const bool windowPastRim = tearing && tearing->windowPastRim();
    const double h = grid.voxelSize()[0];
    const float reach = float(kCorrectedReach * h), seedReach = float(kSeedValues * h);
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& range) {
        const SampleSource::Accessor acc(source);
        ResampleScratch& s = scratch.local();
        SourceBlock& block = s.block;
        std::size_t n = 0;
        pollInterrupt(interrupter);
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
            const auto* wanted = only ? only->probeConstLeaf(leaf.origin()) : nullptr;
            if (only && !wanted) continue;
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
            map(s.x.data(), std::size_t(listed), s.y.data(), s.maps);
            bool filled = false; // the block is filled for the leaf's first sample
            const float* values = leaf.buffer().data();
            float* const out = staged ? &staged->values[l * LeafNode::SIZE] : leaf.buffer().data();
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
                    v = sample(y, gradientBefore ? slope : nullptr);
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
                    if (filling && filledBox.contains(x)) {
                        const float filled = float(filling->filledValue(x, v, fromValue));
                        madeDistance = filled != v;
                        v = filled;
                    }
                }
                if (madeDistance && gradientBefore && std::abs(v) < seedReach) {
                    // A filled value is a distance already: no stretch to divide it by.
                    (*gradientBefore)[l].values[std::size_t(pos)] = 1.0f;
                } else if (gradientBefore && std::abs(v) < seedReach) {
                    // The source's central differences at the pre-image (renormalize()): from
                    // the sample's own reads, or, for a voxel that kept its value, its
                    // neighbours'.
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
                if (std::abs(v - old) > changes.nudge || joined)
                    movedWords[l][std::size_t(pos >> 6)] |= bit;
                out[pos] = v;
            }
            n += std::size_t(listed);
        }
        count += n;
    });
    for (std::size_t l = 0; l < leaves.size(); ++l) {
        if (leafwords::any(changedWords[l]))
            changes.changed.push_back({leaves[l]->origin(), changedWords[l]});
        if (leafwords::any(movedWords[l]))
            changes.moved.push_back({leaves[l]->origin(), movedWords[l]});
    }
    if (staged) staged->changed = std::move(changedWords);
    return count;
}

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

// Adds to `mask` (each leaf once) what a tearing deformation needs sampled beyond the band
// grown around the images of the surface: the inside voxels of the opened region (their sign
// changes), and the voxels near the opening's rim whose value will lie within `shell` of the
// surface. Where the surface touched the torn set, the rim is new surface, and the images of
// the few voxels near the touching point only reach it in their own directions; around the
// rim the tear stretches space along it by (d + r) / d at distance d from the torn set, and
// past a stretch of 7 (d < r / 6, less than r / 6 beyond the rim) the images of neighbouring
// voxels land farther apart than the band's dilation closes.
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

// Adds to `mask` (each leaf once) what a filling deformation needs sampled beyond the band
// grown around the images of the surface: no surface maps into the region it fills, whose
// edge may be new surface. The voxels there whose filled value lies within `shell` of the
// surface join the band; they enclose the rest of the region, whose signs the flood after
// sampling re-derives. Nothing is marked where the fill does not apply (a dab of clay well
// inside the shape, as the modeler places it): its ball's box is not walked.
std::size_t markFilled(const Grid& grid, const StepDeformation& seg, double shell,
                       Sampling sampling, VoxelList& mask) {
    const SampleSource source(grid, Grid::create());
    const double from = filledFromValue(source, grid, seg, sampling);
    if (!seg.fillsWith(from)) return 0;
    const openvdb::CoordBBox box = indexBox(grid, seg.filledBox(), 1);
    const auto needed = [&](const Eigen::Vector3d& x, float, const SampleSource::Accessor& acc) {
        const double at = acc.trilinear(grid.worldToIndex(toVdb(seg.inverseMap(x))));
        const double filled = seg.filledValue(x, at, from);
        return filled != at && std::abs(filled) < shell;
    };
    return markInactive(grid, box, needed, mask);
}

// Whether sampling reached every voxel renormalization seeds from and every voxel their
// gradients read: each voxel of `box` in `leaves` next to the zero crossing is active, and
// so are its face neighbours. The signs are read as they stand, before inactive ones are
// re-derived: where the surface moved past an inactive voxel it reads as a crossing there,
// and the answer is no (which is only ever too cautious).
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

// Rounds of sampling the voxels seedsSampled finds missing, at most.
constexpr int kSeedRounds = 4;

// What seedsSampled finds missing, voxel by voxel (where it answered no even after the images
// were dilated as far as the band reaches): the inactive voxels of `box` in `leaves` next to
// the zero crossing, and the inactive face neighbours within `box` of those next to it.
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

// Makes the leaves of `grid` within `beyond` voxels of the mask's voxels that overlap `box`,
// exactly those dilating the mask by a cube of that radius would make: a voxel reaches the
// leaf next to it along an axis when it lies within `beyond` of it (a leaf more would only
// widen renormalization's domain). Along x the words themselves are chosen; along y and z,
// the bits of a word.
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

// How many voxels (face steps) the band of each of `leaves` is to be widened by. A stretch s
// measured at interface voxel x (one in kStretchSampling is measured; the stretch varies
// smoothly, as the widening of the whole box by the largest one assumed too) asks for a band
// of n = needed(s) voxels: the pre-images of the voxels next to the new surface near x's
// image lie within n voxels of x, and the band voxels nearest them within n more. So every
// leaf within 2n voxels of x's leaf has its band widened to n.
template <typename Needed>
std::vector<int>
widening(const std::vector<const LeafNode*>& leaves, const std::vector<openvdb::Coord>& interface,
         const std::vector<double>& stretchAt, const Needed& needed, double halfWidth) {
    constexpr int kDim = int(LeafNode::DIM);
    std::map<openvdb::Coord, double> asks; // by the leaf the measured voxel lies in
    for (std::size_t k = 0; k < stretchAt.size() && k * kStretchSampling < interface.size(); ++k) {
        const double n = needed(stretchAt[k]);
        if (n <= halfWidth) continue;
        double& a = asks[interface[k * kStretchSampling] & ~(kDim - 1)];
        a = std::max(a, n);
    }
    // Every leaf against every asking one: the pairs are few where a stretch is local (some
    // 300 leaves against a few dozen in a needle segment at 1/128).
    std::vector<int> by(leaves.size(), 0);
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& r) {
        for (std::size_t l = r.begin(); l != r.end(); ++l) {
            const openvdb::Coord o = leaves[l]->origin();
            for (const auto& [from, n] : asks) {
                // The gap between the two leaves in voxels, along the axis they lie farthest
                // apart.
                const openvdb::Coord d = o - from;
                const int gap =
                    std::max({std::abs(d.x()), std::abs(d.y()), std::abs(d.z())}) - kDim;
                if (gap <= 2 * int(n)) by[l] = std::max(by[l], int(std::ceil(n - halfWidth)));
            }
        }
    });
    return by;
}

} // namespace

openvdb::CoordBBox changedRegion(const Grid& grid, const StepDeformation& seg) {
    // The sampled region, and the band activated around images of the interface (which
    // stay inside the affected box: the deformation maps it onto itself), and what
    // renormalization writes: within half-width + 1 of a changed voxel, and one step past
    // that, where the band may grow.
    openvdb::CoordBBox box = indexBox(grid, seg.affectedBox(), 1);
    box.expand(int(std::ceil(halfWidthOf(grid))) + 2);
    return box;
}

openvdb::CoordBBox indexBox(const Grid& grid, const Box& world, int pad) {
    if (world.empty()) return {};
    const openvdb::Vec3d lo = grid.worldToIndex(toVdb(world.min));
    const openvdb::Vec3d hi = grid.worldToIndex(toVdb(world.max));
    return openvdb::CoordBBox(openvdb::Coord::floor(lo).offsetBy(-pad),
                              openvdb::Coord::ceil(hi).offsetBy(pad));
}

// A segment's state between its phases, and the scratch that outlives it.
struct SegmentAdvector::Work {
    // --- scratch kept from segment to segment ---------------------------------------------
    // Times one of the buffers below had to grow. (A thread's own buffers are not counted: a
    // thread that first takes part in a later segment makes them then, whatever the stroke.
    // Its mapped points come in batches of a fixed size, and its list of images keeps room
    // for twice what it held.)
    std::atomic<std::size_t> growths{0};
    std::vector<LeafNode::NodeMaskType> crossing;
    std::vector<std::size_t> first;
    std::vector<char> scanned;
    std::vector<openvdb::Index64> onVoxels;
    std::vector<openvdb::Coord> interface;
    std::vector<double> stretchAt;
    // Per thread: the images it marked, and the points it maps a sub-step at a time.
    struct Mapping {
        VoxelList marked;
        std::vector<Eigen::Vector3d> mapped, next;
        MapScratch maps;
    };
    tbb::enumerable_thread_specific<Mapping> mapping;
    ResampleScratches resampling;
    Staged staged;

    // --- the segment ------------------------------------------------------------------------
    Grid* grid = nullptr;
    const StepDeformation* seg = nullptr;
    const AdvectOptions* options = nullptr;
    AdvectStats stats;
    double h = 0.0, halfWidth = 0.0, forwardTolerance = 0.0, tornWindow = 0.0;
    openvdb::CoordBBox region, touched;
    bool measureStretch = false;
    int bandReach = 0, reach = 0;
    VoxelList images, mask, fresh, changed, moved, freed;
    GridPtr widened; // the copies with the widened band, when it had to be widened
    // Per moving leaf, the gradient norms its seeds had before the segment
    // (Sampling::Corrected, but for tears).
    VoxelValues gradientBefore;
    std::vector<LeafNode*> sampled, moving;

    // Gives a kept buffer room for n entries, counting when its storage has to grow. A
    // buffer that grows takes room for twice what is asked: the next segments of a stroke
    // ask for about as much, a little more where the shape grew.
    template <typename Vector> void makeRoom(Vector& v, std::size_t n) {
        if (n <= v.capacity()) return;
        v.reserve(std::max(2 * n, 2 * v.capacity()));
        ++growths;
    }
    // Sizes a kept buffer for n entries.
    template <typename Vector> void fit(Vector& v, std::size_t n) {
        makeRoom(v, n);
        v.resize(n);
    }

    void begin(Grid& g, const StepDeformation& s, const AdvectOptions& o) {
        grid = &g;
        seg = &s;
        options = &o;
        stats = AdvectStats{};
        stats.subSteps = s.steps();
        h = g.voxelSize()[0];
        halfWidth = halfWidthOf(g);
        region = indexBox(g, s.affectedBox(), 1);
        // The images only pick voxels to activate: a hundredth of a voxel is plenty.
        forwardTolerance = 0.01 * h / (1.0 + s.affectedBox().max.cwiseAbs().maxCoeff());
        tornWindow = (std::ceil(halfWidth) + 1) * h; // see resample
        bandReach = int(std::ceil(halfWidth)) + 1;
        widened.reset();
        for (VoxelList* list : {&images, &mask, &fresh, &changed, &moved, &freed})
            list->clear();
        sampled.clear();
        moving.clear();
    }

    // Whether renormalization divides this segment's seeds by its stretch: with corrected
    // sampling of the composed inverse, but for a tear (renormalizeChanged).
    bool dividesByStretch() const {
        return options->sampling == Sampling::Corrected && !options->resampleEachSubStep &&
               !seg->tears();
    }

    // Leaves where the deformation is the identity (within a voxel of them: the stretch
    // reads half a voxel around an image) keep their values, and the band already covers
    // their surface: only the interface of the other leaves is forward-mapped (the images of
    // a moving leaf's surface reach into still leaves where they need a band).
    bool still(const LeafNode& leaf) const {
        openvdb::CoordBBox box = leaf.getNodeBoundingBox();
        box.expand(1);
        const openvdb::BBoxd world = grid->transform().indexToWorld(box);
        return seg->identityOn(Box(toEigen(world.min()), toEigen(world.max())));
    }

    // The voxels the renormalization seeds from lie within 1.5 voxels of the new surface
    // (crossing ends and their central differences); their pre-images lie within
    // 1.5 * stretch voxels of the old one, and trilinear sampling reads one more voxel
    // beyond. The old band must reach that far, so that none of them reads a clamped value.
    static double neededFor(double stretch) {
        return std::ceil(1.5 * std::min(stretch, 32.0) + 1.0);
    }

    void findInterface();
    void mapImages();
    void widenSource();
    void growBand();
    void sample();
    void fixSigns();
    void renormalizeChanged();
    void report(std::vector<openvdb::CoordBBox>* boxes) const;

    VoxelList switchOn(const VoxelList& on);
    void copyFar(const std::vector<LeafNode*>& leaves);
    std::vector<LeafNode*> movingOf(const std::vector<LeafNode*>& leaves) const;
    std::shared_ptr<SampleSource> sourceOfSubStep(int k);
    Changes changes();
};

// The interface voxels of the leaves the deformation moves: found leaf by leaf in parallel,
// then listed in leaf order (the stretch samples every fourth one of that list), each leaf's
// voxels counted first, then written where the counts before it put them (a list per leaf,
// joined on one thread, would be a serial part of every segment).
void SegmentAdvector::Work::findInterface() {
    const auto leaves = leavesIn(std::as_const(grid->tree()), region);
    fit(crossing, leaves.size());
    fit(first, leaves.size() + 1);
    fit(scanned, leaves.size());
    fit(onVoxels, leaves.size());
    first[0] = 0;
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& r) {
        const auto acc = grid->getConstAccessor();
        for (std::size_t l = r.begin(); l != r.end(); ++l) {
            const LeafNode& leaf = *leaves[l];
            scanned[l] = 0;
            crossing[l].setOff();
            first[l + 1] = 0;
            if (still(leaf)) continue;
            scanned[l] = 1;
            onVoxels[l] = leaf.onVoxelCount();
            // The active voxels next to the crossing, a word of the masks at a time (a
            // leaf's 300 or so active voxels hold some 40 of them).
            crossing[l] = crossingVoxels(leaf, acc);
            crossing[l] &= leaf.getValueMask();
            if (!region.isInside(leaf.getNodeBoundingBox()))
                for (auto it = crossing[l].beginOn(); it; ++it)
                    if (!region.isInside(leaf.offsetToGlobalCoord(it.pos())))
                        crossing[l].setOff(it.pos());
            first[l + 1] = crossing[l].countOn();
        }
    });
    for (std::size_t l = 0; l < leaves.size(); ++l) {
        first[l + 1] += first[l];
        if (!scanned[l]) continue;
        ++stats.leavesVisited;
        stats.voxelsVisited += onVoxels[l];
    }
    fit(interface, first[leaves.size()]);
    parallelFor(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& r) {
        for (std::size_t l = r.begin(); l != r.end(); ++l) {
            std::size_t i = first[l];
            for (auto it = crossing[l].beginOn(); it; ++it)
                interface[i++] = leaves[l]->offsetToGlobalCoord(it.pos());
        }
    });
    stats.interfaceVoxels = interface.size();
}

// Forward-maps the interface voxels, one sub-step at a time, and marks every image; measures
// how far apart the images of neighbouring voxels land (the stretch), which bounds how far a
// pre-image can sit from the old surface. Each thread lists the images leaf by leaf, a list
// of its own, a run of interface voxels at a time; a leaf the runs share is listed by each
// (dilatedByCube joins the entries). Marked in a tree per thread, they would cost a tree's
// look-up per image, and the trees would have to be listed and freed after.
void SegmentAdvector::Work::mapImages() {
    for (Mapping& m : mapping)
        m.marked.clear();
    const VoxelPlacement place(grid->transform());
    // The stretch at every kStretchSampling-th interface voxel (1 where not measured), unless
    // the deformation's bound shows that the band is wide enough wherever it is measured
    // (a drag's segments, where measuring would cost inverse maps and an eigenvalue solve at
    // every sampled voxel for nothing).
    measureStretch = neededFor(seg->stretchBound()) > halfWidth;
    fit(stretchAt, interface.size() / kStretchSampling + 1);
    std::fill(stretchAt.begin(), stretchAt.end(), 1.0);
    parallelFor(
        tbb::blocked_range<std::size_t>(0, interface.size(), grainFor(interface.size(), 64)),
        [&](const auto& r) {
            pollInterrupt(options->interrupter);
            Mapping& m = mapping.local();
            VoxelList& marked = m.marked;
            const std::size_t run = marked.size(); // this run's entries start here
            // The images of a run of voxels next to each other fall into a few leaves: its
            // entries are searched from the one marked last.
            std::size_t last = run;
            const auto mark = [&](const openvdb::Coord& c) {
                const openvdb::Coord origin = c & ~int(LeafNode::DIM - 1);
                if (last == marked.size() || marked[last].origin != origin) {
                    last = run;
                    while (last < marked.size() && marked[last].origin != origin)
                        ++last;
                    if (last == marked.size()) marked.push_back({origin, {}});
                }
                const openvdb::Index off = LeafNode::coordToOffset(c);
                marked[last].words[off >> 6] |= leafwords::Word(1) << (off & 63);
            };
            // The range's voxels are mapped a sub-step at a time, a batch of them at once (a
            // batch of fixed size, so that the buffers need no more room however the loop is
            // split among the threads).
            std::vector<Eigen::Vector3d>&mapped = m.mapped, &next = m.next;
            if (mapped.capacity() < kMapBatch) {
                mapped.reserve(kMapBatch);
                next.reserve(kMapBatch);
            }
            for (std::size_t b = r.begin(); b < r.end(); b += kMapBatch) {
                const std::size_t e = std::min(b + kMapBatch, r.end());
                mapped.resize(e - b);
                next.resize(e - b);
                for (std::size_t i = b; i != e; ++i)
                    mapped[i - b] = toEigen(place.toWorld(interface[i].asVec3d()));
                for (int k = 0; k < seg->steps(); ++k) {
                    seg->forwardSteps(k, mapped.data(), mapped.size(), forwardTolerance,
                                      next.data(), m.maps);
                    mapped.swap(next);
                    // Intermediate surfaces only need a band when they are stored.
                    if (options->resampleEachSubStep || k + 1 == seg->steps())
                        for (const Eigen::Vector3d& p : mapped)
                            mark(openvdb::Coord::round(place.toIndex(toVdb(p))));
                }
                for (std::size_t i = b; i != e; ++i) {
                    const Eigen::Vector3d& p = mapped[i - b];
                    if (!measureStretch || i % kStretchSampling != 0) continue;
                    // How far the inverse map can spread a voxel-sized neighbourhood of the new
                    // surface: the largest singular value of its Jacobian.
                    Eigen::Matrix3d J;
                    for (int a = 0; a < 3; ++a) {
                        Eigen::Vector3d e = Eigen::Vector3d::Zero();
                        e[a] = 0.5 * h;
                        J.col(a) = (seg->inverseMap(p + e) - seg->inverseMap(p - e)) / h;
                    }
                    // Its square is the largest eigenvalue of J^T J, solved in closed form (an
                    // iterative SVD of J costs more than the six inverse maps).
                    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
                    eigen.computeDirect(J.transpose() * J, Eigen::EigenvaluesOnly);
                    stretchAt[i / kStretchSampling] =
                        std::sqrt(std::max(0.0, eigen.eigenvalues()[2]));
                }
            }
        });
    // Each thread's list keeps room for twice what it marked this time.
    for (Mapping& m : mapping)
        if (m.marked.capacity() < 2 * m.marked.size()) m.marked.reserve(2 * m.marked.size());
    std::size_t count = 0;
    for (const Mapping& m : mapping)
        count += m.marked.size();
    makeRoom(images, count);
    for (const Mapping& m : mapping)
        images.insert(images.end(), m.marked.begin(), m.marked.end());
    if (measureStretch)
        stats.stretchSamples = (interface.size() + kStretchSampling - 1) / kStretchSampling;
}

// Where the stretch asks for more band than the grid has: only the affected box is sampled,
// so the band is widened there alone. Copies of its leaves, whose inactive values (now
// +-needed voxels) carry the signs, take the band dilated by the missing voxels, and fast
// marching fills in distances.
void SegmentAdvector::Work::widenSource() {
    const double needed = neededFor(*std::max_element(stretchAt.begin(), stretchAt.end()));
    stats.widenedTo = std::max(halfWidth, needed);
    if (needed <= halfWidth) return;
    const openvdb::CoordBBox box = indexBox(*grid, seg->affectedBox(), int(needed) + 3);
    const auto leaves = leavesIn(std::as_const(grid->tree()), box);
    GridPtr source = SampleSource::copyLeaves(*grid, leaves);
    stats.leavesCopied += leaves.size();
    openvdb::tools::changeLevelSetBackground(source->tree(), float(needed * h));
    // A stretch is strong only near where a tool tears or squeezes (the tips of the pinch's
    // needles, the noose): the band is widened as far as the stretch measured near each leaf
    // asks, and not at all where none asks (in a needle segment of a pinch, a few leaves of
    // the hundreds in the box ask for more than the band holds).
    const std::vector<int> by = widening(leaves, interface, stretchAt, neededFor, halfWidth);
    std::map<int, openvdb::MaskTree> widen; // the leaves to widen, by how far
    for (std::size_t l = 0; l < leaves.size(); ++l) {
        if (by[l] == 0) continue;
        widen[by[l]].touchLeaf(leaves[l]->origin())->topologyUnion(*leaves[l]);
        ++stats.leavesWidened;
    }
    for (auto& [steps, toWiden] : widen) {
        openvdb::tools::dilateActiveValues(toWiden, steps, openvdb::tools::NN_FACE,
                                           openvdb::tools::IGNORE_TILES);
        source->tree().topologyUnion(toWiden);
    }
    // Leaves the dilation added hold the copies' background, whatever the side.
    const auto live = grid->getConstAccessor();
    const std::vector<LeafNode*> copied = leavesIn(source->tree(), box);
    for (LeafNode* leaf : copied)
        if (!grid->tree().probeConstLeaf(leaf->origin())) // not a copy
            farWithSigns(*leaf, float(needed * h), live);
    // Sampling reads every leaf from the widened copy, so a voxel the deformation leaves in
    // place must find its own value there: the copy's band is renormalized only where the
    // deformation moves it, and where the widening added voxels. Renormalizing it all seeded
    // the still band again at every segment, and the surface crept where it curves within a
    // voxel, across the whole affected box (as renormalizeChanged() says), over the many
    // segments of a stroke whose noose or needles call for a wider band.
    VoxelList redo(copied.size());
    parallelFor(std::size_t(0), copied.size(), [&](std::size_t l) {
        const LeafNode& leaf = *copied[l];
        LeafVoxels& entry = redo[l];
        entry.origin = leaf.origin();
        const LeafNode* old = grid->tree().probeConstLeaf(leaf.origin());
        for (int x = 0; x < 8; ++x) {
            const auto on = leaf.getValueMask().getWord<leafwords::Word>(x);
            entry.words[std::size_t(x)] =
                old ? on & ~old->getValueMask().getWord<leafwords::Word>(x) : on;
        }
        if (!old || still(*old)) return;
        for (auto it = old->cbeginValueOn(); it; ++it)
            if (!seg->stillAt(toEigen(grid->indexToWorld(it.getCoord()))))
                entry.words[it.pos() >> 6] |= leafwords::Word(1) << (it.pos() & 63);
    });
    redo.erase(std::remove_if(redo.begin(), redo.end(),
                              [](const LeafVoxels& e) { return !leafwords::any(e.words); }),
               redo.end());
    renormalize(*source, indexBox(*grid, seg->affectedBox(), int(needed) + 1), redo, redo,
                FmmOrder::First, options->interrupter);
    // Beyond the band, the copy reads the grid's own clamp again: where no leaf was widened
    // (far from the stretch, across the box of a deformation that reaches the whole shape,
    // as an inflation does), a sample next to the band's edge reads past it, and the wider
    // clamp there (needed voxels instead of the band's) would bend the values it reads
    // towards it, corrected sampling's second differences most (a sign flips three voxels
    // out). The widened leaves' active voxels keep their distances.
    openvdb::tools::changeLevelSetBackground(source->tree(), grid->background());
    widened = source;
}

// The voxels of `on` not yet on in the grid, switched on and returned: those the band grows
// into (renormalized, or dropped again, wherever they are). The grid's leaves are found (or
// made) on this thread, through an accessor (entries next to each other in the list mostly
// lie in one internal node); the voxels are switched on a leaf and a word at a time in
// parallel (the list holds each leaf once, so no two tasks write one leaf).
VoxelList SegmentAdvector::Work::switchOn(const VoxelList& on) {
    std::vector<const LeafVoxels*> from;
    for (const LeafVoxels& leaf : on)
        if (leafwords::any(leaf.words)) from.push_back(&leaf);
    // Most of the leaves are there already: they are found in parallel (reading the tree),
    // and only the missing ones are made, on this thread (the tree changes).
    std::vector<LeafNode*> to(from.size());
    parallelFor(tbb::blocked_range<std::size_t>(0, from.size(), grainFor(from.size(), 64)),
                [&](const auto& r) {
                    const auto acc = grid->getConstAccessor();
                    for (std::size_t i = r.begin(); i != r.end(); ++i)
                        to[i] = const_cast<LeafNode*>(acc.probeConstLeaf(from[i]->origin));
                });
    {
        auto into = grid->getAccessor();
        for (std::size_t i = 0; i < from.size(); ++i)
            if (!to[i]) to[i] = into.touchLeaf(from[i]->origin);
    }
    std::vector<leafwords::Words> newlyOn(from.size());
    parallelFor(tbb::blocked_range<std::size_t>(0, from.size()), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            auto& words = to[i]->getValueMask();
            for (int x = 0; x < 8; ++x) {
                const std::uint64_t add = from[i]->words[std::size_t(x)];
                newlyOn[i][std::size_t(x)] = add & ~words.getWord<std::uint64_t>(x);
                words.getWord<std::uint64_t>(x) |= add;
            }
        }
    });
    VoxelList newly;
    for (std::size_t i = 0; i < from.size(); ++i)
        if (leafwords::any(newlyOn[i])) newly.push_back({from[i]->origin, newlyOn[i]});
    return newly;
}

// The band the images are dilated into, switched on: what renormalization's seeds read (the
// voxels next to the new crossing and their face neighbours) lies within kSeedReach of them,
// and sampling checks that it reached it all (else sample() dilates the images as far as the
// whole band reaches). Renormalization gives the voxels between there and the band's edge
// their distances: sampling them too would read about twice as many voxels as the band holds.
void SegmentAdvector::Work::growBand() {
    reach = options->resampleEachSubStep ? bandReach : std::min(kSeedReach, bandReach);
    mask = dilatedByCube(images, reach);
    stats.sampledReach = reach;
    // A tear opens empty space where there was material: no image of the surface reaches the
    // middle of the opening, so the inside voxels there join the band to be sampled
    // (renormalization drops them again, with their new sign).
    if (seg->tears()) stats.tornVoxels = markOpened(*grid, *seg, (halfWidth + 2) * h, mask);
    // An inflation fills its ball: no image of the surface reaches its edge either.
    if (seg->fills())
        stats.filledVoxels = markFilled(*grid, *seg, (halfWidth + 2) * h, options->sampling, mask);
    fresh = switchOn(mask);
}

// Leaves the band just grew into, outside the widened copies: sampling writes them, so it
// must not read them from the live grid, which still holds their tiles' signs.
void SegmentAdvector::Work::copyFar(const std::vector<LeafNode*>& leaves) {
    const auto live = grid->getConstAccessor();
    for (const LeafNode* leaf : leaves) {
        if (widened->tree().probeConstLeaf(leaf->origin())) continue;
        auto* copy = new LeafNode(*leaf);
        farWithSigns(*copy, widened->background(), live);
        widened->tree().addLeaf(copy);
        ++stats.leavesCopied;
    }
}

// Only leaves the deformation moves are resampled (and copied before they are written):
// elsewhere a sample at a voxel centre gives back its own value. A widened band is the
// exception: its values differ from the grid's, so every leaf is resampled from it.
std::vector<LeafNode*> SegmentAdvector::Work::movingOf(const std::vector<LeafNode*>& leaves) const {
    std::vector<char> moves(leaves.size(), 1);
    if (!widened)
        parallelFor(std::size_t(0), leaves.size(),
                    [&](std::size_t l) { moves[l] = !still(*leaves[l]); });
    std::vector<LeafNode*> out;
    for (std::size_t l = 0; l < leaves.size(); ++l)
        if (moves[l]) out.push_back(leaves[l]);
    return out;
}

// What sub-step k samples when they are sampled one at a time: the grid with copies of what
// they write (the first, from a widened band, its copies).
std::shared_ptr<SampleSource> SegmentAdvector::Work::sourceOfSubStep(int k) {
    if (widened && k == 0) return std::make_shared<SampleSource>(*grid, widened);
    auto copy = SampleSource::copyOnWrite(*grid, moving);
    stats.leavesCopied += moving.size();
    return copy;
}

// Where sampling lists what it changed and moved. A change of less than a hundredth of a voxel
// is a nudge: what a tool's falloff leaves at its edge, segment after segment. Seeding again
// next to nudges alone let the surface creep there. One sub-step at a time, nudges add up
// over the sub-steps: each change counts.
Changes SegmentAdvector::Work::changes() {
    const double nudge = options->resampleEachSubStep ? 0.0 : 0.01;
    return {changed, moved, float(nudge * h)};
}

// Samples the moving leaves at their pre-images: the composed inverse (default) or one
// resample per sub-step (5.3.4).
void SegmentAdvector::Work::sample() {
    sampled = leavesIn(grid->tree(), region);
    stats.leavesVisited += sampled.size();
    if (widened) copyFar(sampled);
    moving = movingOf(sampled);
    touched = changedRegion(*grid, *seg);
    const StepDeformation* tearsOrFills = seg->tears() || seg->fills() ? seg : nullptr;
    if (options->resampleEachSubStep) {
        // Each sub-step reads what the one before wrote, inactive values included, so their
        // signs are re-derived before it reads them: otherwise a pre-image beyond the band
        // takes the sign its place had before the earlier sub-steps moved the surface.
        for (int k = 0; k < seg->steps(); ++k) {
            if (k > 0) stats.leavesFlooded += floodSignsIn(grid->tree(), moving, touched);
            const auto from = sourceOfSubStep(k);
            stats.sampledVoxels += resample(
                *grid, moving, *from, !widened || k > 0, region,
                [&](const Eigen::Vector3d* x, std::size_t n, Eigen::Vector3d* y, MapScratch&) {
                    for (std::size_t i = 0; i < n; ++i)
                        y[i] = seg->inverseStep(k, x[i]);
                },
                tearsOrFills, tornWindow, options->sampling, changes(), options->interrupter,
                resampling);
            from->freeCopies();
        }
        return;
    }
    const auto map = [&](const Eigen::Vector3d* x, std::size_t n, Eigen::Vector3d* y,
                         MapScratch& scratch) { seg->inverseMaps(x, n, y, scratch); };
    if (dividesByStretch()) fit(gradientBefore, moving.size());
    // Sampling reads the grid itself and writes beside it (staged), or, from a widened band,
    // reads the copies that hold it and writes into the grid.
    const auto from =
        widened ? std::make_shared<SampleSource>(*grid, widened) : SampleSource::live(*grid);
    if (!widened) staged.reserve(moving.size(), growths);
    stats.sampledVoxels =
        resample(*grid, moving, *from, !widened, region, map, tearsOrFills, tornWindow,
                 options->sampling, changes(), options->interrupter, resampling, nullptr,
                 widened ? nullptr : &staged, dividesByStretch() ? &gradientBefore : nullptr);
    if (!widened) {
        staged.swapInto(moving);
        stats.leavesCopied += moving.size();
    }
    // More voxels switched on and sampled from the same source (the leaves that adds copied
    // first, while they still hold their tiles' values). The leaves sampled already are
    // copied as sampling found them, their values and their active voxels, before the band
    // grows the first time: their old values are staged now.
    bool sourceHoldsMoving = widened != nullptr;
    const auto sampleAlso = [&](const VoxelList& more) {
        if (!sourceHoldsMoving) from->copyAlso(moving, staged);
        sourceHoldsMoving = true;
        const VoxelList added = switchOn(more);
        fresh.insert(fresh.end(), added.begin(), added.end());
        openvdb::MaskTree addedTree;
        uniteMasks(addedTree, added);
        std::vector<LeafNode*> all = leavesIn(grid->tree(), region), grown;
        // `sampled` is in the tree's order, and the tree only gained leaves.
        for (std::size_t i = 0, j = 0; i < all.size(); ++i) {
            if (j < sampled.size() && all[i] == sampled[j])
                ++j;
            else
                grown.push_back(all[i]);
        }
        stats.leavesVisited += grown.size();
        const std::vector<LeafNode*> movingGrown = movingOf(grown);
        if (widened) {
            copyFar(grown);
        } else {
            from->copyAlso(movingGrown);
            stats.leavesCopied += movingGrown.size();
        }
        moving.insert(moving.end(), movingGrown.begin(), movingGrown.end());
        stats.sampledVoxels +=
            resample(*grid, moving, *from, !widened, region, map, tearsOrFills, tornWindow,
                     options->sampling, changes(), options->interrupter, resampling, &addedTree);
        sampled = std::move(all);
    };
    if (reach < bandReach && !seedsSampled(*grid, moving, region)) {
        // A strong stretch spread the images apart: the images are dilated as far as the band
        // reaches.
        mask = dilatedByCube(mask, bandReach - reach);
        stats.sampledReach = bandReach;
        sampleAlso(mask);
        // Where even that leaves a voxel next to the new crossing unsampled (a swirl that
        // carries a ball turns the outside deep into the shape, spreading its images farther
        // apart than the band reaches), those voxels are sampled themselves: a few rounds at
        // most, since each may put the crossing beside another.
        for (int round = 0; round < kSeedRounds; ++round) {
            const VoxelList missing = unsampledSeeds(*grid, moving, region);
            if (missing.empty()) break;
            VoxelList grown = mask;
            grown.insert(grown.end(), missing.begin(), missing.end());
            mask = eachLeafOnce(std::move(grown));
            sampleAlso(missing);
        }
    }
    from->freeCopies();
}

// Inactive voxels of the resampled leaves kept their old values, whose signs may now be wrong
// (space pulled out of the shape is inside it now): their signs, and those of the tiles
// around them, are re-derived from the band. Other leaves did not change. The band's outer
// voxels may lie in leaves no sample reached: those leaves are made now, after the signs were
// re-derived, so that they take the sign of the tile they replace.
void SegmentAdvector::Work::fixSigns() {
    stats.voxelsVisited += stats.sampledVoxels;
    stats.leavesFlooded += floodSignsIn(grid->tree(), moving, touched);
    if (stats.sampledReach < bandReach)
        makeLeavesWithin(*grid, mask, bandReach - stats.sampledReach, touched);
}

// Renormalizes only where values changed, and as far as the band reaches from there (the
// nearest surface of a voxel nearby may have moved): where the deformation is the identity
// (outside the tools' coatings, which fill only part of the box) the distances hold. The
// voxels the band grew into are freed too. Seeds are recomputed only next to what moved
// (changes()): the others are distances already, and seeding them again at every segment
// would let the surface creep where it curves within a voxel.
void SegmentAdvector::Work::renormalizeChanged() {
    if (!options->renormalize) return;
    freed = dilatedByCube(changed, int(std::ceil(halfWidth)) + 1);
    freed.insert(freed.end(), fresh.begin(), fresh.end());
    moved.insert(moved.end(), fresh.begin(), fresh.end());
    const auto pass = [&](Seeding seeding) {
        const FmmStats fmm = renormalize(*grid, touched, freed, moved, options->renormalization,
                                         options->interrupter, seeding,
                                         dividesByStretch() ? &gradientBefore : nullptr);
        stats.leavesVisited += fmm.leaves;
        stats.voxelsVisited += fmm.leaves * LeafNode::SIZE;
    };
    if (!seg->tears()) {
        pass(Seeding::Lower);
        return;
    }
    // A tear's seeds come from a field whose slope varies by orders of magnitude around the
    // rim: the first pass puts the surface where the tear leaves it, the second seeds the
    // same voxels from that surface (Seeding says why).
    pass(Seeding::Either);
    pass(Seeding::Interface);
}

// Sampling changed the band's voxels in `changed` and switched on those of `fresh`;
// renormalization, where it ran, wrote within `freed` and one step past it, where the band
// may grow. The sign floods and the pruning of emptied leaves change inactive values only.
void SegmentAdvector::Work::report(std::vector<openvdb::CoordBBox>* boxes) const {
    if (!boxes) return;
    boxes->clear();
    const auto addBox = [&](const openvdb::Coord& o, const leafwords::Words& on, int margin) {
        if (!leafwords::any(on)) return;
        int lo[3], hi[3];
        leafwords::bounds(on, lo, hi);
        boxes->emplace_back(o.offsetBy(lo[0] - margin, lo[1] - margin, lo[2] - margin),
                            o.offsetBy(hi[0] + margin, hi[1] + margin, hi[2] + margin));
    };
    if (options->renormalize) {
        for (const LeafVoxels& leaf : freed)
            addBox(leaf.origin, leaf.words, 1);
    } else {
        for (const VoxelList* list : {&changed, &fresh})
            for (const LeafVoxels& leaf : *list)
                addBox(leaf.origin, leaf.words, 0);
    }
}

SegmentAdvector::SegmentAdvector() : work_(std::make_unique<Work>()) {}
SegmentAdvector::~SegmentAdvector() = default;
SegmentAdvector::SegmentAdvector(SegmentAdvector&&) noexcept = default;
SegmentAdvector& SegmentAdvector::operator=(SegmentAdvector&&) noexcept = default;

std::size_t SegmentAdvector::scratchGrowths() const {
    return work_->growths;
}

AdvectStats SegmentAdvector::run(Grid& grid, const StepDeformation& segment,
                                 const AdvectOptions& options,
                                 std::vector<openvdb::CoordBBox>* changed) {
    Work& w = *work_;
    w.begin(grid, segment, options);
    AdvectStats& stats = w.stats;
    // Each phase under a clock of its own: its wall time and its serial time.
    const auto phase = [&](std::size_t k, auto&& body) {
        const SerialClock clock;
        body();
        stats.phases[k] = {clock.wallSeconds(), clock.serialSeconds()};
    };
    phase(0, [&] { w.findInterface(); });
    phase(1, [&] { w.mapImages(); });
    phase(2, [&] { w.widenSource(); });
    phase(3, [&] { w.growBand(); });
    phase(4, [&] { w.sample(); });
    phase(5, [&] { w.fixSigns(); });
    phase(6, [&] { w.renormalizeChanged(); });
    const auto& p = stats.phases;
    stats.growSeconds = p[0].seconds + p[1].seconds + p[2].seconds + p[3].seconds;
    stats.sampleSeconds = p[4].seconds + p[5].seconds;
    stats.renormalizeSeconds = p[6].seconds;
    stats.touched = w.touched;
    phase(7, [&] {
        w.report(changed);
        // What the segment holds of the grid goes: the next one starts from the grid alone.
        w.widened.reset();
        w.sampled.clear();
        w.moving.clear();
    });
    return stats;
}

AdvectStats advectSegment(Grid& grid, const StepDeformation& segment, const AdvectOptions& options,
                          std::vector<openvdb::CoordBBox>* changed) {
    return SegmentAdvector().run(grid, segment, options, changed);
}

} // namespace sweepers
