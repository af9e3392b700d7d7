// SPDX-License-Identifier: Apache-2.0
#include "levelset/advect.h"
#include "core/stopwatch.h"
#include "levelset/band.h"
#include "levelset/band_growth.h"
#include "levelset/dilate.h"
#include "levelset/renormalize.h"
#include "vdb/leaf_words.h"
#include "vdb/local_tree.h"
#include "vdb/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
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

// How many interface voxels a thread maps through the sub-steps at once: enough for the
// batched maps to pay, few enough for the points to stay in cache.
constexpr std::size_t kMapBatch = 256;

// Rounds of sampling the voxels seedsSampled finds missing, at most.
constexpr int kSeedRounds = 4;

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
    Resampler resampler;
    Staged staged;

    // --- the segment ------------------------------------------------------------------------
    Grid* grid = nullptr;
    const StepDeformation* seg = nullptr;
    const AdvectOptions* options = nullptr;
    AdvectStats stats;
    double h = 0.0, halfWidth = 0.0, forwardTolerance = 0.0, tornWindow = 0.0;
    double filledFrom = 0.0; // what a filling segment fills from (filledFromValue)
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
        filledFrom = s.fills() ? filledFromValue(g, s, o.sampling) : 0.0;
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
    ResampleOutput changes();
    ResamplePlan plan(const LeafMap& map) const;
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
    RenormalizeOptions redone;
    redone.region = indexBox(*grid, seg->affectedBox(), int(needed) + 1);
    redone.only = &redo;
    redone.moved = &redo;
    redone.order = UpwindOrder::First;
    redone.interrupter = options->interrupter;
    renormalize(*source, redone);
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
        stats.filledVoxels = markFilled(*grid, *seg, (halfWidth + 2) * h, filledFrom, mask);
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
ResampleOutput SegmentAdvector::Work::changes() {
    const double nudge = options->resampleEachSubStep ? 0.0 : 0.01;
    ResampleOutput out;
    out.changed = &changed;
    out.moved = &moved;
    out.nudge = float(nudge * h);
    return out;
}

// A sampling pass over the segment's region through `map`, from a source that holds the
// grid's own values unless the band was widened.
ResamplePlan SegmentAdvector::Work::plan(const LeafMap& map) const {
    ResamplePlan p;
    p.box = region;
    p.map = map;
    p.sampling = options->sampling;
    p.sourceIsGrid = !widened;
    p.tearsOrFills = seg->tears() || seg->fills() ? seg : nullptr;
    p.filledFrom = filledFrom;
    p.tornWindow = tornWindow;
    p.interrupter = options->interrupter;
    return p;
}

// Samples the moving leaves at their pre-images: the composed inverse (default) or one
// resample per sub-step (5.3.4).
void SegmentAdvector::Work::sample() {
    sampled = leavesIn(grid->tree(), region);
    stats.leavesVisited += sampled.size();
    if (widened) copyFar(sampled);
    moving = movingOf(sampled);
    touched = changedRegion(*grid, *seg);
    if (options->resampleEachSubStep) {
        // Each sub-step reads what the one before wrote, inactive values included, so their
        // signs are re-derived before it reads them: otherwise a pre-image beyond the band
        // takes the sign its place had before the earlier sub-steps moved the surface.
        for (int k = 0; k < seg->steps(); ++k) {
            if (k > 0) stats.leavesFlooded += floodSignsIn(grid->tree(), moving, touched);
            const auto from = sourceOfSubStep(k);
            ResamplePlan step =
                plan([&](const Eigen::Vector3d* x, std::size_t n, Eigen::Vector3d* y, MapScratch&) {
                    for (std::size_t i = 0; i < n; ++i)
                        y[i] = seg->inverseStep(k, x[i]);
                });
            step.sourceIsGrid = !widened || k > 0;
            stats.sampledVoxels += resampler.run(*grid, moving, *from, step, changes());
            from->freeCopies();
        }
        return;
    }
    const ResamplePlan composed =
        plan([&](const Eigen::Vector3d* x, std::size_t n, Eigen::Vector3d* y, MapScratch& scratch) {
            seg->inverseMaps(x, n, y, scratch);
        });
    if (dividesByStretch()) fit(gradientBefore, moving.size());
    // Sampling reads the grid itself and writes beside it (staged), or, from a widened band,
    // reads the copies that hold it and writes into the grid.
    const auto from =
        widened ? std::make_shared<SampleSource>(*grid, widened) : SampleSource::live(*grid);
    if (!widened) staged.reserve(moving.size(), growths);
    ResampleOutput first = changes();
    first.staged = widened ? nullptr : &staged;
    first.gradientBefore = dividesByStretch() ? &gradientBefore : nullptr;
    stats.sampledVoxels = resampler.run(*grid, moving, *from, composed, first);
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
        ResamplePlan ofAdded = composed;
        ofAdded.only = &addedTree;
        stats.sampledVoxels += resampler.run(*grid, moving, *from, ofAdded, changes());
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
    const auto pass = [&](Seeding seeding, const VoxelList& only) {
        RenormalizeOptions o;
        o.region = touched;
        o.only = &only;
        o.moved = &moved;
        o.order = options->renormalization;
        o.seeding = seeding;
        o.gradientBefore = dividesByStretch() ? &gradientBefore : nullptr;
        o.interrupter = options->interrupter;
        const RenormalizeStats done = renormalize(*grid, o);
        stats.leavesVisited += done.leaves;
        stats.voxelsVisited += done.leaves * LeafNode::SIZE;
    };
    if (!seg->tears() && !seg->fills()) {
        pass(Seeding::Lower, freed);
        return;
    }
    // A tear's seeds come from a field whose slope varies by orders of magnitude around the
    // rim; an inflation joins the distances found along rays near its ball's edge to the
    // values carried through its map beyond (inflate.h), at seams the central differences
    // straddle. The first pass puts the surface where the segment leaves it, the second seeds
    // the same voxels from that surface (Seeding says why): all of them after a tear, those
    // within the inflation's fillReach() after an inflation.
    pass(Seeding::Either, freed);
    if (seg->tears()) {
        pass(Seeding::Interface, freed);
        return;
    }
    const openvdb::CoordBBox near =
        indexBox(*grid, seg->fillReach(), int(std::ceil(halfWidth)) + 1);
    VoxelList nearFreed;
    for (const LeafVoxels& leaf : freed)
        if (near.hasOverlap(openvdb::CoordBBox::createCube(leaf.origin, LeafNode::DIM)))
            nearFreed.push_back(leaf);
    pass(Seeding::Interface, nearFreed);
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
