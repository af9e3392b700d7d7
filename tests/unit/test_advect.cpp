// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/Interpolation.h>

#include "coarse.h"
#include "deform/inflate.h"
#include "deform/pinch.h"
#include "deform/strangle.h"
#include "deform/swirl.h"
#include "grids.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "levelset/advect.h"
#include "levelset/band.h"
#include "levelset/band_growth.h"
#include "levelset/create.h"
#include "levelset/measure.h"
#include "levelset/monotone_cubic.h"
#include "levelset/peer_check.h"
#include "mesh/marching_cubes.h"
#include "replay.h"
#include "sculpt/sculptor.h"
#include "tools/ellipsoid.h"

using namespace sweepers;
namespace fs = std::filesystem;

namespace {

Eigen::Vector3d centroid(const TriangleMesh& m) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    double v = 0.0;
    for (const Eigen::Vector3i& t : m.triangles) {
        const Eigen::Vector3d a = m.positions[t[0]].cast<double>(),
                              b = m.positions[t[1]].cast<double>(),
                              d = m.positions[t[2]].cast<double>();
        const double w = a.dot(b.cross(d)) / 6.0;
        v += w;
        c += w * (a + b + d) / 4.0;
    }
    return c / v;
}

// RMS (in voxels) of phi minus the exact distance, over voxels next to the zero crossing.
double interfaceRms(const Grid& g, const std::function<double(const Eigen::Vector3d&)>& sdf) {
    const double h = g.voxelSize()[0];
    auto acc = g.getConstAccessor();
    double sum2 = 0.0;
    std::size_t n = 0;
    for (auto leaf = g.tree().cbeginLeaf(); leaf; ++leaf)
        for (auto it = leaf->cbeginValueOn(); it; ++it) {
            if (!nextToCrossing(*leaf, it.pos(), acc)) continue;
            const double e = (*it - sdf(toEigen(g.indexToWorld(it.getCoord())))) / h;
            sum2 += e * e;
            ++n;
        }
    return std::sqrt(sum2 / n);
}

Placement at(const Eigen::Vector3d& t) {
    Placement p;
    p.t = t;
    return p;
}

// A pinch whose needles start just outside the unit sphere, along y.
PinchSpec pinchAcrossTheSphere() {
    PinchSpec spec;
    spec.axis = Eigen::Vector3d::UnitY();
    spec.size = 1.1;
    spec.falloff = 0.3;
    spec.open = 0.15;
    return spec;
}

struct Translated {
    GridPtr grid;
    Eigen::Vector3d d;
    double h;
};

// A ball tool enclosing the whole unit sphere (and its band) moves it by 20 voxels.
Translated translateSphere(bool perSubStep, Sampling sampling = Sampling::Trilinear) {
    const double h = 1.0 / 32;
    // 20 voxels along a direction that puts the result between lattice points.
    const Eigen::Vector3d d = 20 * h * Eigen::Vector3d(0.48, 0.6, 0.64);
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
    Sweep sweep{{{std::make_shared<EllipsoidShape>(1.25), 0.4, {at({0, 0, 0}), at(d)}}}};
    const SweepSegment seg(sweep, 0);
    AdvectOptions o;
    o.resampleEachSubStep = perSubStep;
    o.sampling = sampling;
    advectSegment(*g, seg, o);
    return {g, d, h};
}

} // namespace

TEST(Advect, EnclosedSphereTranslatesExactly) {
    const Translated t = translateSphere(false);
    const Grid& g = *t.grid;
    const TriangleMesh mesh = meshLevelSet(g);
    const Eigen::Vector3d c = centroid(mesh);
    const double volume = levelSetVolume(g), exactVolume = 4.0 / 3.0 * M_PI;
    const double rms =
        interfaceRms(g, [&](const Eigen::Vector3d& p) { return (p - t.d).norm() - 1.0; });
    std::printf("[ advect ] centre off by %.4f voxels, volume %+.3f%%, interface RMS %.4f voxels\n",
                (c - t.d).norm() / t.h, 100 * (volume - exactVolume) / exactVolume, rms);
    EXPECT_LT((c - t.d).norm(), 0.1 * t.h);
    EXPECT_NEAR(volume, exactVolume, 0.005 * exactVolume);
    EXPECT_LT(rms, 0.1);
}

TEST(Advect, ComposedInverseBeatsResamplingEachSubStep) {
    const Translated composed = translateSphere(false), perStep = translateSphere(true);
    auto sdf = [&](const Eigen::Vector3d& p) { return (p - composed.d).norm() - 1.0; };
    const double a = interfaceRms(*composed.grid, sdf), b = interfaceRms(*perStep.grid, sdf);
    std::printf(
        "[ advect ] interface RMS: composed inverse %.4f voxels, per sub-step %.4f voxels\n", a, b);
    EXPECT_LT(a, b);
}

// Two sub-steps of 0.25 each, 33 voxels, ten times the band: the second reads, beyond the
// band, space the first moved the sphere out of. With the inside signs that space had
// before, it grew 12 stray pieces of surface there.
TEST(Advect, ResamplingEachSubStepReadsTheSignsTheSubStepBeforeLeft) {
    const double h = 1.0 / 128;
    const Eigen::Vector3d d(0.5, 0.1, 0.0);
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 0.3, h, 3);
    Sweep sweep{{{std::make_shared<EllipsoidShape>(0.45), 0.6, {at({0, 0, 0}), at(d)}}}};
    const SweepSegment seg(sweep, 0);
    ASSERT_EQ(seg.steps(), 2);
    AdvectOptions o;
    o.resampleEachSubStep = true;
    advectSegment(*g, seg, o);
    const LevelSetMeasures m = measureLevelSet(*g);
    EXPECT_EQ(m.components, 1u);
    EXPECT_EQ(m.genus, 0);
    const Eigen::Vector3d c = centroid(meshLevelSet(*g));
    EXPECT_LT((c - d).norm(), 0.5 * h);
    EXPECT_NEAR(m.volume, 4.0 / 3.0 * M_PI * 0.027, 0.01 * 4.0 / 3.0 * M_PI * 0.027);
}

// A tool holding the whole sphere squeezes it to 0.4 of its size along x: the inverse map
// stretches space 2.5 times along x and not at all across, so the pre-images of the voxels
// next to the new surface lie up to 1.5 * 2.5 voxels from the old one, and trilinear
// sampling reads one more: the band is sampled 5 voxels wide, whatever the other axes do.
TEST(Advect, TheBandIsWidenedByTheLargestStretch) {
    const double h = 1.0 / 32;
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
    Placement squeezed;
    squeezed.scale = Eigen::Vector3d(0.4, 1.0, 1.0);
    Sweep sweep{{{std::make_shared<EllipsoidShape>(1.25), 0.4, {at({0, 0, 0}), squeezed}}}};
    const AdvectStats stats = advectSegment(*g, SweepSegment(sweep, 0));
    EXPECT_EQ(stats.widenedTo, 5.0);
    const LevelSetMeasures m = measureLevelSet(*g);
    EXPECT_NEAR(m.volume, 0.4 * 4.0 / 3.0 * M_PI, 0.01 * 0.4 * 4.0 / 3.0 * M_PI);
}

// The band is widened only where a stretch asks: the needles of a pinch stretch space near
// their tips alone, and the band of the leaves far from them in the box (which spans both
// tips) is left as it is (at 1/32, 124 of the box's 232 leaves are widened).
TEST(Advect, TheBandIsWidenedOnlyWhereTheStretchAsks) {
    const double h = 1.0 / 32;
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
    const auto parts = planPinch(pinchAcrossTheSphere(), h);
    bool widened = false;
    for (std::size_t j = 0; j + 1 < parts.size() && !widened; ++j) {
        const GridPtr before = g->deepCopy();
        const AdvectStats stats = advectSegment(*g, *parts[j]);
        if (stats.widenedTo <= 3.0) {
            EXPECT_EQ(stats.leavesWidened, 0u);
            continue;
        }
        widened = true;
        // The band's leaves the widening copied: those of the box grown by the width.
        const openvdb::CoordBBox box =
            indexBox(*before, parts[j]->affectedBox(), int(stats.widenedTo) + 3);
        std::size_t inBox = 0;
        for (auto leaf = before->tree().cbeginLeaf(); leaf; ++leaf)
            inBox += box.hasOverlap(leaf->getNodeBoundingBox());
        std::printf("[ advect ] needle segment %zu at 1/32: band widened to %g voxels in %zu of "
                    "the %zu leaves in its box\n",
                    j, stats.widenedTo, stats.leavesWidened, inBox);
        EXPECT_GT(stats.leavesWidened, 0u);
        EXPECT_LT(stats.leavesWidened, inBox);
    }
    EXPECT_TRUE(widened);
}

// Sampling reaches two voxels around the images of the surface, what renormalization's seeds
// read, and no further where that covers them: a drag samples that far. A tool holding the
// whole sphere blows it up 5 times, which spreads the images of neighbouring voxels 5 voxels
// apart: seeds between them are found unsampled, and the segment samples as far as the band
// reaches after all. Without that, voxels next to the new surface kept values 4.7 voxels off.
TEST(Advect, SamplingReachesEverySeedOfRenormalization) {
    const double h = 1.0 / 32;
    {
        GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
        Sweep sweep{
            {{std::make_shared<EllipsoidShape>(0.25), 0.25, {at({0, 0, 1}), at({0.05, 0, 1})}}}};
        EXPECT_EQ(advectSegment(*g, SweepSegment(sweep, 0)).sampledReach, 2);
    }
    const double r = 0.3, f = 5.0;
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), r, h, 3);
    Placement blown;
    blown.scale = Eigen::Vector3d::Constant(f);
    Sweep sweep{{{std::make_shared<EllipsoidShape>(1.5 * r), 0.2, {at({0, 0, 0}), blown}}}};
    const AdvectStats stats = advectSegment(*g, SweepSegment(sweep, 0));
    EXPECT_EQ(stats.sampledReach, 4);
    double largest = 0.0;
    auto acc = g->getConstAccessor();
    for (auto leaf = g->tree().cbeginLeaf(); leaf; ++leaf)
        for (auto it = leaf->cbeginValueOn(); it; ++it)
            if (nextToCrossing(*leaf, it.pos(), acc))
                largest = std::max(
                    largest, std::abs(*it - (g->indexToWorld(it.getCoord()).length() - f * r)) / h);
    std::printf("[ advect ] blown up %g times: sampled %d voxels around the images, largest error "
                "next to the surface %.3f voxels\n",
                f, stats.sampledReach, largest);
    EXPECT_LT(largest, 0.2);
    const double exact = 4.0 / 3.0 * M_PI * std::pow(f * r, 3);
    EXPECT_NEAR(levelSetVolume(*g), exact, 0.01 * exact);
}

// Where the images of the surface land too far apart for the seeds without widening the band
// (a swirl's segment at 1/128), the voxels the band's second growth adds are sampled in a
// second pass, from the grid as the first pass found it: the first pass stages its values
// beside the grid and swaps them in, the second reads copies of the leaves as they were.
// Without renormalization, every voxel sampled holds the old grid's value at its pre-image.
TEST(Advect, ASecondSamplingPassReadsTheGridAsItWas) {
    SwirlSpec spec;
    spec.at = {0.0, 0.95, 0.0};
    spec.move = {0.0, 0.06, 0.0};
    spec.radius = 0.25;
    const SwirlSegment seg(spec);
    const double h = 1.0 / 128;
    const GridPtr before = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
    const GridPtr after = before->deepCopy();
    AdvectOptions sampleOnly;
    sampleOnly.renormalize = false;
    sampleOnly.sampling = Sampling::Trilinear; // as the BoxSampler below reads
    const AdvectStats stats = advectSegment(*after, seg, sampleOnly);
    EXPECT_EQ(stats.sampledReach, 4); // the second pass ran
    EXPECT_EQ(stats.widenedTo, 3.0);  // from the grid itself, not from widened copies
    const openvdb::tools::GridSampler<Grid, openvdb::tools::BoxSampler> old(*before);
    const openvdb::CoordBBox region = indexBox(*after, seg.affectedBox(), 1);
    std::size_t sampled = 0, off = 0;
    for (auto it = after->cbeginValueOn(); it; ++it) {
        if (!region.isInside(it.getCoord())) continue;
        const Eigen::Vector3d x = toEigen(after->indexToWorld(it.getCoord()));
        const Eigen::Vector3d y = seg.inverseMap(x);
        if ((y - x).norm() < 1e-3 * h) continue;
        ++sampled;
        off += std::abs(*it - old.wsSample(toVdb(y))) > 1e-4 * h;
    }
    EXPECT_GT(sampled, 10000u);
    EXPECT_EQ(off, 0u);
}

// Trilinear sampling's error is half the second differences times t (1 - t) along each
// axis: it reads a distance high next to a convex surface, inside and out, and rounds the
// shape off. Corrected sampling takes that term off. A ball 6 voxels in radius moved by 20
// voxels, sampled only (not renormalized), next to its surface: trilinear reads it high (the
// ball shrinks), and the corrected values lie within a two-hundredth of a voxel of its
// distance on average, a tenth of trilinear's error.
TEST(Advect, CorrectedSamplingReadsACurvedDistance) {
    const double h = 1.0 / 32, radius = 6 * h;
    const Eigen::Vector3d d = 20 * h * Eigen::Vector3d(0.48, 0.6, 0.64);
    Sweep sweep{{{std::make_shared<EllipsoidShape>(1.0), 0.4, {at({0, 0, 0}), at(d)}}}};
    const SweepSegment seg(sweep, 0);
    double mean[2] = {0, 0}, bias[2] = {0, 0};
    for (const Sampling sampling : {Sampling::Trilinear, Sampling::Corrected}) {
        GridPtr g = makeSphere(Eigen::Vector3d::Zero(), radius, h, 3);
        AdvectOptions o;
        o.sampling = sampling;
        o.renormalize = false;
        advectSegment(*g, seg, o);
        const int k = sampling == Sampling::Corrected;
        std::size_t n = 0;
        for (auto it = g->cbeginValueOn(); it; ++it) {
            const double exact = (toEigen(g->indexToWorld(it.getCoord())) - d).norm() - radius;
            if (std::abs(exact) > 1.5 * h) continue;
            const double err = (*it - exact) / h;
            mean[k] += std::abs(err);
            bias[k] += err; // positive: read high, the ball shrinks
            ++n;
        }
        ASSERT_GT(n, 1000u);
        mean[k] /= double(n);
        bias[k] /= double(n);
    }
    std::printf("[ advect ] a ball 6 voxels in radius, sampled next to its surface: mean error "
                "%.4f voxel trilinear (mean %+.4f), %.4f corrected (%+.4f)\n",
                mean[0], bias[0], mean[1], bias[1]);
    EXPECT_GT(bias[0], 0.5 * mean[0]);
    EXPECT_LT(mean[1], 0.1 * mean[0]);
    EXPECT_LT(mean[1], 0.005);
}

TEST(Advect, MonotoneCubicNeverOvershoots) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < 10000; ++i) {
        const double fm = u(rng), f0 = u(rng), f1 = u(rng), f2 = u(rng);
        for (double t = 0.0; t <= 1.0; t += 0.125) {
            const double v = monotoneCubic(fm, f0, f1, f2, t);
            ASSERT_GE(v, std::min(f0, f1) - 1e-12);
            ASSERT_LE(v, std::max(f0, f1) + 1e-12);
        }
    }
    // Linear data is reproduced exactly, and the ends are the samples.
    EXPECT_NEAR(monotoneCubic(-1, 0, 1, 2, 0.3), 0.3, 1e-15);
    EXPECT_EQ(monotoneCubic(5, 1, 2, -3, 0.0), 1.0);
    EXPECT_EQ(monotoneCubic(5, 1, 2, -3, 1.0), 2.0);
    // Translating the enclosed sphere with it is as exact as with trilinear sampling.
    const Translated t = translateSphere(false, Sampling::MonotoneCubic);
    const double rms =
        interfaceRms(*t.grid, [&](const Eigen::Vector3d& p) { return (p - t.d).norm() - 1.0; });
    const double volume = enclosedVolume(meshLevelSet(*t.grid)), exact = 4.0 / 3.0 * M_PI;
    std::printf("[ advect ] monotone cubic: interface RMS %.4f voxels, mesh volume %+.3f%%\n", rms,
                100 * (volume - exact) / exact);
    EXPECT_LT(rms, 0.1);
    EXPECT_NEAR(volume, exact, 0.005 * exact);
}

TEST(Advect, InflationAddsTheBallInsideAndKeepsVolumeOutside) {
    // Decaudin's inflate (2.30, 2.31): a ball blown up inside the shape adds its volume,
    // outside it only pushes the shape aside. Volumes from the welded mesh.
    const double h = 1.0 / 64, rho = 0.3;
    const double ball = 4.0 / 3.0 * M_PI * rho * rho * rho;
    for (const Eigen::Vector3d& c : {Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(1.45, 0.1, 0)}) {
        GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
        const double v0 = enclosedVolume(meshLevelSet(*g));
        const Inflation inflate(c, rho, activeWorldBox(*g).expanded(2 * h));
        advectSegment(*g, inflate);
        const TriangleMesh mesh = meshLevelSet(*g);
        const double added = enclosedVolume(mesh) - v0;
        const bool inside = c.norm() < 1.0;
        std::printf("[ inflate ] centre %s: volume %+.5f (ball %.5f)\n",
                    inside ? "inside" : "outside", added, ball);
        if (inside) {
            EXPECT_NEAR(added, ball, 0.02 * ball);
        } else {
            EXPECT_NEAR(added, 0.0, 0.01 * v0);
        }
        EXPECT_TRUE(meshTopology(mesh).watertight());
    }
}

TEST(Advect, ASegmentsWorkFollowsTheBrushNotTheModel) {
    // The same three-segment pull on the unit sphere, alone and in a grid that also holds a
    // sphere of radius 4 ten units away: every count of work is the same, and so is the
    // result near the brush.
    const double h = 1.0 / 64;
    const GridPtr alone = makeSphere({0, 0, 0}, 1.0, h, 3.0);
    GridPtr both = alone->deepCopy();
    openvdb::tools::csgUnion(both->tree(), makeSphere({10, 0, 0}, 4.0, h, 3.0)->tree());
    ASSERT_GT(both->tree().leafCount(), 10 * alone->tree().leafCount());
    const Sweep sweep{
        {{std::make_shared<EllipsoidShape>(0.25),
          0.25,
          {at({0, 0.95, 0}), at({0.1, 1.15, 0}), at({0.2, 1.3, 0}), at({0.2, 1.45, 0.1})}}}};
    Sculptor small(alone), large(both);
    small.startMeshing();
    large.startMeshing();
    for (std::size_t k = 0; k < sweep.segmentCount(); ++k) {
        const SweepSegment segment(sweep, k);
        const SegmentReport a = small.applySegment(segment), b = large.applySegment(segment);
        std::printf("[ work ] segment %zu: %zu voxels and %zu leaves visited, %zu leaves "
                    "copied, %zu flooded, %zu re-meshed (model of %zu or %zu leaves)\n",
                    k, a.stats.voxelsVisited, a.stats.leavesVisited, a.stats.leavesCopied,
                    a.stats.leavesFlooded, a.remeshedLeaves,
                    std::size_t(small.grid().tree().leafCount()),
                    std::size_t(large.grid().tree().leafCount()));
        EXPECT_GT(a.stats.voxelsVisited, 0u);
        EXPECT_GT(a.stats.leavesCopied, 0u);
        EXPECT_GT(a.stats.leavesFlooded, 0u);
        EXPECT_EQ(a.stats.voxelsVisited, b.stats.voxelsVisited) << "segment " << k;
        EXPECT_EQ(a.stats.leavesVisited, b.stats.leavesVisited) << "segment " << k;
        EXPECT_EQ(a.stats.leavesCopied, b.stats.leavesCopied) << "segment " << k;
        EXPECT_EQ(a.stats.leavesFlooded, b.stats.leavesFlooded) << "segment " << k;
        EXPECT_EQ(a.remeshedLeaves, b.remeshedLeaves) << "segment " << k;
    }
    // Near the brush (the unit sphere's box) the two grids hold the same values.
    auto ca = small.grid().getConstAccessor();
    auto cb = large.grid().getConstAccessor();
    std::size_t differing = 0;
    const openvdb::CoordBBox box = small.grid().evalActiveVoxelBoundingBox();
    for (auto it = box.begin(); it; ++it)
        differing += ca.getValue(*it) != cb.getValue(*it);
    EXPECT_EQ(differing, 0u);
}

TEST(Advect, ShapesWhereTheDeformationIsTheIdentityCostNoWork) {
    // One pull on the unit sphere, alone and with a small sphere in a corner of the
    // segment's affected box, outside the tool's coating: the small sphere's surface is not
    // forward-mapped, sampled, copied or flooded, and it keeps its values.
    const double h = 1.0 / 128;
    const GridPtr alone = makeSphere({0, 0, 0}, 1.0, h, 3.0);
    GridPtr both = alone->deepCopy();
    const Eigen::Vector3d corner(0.42, 1.4, 0.42);
    openvdb::tools::csgUnion(both->tree(), makeSphere(corner, 0.05, h, 3.0)->tree());
    const Sweep sweep{
        {{std::make_shared<EllipsoidShape>(0.25), 0.25, {at({0, 0.95, 0}), at({0, 0.98, 0})}}}};
    const SweepSegment segment(sweep, 0);
    // The small sphere's band lies in the box whose leaves the segment looks at, away from
    // the coating (radius 0.5 around the tool's path).
    const Box affected = segment.affectedBox();
    ASSERT_TRUE(affected.contains(corner + Eigen::Vector3d::Constant(0.05 + 3 * h)));
    const GridPtr small = makeSphere(corner, 0.05, h, 3.0);
    const GridPtr before = both->deepCopy();
    const AdvectStats a = advectSegment(*alone, segment), b = advectSegment(*both, segment);
    std::printf("[ still ] interface %zu, sampled %zu, copied %zu, flooded %zu, voxels "
                "visited %zu alone; %zu, %zu, %zu, %zu, %zu with the small sphere\n",
                a.interfaceVoxels, a.sampledVoxels, a.leavesCopied, a.leavesFlooded,
                a.voxelsVisited, b.interfaceVoxels, b.sampledVoxels, b.leavesCopied,
                b.leavesFlooded, b.voxelsVisited);
    EXPECT_GT(a.interfaceVoxels, 0u);
    EXPECT_EQ(a.interfaceVoxels, b.interfaceVoxels);
    EXPECT_EQ(a.sampledVoxels, b.sampledVoxels);
    EXPECT_EQ(a.leavesCopied, b.leavesCopied);
    EXPECT_EQ(a.leavesFlooded, b.leavesFlooded);
    // The small sphere's leaves hold what they held, active states included.
    std::size_t leaves = 0, differing = 0;
    for (auto it = small->tree().cbeginLeaf(); it; ++it) {
        const LeafNode* was = before->tree().probeConstLeaf(it->origin());
        const LeafNode* now = both->tree().probeConstLeaf(it->origin());
        ASSERT_TRUE(was && now);
        ++leaves;
        differing += was->getValueMask() != now->getValueMask();
        for (openvdb::Index i = 0; i < LeafNode::SIZE; ++i)
            differing += was->getValue(i) != now->getValue(i);
    }
    EXPECT_GT(leaves, 0u);
    EXPECT_EQ(differing, 0u);
}

// A segment renormalizes only where its samples changed values or the band grew, and as far
// as the band reaches from there. That must be everywhere renormalizing could change
// anything: the same segments renormalized over their whole boxes give the same grid. (The
// start is renormalized once: OpenVDB's exact distances are not quite the upwind scheme's
// solution, which renormalizing leaves where it is. Both sample trilinearly: corrected
// sampling seeds from the stretch, which only the segment knows.)
TEST(Advect, ASegmentRenormalizesEverythingItChanged) {
    const double h = 1.0 / 64;
    GridPtr part = makeSphere({0, 0, 0}, 1.0, h, 3.0);
    renormalize(*part);
    GridPtr whole = part->deepCopy();
    const Sweep sweep{{{std::make_shared<EllipsoidShape>(0.25),
                        0.25,
                        {at({0, 0, 1}), at({0.03, 0.02, 1.01}), at({0.06, 0.04, 1.02})}}}};
    AdvectOptions trilinear, sampleOnly;
    trilinear.sampling = sampleOnly.sampling = Sampling::Trilinear;
    sampleOnly.renormalize = false;
    for (std::size_t k = 0; k < sweep.segmentCount(); ++k) {
        advectSegment(*part, SweepSegment(sweep, k), trilinear);
        RenormalizeOptions box;
        box.region = advectSegment(*whole, SweepSegment(sweep, k), sampleOnly).touched;
        renormalize(*whole, box);
    }
    auto a = part->getConstAccessor();
    auto b = whole->getConstAccessor();
    double largest = 0.0;
    for (auto it = whole->evalActiveVoxelBoundingBox().begin(); it; ++it)
        largest = std::max(largest, double(std::abs(a.getValue(*it) - b.getValue(*it))) / h);
    std::printf("[ renorm ] part of the box against all of it: values %.2g voxel apart\n", largest);
    EXPECT_LT(largest, 1e-5); // the solve's tolerance is 1e-6 voxel
}

// What a segment reports it changed holds every voxel of the band (before or after) whose
// value or state it changed, what a mesh kept up to date reads again, for every kind of
// segment: a drag, a drag resampled per sub-step or left without renormalization, a squeeze
// that widens the band, a pinch that tears the shape, an inflation. And it is less than the
// segment's box: the drag's boxes hold a part of the voxels of its box.
TEST(Advect, ASegmentReportsEveryVoxelItChanged) {
    const double h = 1.0 / 32;
    const auto check = [&](const char* what, Grid& g, const StepDeformation& seg,
                           const AdvectOptions& options) {
        const GridPtr before = g.deepCopy();
        std::vector<openvdb::CoordBBox> boxes;
        const AdvectStats stats = advectSegment(g, seg, options, &boxes);
        EXPECT_EQ(sweepers::test::changedOutside(*before, g, boxes), 0u) << what;
        EXPECT_GT(sweepers::test::differingVoxels(*before, g), 0u) << what; // it did change
        openvdb::MaskTree reported;
        for (const openvdb::CoordBBox& box : boxes)
            reported.sparseFill(box, true, true);
        std::printf("[ advect ] %s: %zu boxes, %llu voxels, of the %llu of its box\n", what,
                    boxes.size(), (unsigned long long)reported.activeVoxelCount(),
                    (unsigned long long)stats.touched.volume());
        return double(reported.activeVoxelCount()) / double(stats.touched.volume());
    };
    const Sweep drag{{{std::make_shared<EllipsoidShape>(0.3),
                       0.3,
                       {at({0, 1, 0}), at({0.05, 1.1, 0}), at({0.1, 1.2, 0.02})}}}};
    for (const bool perSubStep : {false, true})
        for (const bool renormalize : {true, false}) {
            GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
            AdvectOptions o;
            o.resampleEachSubStep = perSubStep;
            o.renormalize = renormalize;
            for (std::size_t k = 0; k < drag.segmentCount(); ++k) {
                const double part = check(perSubStep    ? "drag, per sub-step"
                                          : renormalize ? "drag"
                                                        : "drag, not renormalized",
                                          *g, SweepSegment(drag, k), o);
                if (!perSubStep && renormalize) {
                    EXPECT_LT(part, 0.7);
                }
            }
        }
    {
        GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
        Placement squeezed;
        squeezed.scale = Eigen::Vector3d(0.4, 1.0, 1.0);
        Sweep sweep{{{std::make_shared<EllipsoidShape>(1.25), 0.4, {at({0, 0, 0}), squeezed}}}};
        check("squeeze (band widened)", *g, SweepSegment(sweep, 0), {});
    }
    {
        GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
        for (const auto& part : planPinch(pinchAcrossTheSphere(), h))
            check("pinch", *g, *part, {});
    }
    {
        GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
        check("inflation", *g, Inflation({0.5, 0, 0}, 0.3, activeWorldBox(*g).expanded(2 * h)), {});
    }
}

// A grid's copy (Grid::deepCopy, a file read back) must sculpt to the same voxels as the
// grid itself, at voxel sizes that are not powers of two too: copying a transform once
// moved 1/24 by a unit in the last place, and with it every sample point and the band's
// half-width (2.9999999999999996 voxels, so one more ring of widening).
TEST(Advect, ACopyOfTheGridSculptsToTheSameVoxels) {
    for (const double h : {1.0 / 24, 0.01}) {
        Sculptor s(makeSphere({0, 0, 0}, 1.0, h, 3.0));
        EXPECT_EQ(halfWidthOf(s.grid()), 3.0);
        InflateStroke dab{{0, 1, 0}, 0.15};
        s.applyStroke(dab);
        Sculptor copy(s.grid().deepCopy());
        EXPECT_EQ(copy.grid().voxelSize(), s.grid().voxelSize());
        ToolSpec t;
        t.size = Eigen::Vector3d::Constant(0.3);
        t.falloff = 0.3;
        Placement a, b;
        a.t = {1, 0, 0};
        b.t = {1.2, 0, 0};
        t.path = {a, b};
        const Stroke drag = SweepStroke{MirrorAxis::None, {t}};
        s.applyStroke(drag);
        copy.applyStroke(drag);
        EXPECT_EQ(sweepers::test::differingVoxels(s.grid(), copy.grid()), 0u) << "h = " << h;
    }
}

// The interface voxels a segment maps forward are found 64 at a time; they are exactly
// the voxels nextToCrossing finds one by one, at leaf borders and next to tiles too.
TEST(Advect, InterfaceVoxelsFoundByWordsAreThoseNextToTheCrossing) {
    const double h = 1.0 / 40;
    GridPtr g = makeSphere(Eigen::Vector3d(0.01, -0.02, 0.03), 0.6, h, 3);
    // The band's leaves border tiles inside and outside; a ball a few voxels across adds
    // voxels with the surface on both sides.
    GridPtr ball = makeSphere(Eigen::Vector3d(0.9, 0.0, 0.0), 0.06, h, 3);
    openvdb::tools::csgUnion(*g, *ball);
    const auto acc = g->getConstAccessor();
    std::size_t voxels = 0, crossing = 0, differ = 0;
    for (auto leaf = g->tree().cbeginLeaf(); leaf; ++leaf) {
        const auto words = crossingVoxels(*leaf, acc);
        for (openvdb::Index off = 0; off < LeafNode::SIZE; ++off) {
            const bool one = nextToCrossing(*leaf, off, acc);
            differ += words.isOn(off) != one;
            crossing += one;
            ++voxels;
        }
    }
    EXPECT_GT(crossing, 10000u);
    EXPECT_GT(voxels, 4 * crossing);
    EXPECT_EQ(differ, 0u);
}

namespace {
// A sweep segment that keeps its stretch bound to itself: advection measures the stretch.
class WithoutStretchBound : public SweepSegment {
  public:
    using SweepSegment::SweepSegment;
    double stretchBound() const override { return std::numeric_limits<double>::infinity(); }
};
} // namespace

// A drag's segments bound their stretch well below what would widen the band, so it is not
// measured; the grid is the one measuring it gives.
TEST(Advect, ADragMeasuresNoStretchAndSculptsTheSame) {
    const double h = 1.0 / 64;
    const GridPtr bounded = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
    const GridPtr measured = bounded->deepCopy();
    std::vector<Placement> path(4);
    for (std::size_t k = 0; k < path.size(); ++k)
        path[k].t = Eigen::Vector3d(0.012 * double(k), 0.008 * double(k), 1.0);
    const Sweep drag{{{std::make_shared<EllipsoidShape>(0.25), 0.25, path}}};
    for (std::size_t k = 0; k < drag.segmentCount(); ++k) {
        const SweepSegment seg(drag, k);
        const AdvectStats a = advectSegment(*bounded, seg);
        const AdvectStats b = advectSegment(*measured, WithoutStretchBound(drag, k));
        EXPECT_EQ(a.stretchSamples, 0u) << "segment " << k;
        EXPECT_GT(b.stretchSamples, 100u) << "segment " << k;
        EXPECT_EQ(a.widenedTo, b.widenedTo) << "segment " << k;
    }
    EXPECT_EQ(sweepers::test::differingVoxels(*bounded, *measured), 0u);
}

// A Sculptor's advector keeps its scratch between segments: once the first segments of a
// drag have sized the buffers, the rest of a long drag of like segments grows none of them.
TEST(Advect, TheAdvectorReusesItsBuffersFromSegmentToSegment) {
    const StrokeScript script = readStrokeScript(std::string(SWEEPERS_DATA_DIR) + "/drag.json");
    Sculptor sculptor(makeSphere({0, 0, 0}, 1.0, 1.0 / 64, 3.0));
    const std::size_t warmUp = 10;
    std::size_t done = 0, afterWarmUp = 0;
    applyStrokes(sculptor, script.strokes, [&](std::size_t d, std::size_t) {
        done = d;
        if (d == warmUp) afterWarmUp = sculptor.advector().scratchGrowths();
    });
    ASSERT_GE(done, 5 * warmUp); // a long drag
    EXPECT_GT(afterWarmUp, 0u);  // the first segments sized the buffers
    EXPECT_EQ(sculptor.advector().scratchGrowths(), afterWarmUp)
        << "a buffer grew after the first " << warmUp << " segments";
}

// A slow stroke nudges the surface: each segment changes the values next to it by less than
// advect's threshold of a move (a hundredth of a voxel), and seeds whose stencil was only
// nudged keep the values sampled there, where seeding them again at every segment lets the
// surface creep. 400 segments of an inflation at the centre of a ball (each moves its surface
// 0.007 voxel, 2.4 voxels in all) leave it within 0.15 voxel RMS of the exact ball next to
// the surface (0.088; seeded again at every nudge, 0.31).
TEST(Advect, ASlowStrokeDoesNotCreep) {
    const double h = 1.0 / 32, radius = 0.5, rho = 0.055;
    const int segments = 400;
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), radius, h, 3);
    const Inflation inflate(Eigen::Vector3d::Zero(), rho,
                            Box(Eigen::Vector3d::Constant(-0.75), Eigen::Vector3d::Constant(0.75)));
    for (int k = 0; k < segments; ++k)
        advectSegment(*g, inflate);
    const double end = std::cbrt(radius * radius * radius + segments * rho * rho * rho);
    const double rms = interfaceRms(*g, [&](const Eigen::Vector3d& p) { return p.norm() - end; });
    std::printf("[ advect ] %d nudging segments: radius %.4f -> %.4f, interface RMS %.4f "
                "voxels\n",
                segments, radius, end, rms);
    EXPECT_LT(rms, 0.15);
}

// Where the band is widened, sampling reads every leaf from the widened copy: a voxel the
// deformation leaves in place must read its own value there. Sampling alone (no
// renormalization), every still voxel of a strangle's segments keeps its value to the bit;
// renormalizing the whole copy had seeded the still band again at every segment, and its
// surface crept where nothing moved it.
TEST(Advect, AWidenedBandGivesStillVoxelsTheirOwnValues) {
    const double h = 1.0 / 32;
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
    StrangleSpec noose;
    noose.at = Eigen::Vector3d(0.78, 0, 0);
    noose.axis = Eigen::Vector3d::UnitZ();
    noose.size = 0.9;
    noose.falloff = 0.25;
    noose.open = 0.3;
    const auto parts = planStrangle(noose, h);
    AdvectOptions sampleOnly;
    sampleOnly.renormalize = false;
    std::size_t widened = 0, still = 0, changed = 0;
    for (std::size_t j = 0; j + 1 < parts.size(); ++j) {
        const GridPtr before = g->deepCopy();
        const AdvectStats stats = advectSegment(*g, *parts[j], sampleOnly);
        widened += stats.leavesWidened > 0;
        const auto now = g->getConstAccessor();
        for (auto it = before->cbeginValueOn(); it; ++it) {
            if (!it.isVoxelValue() ||
                !parts[j]->stillAt(toEigen(before->indexToWorld(it.getCoord()))))
                continue;
            ++still;
            changed += now.getValue(it.getCoord()) != *it;
        }
    }
    std::printf("[ advect ] a strangle's %zu segments, %zu of them widened: %zu still voxels, "
                "%zu changed\n",
                parts.size() - 1, widened, still, changed);
    EXPECT_GT(widened, 0u);
    EXPECT_GT(still, 10000u);
    EXPECT_EQ(changed, 0u);
}

// An inflation centred on the surface (the README's Python example): the thesis gives its
// new ball the value at the centre, about zero, with no sign, and the grid made a ragged crown
// of several parts. The ball is clay now: one part, genus 0, the ball's volume added, and
// OpenVDB's check accepts the grid, every voxel of it. So does it for centres 2 and 8 voxels
// in, where the pushed surface leaves the ball within a voxel or two of its edge (the second
// beyond the band, where the centre's depth is found from the surface): the values near the
// ball's edge are distances along the rays from the centre to the pushed surface. (Before,
// the check refused 32, 172 and 0 voxels at 1/32 for a centre on the surface, 2 and 8
// voxels in; 0, 356 and 204 at 1/64; 124, 1060 and 3288 at 1/128.)
// A centre a voxel and a half outside is moved onto the surface, and adds the same ball.
TEST(Advect, AnInflationCentredOnTheSurfaceAddsOneBallOfClay) {
    const double rho = 0.4, ball = 4.0 / 3.0 * M_PI * rho * rho * rho;
    std::vector<int> sizes = {32, 64};
    if (!sweepers::test::coarse()) sizes.push_back(128);
    for (const int inverse : sizes) {
        const double h = 1.0 / inverse;
        // On the surface, 1.5 voxels out (moved onto it), 2 voxels in (within the band) and 8
        // voxels in (beyond it).
        for (const double out : {0.0, 1.5 * h, -2.0 * h, -8.0 * h}) {
            Sculptor s(makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3));
            const double v0 = levelSetVolume(s.grid());
            InflateStroke inflate{Eigen::Vector3d(0, 1.0 + out, 0), rho};
            s.applyStroke(inflate);
            const LevelSetMeasures m = measureLevelSet(s.grid());
            const PeerCheck peer = peerCheck(s.grid());
            const BandReport band = checkBand(s.grid());
            std::printf("[ inflate ] centre %+.1f voxels off the surface at 1/%d: %zu parts, "
                        "Euler %d, volume %+.5f (ball %.5f), checkLevelSet refuses %zu\n",
                        out / h, inverse, m.components, m.eulerCharacteristic, m.volume - v0, ball,
                        peer.eikonal);
            EXPECT_EQ(m.components, 1u) << inverse;
            EXPECT_EQ(m.eulerCharacteristic, 2) << inverse;
            // Short by what the grid's resolution loses where the pushed surface meets the
            // ball and renormalization after the push (0.8% at most, measured).
            EXPECT_NEAR(m.volume - v0, ball, 0.01 * ball) << inverse;
            EXPECT_EQ(band.vdbCheck, "") << inverse;
            EXPECT_EQ(band.bandHoles, 0u) << inverse;
            EXPECT_EQ(peer.message, "") << inverse;
            EXPECT_EQ(peer.eikonal, 0u) << inverse;
        }
    }
}
