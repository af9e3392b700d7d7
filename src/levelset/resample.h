// SPDX-License-Identifier: Apache-2.0
// Semi-Lagrangian sampling (thesis 5.3.2-5.3.3): the new value of a voxel x is the old band
// read at the deformation's inverse map f^-1(x). What a segment's sampling phase runs
// (advect.h): the source it reads (the grid as it was before sampling began), the values
// staged beside the grid until every sample is taken, and the pass over a list of leaves.
//
// A pass is one call of Resampler::run with a plan: which voxels, which map, how to read
// between voxels, and what the deformation adds where it tears or fills space.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <vector>

#include "deform/step_deformation.h"
#include "levelset/cell_interpolation.h"
#include "levelset/interrupt.h"
#include "vdb/leaf_words.h"
#include "vdb/vdb.h"
#include "vdb/voxel_list.h"

namespace sweepers {

// How sampling reads the grid between its voxels.
//  Trilinear: the thesis's (5.3.2). Its error is half the second differences times
//    t (1 - t) along each axis: it reads a distance high next to a convex surface (inside
//    and out) and low next to a concave one, and rounds the shape off at every segment.
//  Corrected: trilinear less that term, with the second differences of the cell's corners
//    interpolated, where the value lies within two and a half voxels of the surface (farther
//    out the differences read the band's clamp): it reads every quadratic field exactly. Its
//    seeds are divided by the stretch the segment made (renormalize.h), not by their
//    gradient's norm, which reads low wherever the surface curves within a few voxels and
//    would let it creep.
//  MonotoneCubic: the monotone cubic of appendix C.1 (64 values per sample).
enum class Sampling { Trilinear, Corrected, MonotoneCubic };

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
    void reserve(std::size_t leaves, std::atomic<std::size_t>& growths);

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
    void swapInto(const std::vector<LeafNode*>& leaves);
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
                                                     const std::vector<LeafNode*>& leaves);
    // The live grid alone (sampling writes elsewhere: Staged).
    static std::shared_ptr<SampleSource> live(const Grid& live);
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
    static void addCopies(Grid& copies, const std::vector<LeafNode*>& leaves);
    static void addCopies(Grid& copies, const std::vector<const LeafNode*>& leaves);

    // Frees the copies, when nothing else holds them (freeOnThisThread).
    void freeCopies();

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

        // Trilinear interpolation at index-space point p. When the cell lies inside one leaf
        // (343 cells in 512) its eight corners are read from that leaf's buffer, after a
        // single lookup instead of eight.
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

        // Sampling::Corrected at index-space point p, within `reach` (index units) of the
        // surface; `slope`, when given, receives the central differences there.
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

// A leaf of the widened source where the old band did not reach: every voxel at the widened
// background, with the sign the grid has there (a tile of the inside or the outside).
void farWithSigns(LeafNode& leaf, float far, const Grid::ConstAccessor& live);

// The inverse map of a pass: map(x, n, y, scratch) maps a leaf's n voxel centres x at once,
// into y.
using LeafMap = std::function<void(const Eigen::Vector3d* x, std::size_t n, Eigen::Vector3d* y,
                                   MapScratch& scratch)>;

// One sampling pass: which voxels, at which pre-images, read how.
struct ResamplePlan {
    // Every active voxel inside `box` of the leaves passed is sampled; with `only`, just
    // those it holds as well.
    openvdb::CoordBBox box;
    const openvdb::MaskTree* only = nullptr;
    LeafMap map;
    Sampling sampling = Sampling::Corrected;
    // When the source holds the grid's own values (no widened band), a voxel that the map
    // leaves in place keeps its value without interpolating: a sample at a voxel centre
    // returns it exactly.
    bool sourceIsGrid = false;
    // The deformation when it tears or fills, else null.
    //
    // A deformation that tears space adds how deep x lies in what it opened. A point it opened
    // reads the largest value along the torn set within `tornWindow` of the point it was torn
    // from: on a grid, what the pinch's needles bring together (or the strangle's noose
    // squeezes) keeps a membrane a few voxels thick where the exact surface meets itself at
    // one point (the grid rounds off the funnels' tips), and the tear opens through it
    // instead of keeping it as the rim of the hole. Where the tear asks
    // (StepDeformation::windowPastRim), points within the window's reach past the rim read
    // that value less their distance to the rim, when it is more than their own. And no value
    // sampled for a tear lies below the least value the tear allows at the pre-image
    // (StepDeformation::leastValue): the funnels the needles pull (or the noose squeezes)
    // towards the torn set are thinner than the grid resolves, so it reads material next to
    // the set where the shape has none, and the tear, which stretches the space around the
    // set by orders of magnitude, would spread that over the rim of the hole.
    //
    // A deformation that fills what has no pre-image (fills(): an inflation's ball) turns the
    // value sampled there into its filled value, from `filledFrom`.
    const StepDeformation* tearsOrFills = nullptr;
    double filledFrom = 0.0; // filledFromValue, where tearsOrFills fills
    double tornWindow = 0.0; // world units
    Interrupter* interrupter = nullptr;
};

// Where a pass writes and what it lists, a leaf at a time (a leaf resampled again is listed
// again): every voxel whose value changed or that joined the band (`changed`), and of them
// those whose value moved by more than `nudge` (world units) or that joined (`moved`): the
// renormalization seeds again only next to those. With `staged`, the new values go there and
// the leaves keep theirs. With `gradientBefore` (one entry per leaf passed), the norm of the
// source's gradient at the pre-image of every sample that lies near the surface
// (RenormalizeOptions::gradientBefore).
struct ResampleOutput {
    VoxelList* changed = nullptr;
    VoxelList* moved = nullptr;
    float nudge = 0.0f;
    Staged* staged = nullptr;
    VoxelValues* gradientBefore = nullptr;
};

// Sampling passes, with the per-thread scratch (each leaf's pre-images and a dense block of
// the source around it) kept from pass to pass.
class Resampler {
  public:
    Resampler();
    ~Resampler();
    Resampler(Resampler&&) noexcept;
    Resampler& operator=(Resampler&&) noexcept;

    // Resamples the voxels `plan` names in `leaves` of `grid` from `source`; gives how many
    // it sampled.
    std::size_t run(Grid& grid, const std::vector<LeafNode*>& leaves, const SampleSource& source,
                    const ResamplePlan& plan, const ResampleOutput& out);

  private:
    struct Scratch;
    std::unique_ptr<Scratch> scratch_;
};

// Where rays meet the surface the source holds (trilinear samples), for a filling
// deformation's region (StepDeformation::filledValue).
class GridProbe : public SurfaceProbe {
  public:
    GridProbe(const SampleSource::Accessor& acc, const openvdb::math::Transform& transform)
        : acc_(acc), place_(transform), h_(transform.voxelSize()[0]) {}
    SurfaceExit firstExit(const Eigen::Vector3d& from, const Eigen::Vector3d& direction,
                          double start, double most) const override;

  private:
    const SampleSource::Accessor& acc_;
    VoxelPlacement place_;
    double h_;
};

// The value a filling deformation's region is made from: at its filledFrom(), on the grid
// before the deformation, sampled as `sampling` samples every voxel; deeper than the band,
// minus the distance to the surface the grid's crossings place (down to deepestFill()).
// Found once a segment (ResamplePlan::filledFrom).
double filledFromValue(const Grid& grid, const StepDeformation& seg, Sampling sampling);

} // namespace sweepers
