// SPDX-License-Identifier: Apache-2.0
// The smooth brush (levelset/smooth.h) on a bumpy sphere: the noise under the brush goes,
// nothing beyond its reach moves, the stroke written to a script replays to the same grid,
// and a study says no exact shape stands behind it.
#include <gtest/gtest.h>

#include <cmath>

#include <atomic>
#include <set>

#include <openvdb/math/Stencils.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <tbb/global_control.h>

#include "coarse.h"
#include "core/limits.h"
#include "grids.h"
#include "io/stroke_script.h"
#include "io/study_files.h"
#include "levelset/band.h"
#include "levelset/create.h"
#include "levelset/measure.h"
#include "levelset/renormalize.h"
#include "levelset/smooth.h"
#include "sculpt/sculptor.h"
#include "study/study.h"

using namespace sweepers;
using sweepers::test::differingVoxels;

namespace {

constexpr double kR = 0.5;                   // the sphere
constexpr double kBrush = 0.25, kFall = 0.1; // the brush
constexpr double kH = 1.0 / 96;

// A sphere of radius kR with bumps of a tenth of the brush radius, a fifth of it apart on
// the surface's scale, renormalized.
GridPtr bumpySphere() {
    const double amplitude = 0.1 * kBrush, k = 2.0 * M_PI / (0.4 * kBrush);
    const auto sdf = [&](const Eigen::Vector3d& p) {
        return p.norm() - kR -
               amplitude * std::sin(k * p.x()) * std::sin(k * p.y()) * std::sin(k * p.z() + 0.7);
    };
    // Sampled in a wide band (the bumps' slopes make the function far from a distance),
    // then rebuilt as the distance to its zero set in the usual band.
    const int n = int(std::ceil((kR + 0.2) / kH));
    const GridPtr wide = test::gridFromSdf(sdf, kH, 8.0, {openvdb::Coord(-n), openvdb::Coord(n)});
    GridPtr g = openvdb::tools::levelSetRebuild(*wide, 0.0f, 3.0f);
    markAsDocument(*g);
    return g;
}

// The RMS deviation of the mean curvature from 1 / kR over the voxels next to the surface
// (|phi| < half a voxel) within the brush's radius of c.
double curvatureDeviation(const Grid& g, const Eigen::Vector3d& c) {
    openvdb::math::CurvatureStencil<Grid> st(g);
    double sum = 0.0;
    std::size_t n = 0;
    for (auto it = g.cbeginValueOn(); it; ++it) {
        if (std::abs(*it) >= 0.5 * kH) continue;
        if ((toEigen(g.indexToWorld(it.getCoord())) - c).norm() > kBrush) continue;
        st.moveTo(it.getCoord());
        const double d = double(st.meanCurvature()) - 1.0 / kR;
        sum += d * d;
        ++n;
    }
    EXPECT_GT(n, 100u);
    return std::sqrt(sum / double(n));
}

SmoothStroke dabsAt(const std::vector<Eigen::Vector3d>& at, double strength = 1.0) {
    SmoothStroke s;
    s.tool.size = Eigen::Vector3d::Constant(kBrush);
    s.tool.falloff = kFall;
    for (const Eigen::Vector3d& p : at) {
        Placement pl;
        pl.t = p;
        s.tool.path.push_back(pl);
    }
    s.strength = strength;
    return s;
}

} // namespace

TEST(Smooth, RelaxesTheNoiseUnderTheBrushAndNothingBeyondIt) {
    const GridPtr before = bumpySphere();
    const Eigen::Vector3d c(0.0, kR, 0.0);
    const double deviation = curvatureDeviation(*before, c);
    Sculptor sculptor(before->deepCopy());
    sculptor.applyStroke(dabsAt({c}));
    const Grid& after = sculptor.grid();
    const double smoothed = curvatureDeviation(after, c);
    std::printf(
        "[ smooth ] mean curvature's RMS deviation from 1/R under the brush: %.3f -> %.3f\n",
        deviation, smoothed);
    EXPECT_LT(smoothed, 0.5 * deviation);

    // Beyond the brush's reach every voxel keeps its value and state, to the bit.
    SmoothBrush brush;
    brush.center = c;
    brush.radius = kBrush;
    brush.falloff = kFall;
    const double reach = CurvatureSmoother(*before, brush).reachRadius();
    const openvdb::CoordBBox box = before->evalActiveVoxelBoundingBox().expandBy(8), all = box;
    auto a = before->getConstAccessor();
    auto b = after.getConstAccessor();
    std::size_t changed = 0, changedNear = 0;
    for (auto it = all.begin(); it; ++it) {
        const bool differs =
            a.getValue(*it) != b.getValue(*it) || a.isValueOn(*it) != b.isValueOn(*it);
        if (!differs) continue;
        if ((toEigen(before->indexToWorld(*it)) - c).norm() > reach)
            ++changed;
        else
            ++changedNear;
    }
    EXPECT_EQ(changed, 0u);
    EXPECT_GT(changedNear, 1000u);
}

TEST(Smooth, StrengthIsAFractionOfTheFlowTime) {
    const GridPtr start = bumpySphere();
    const Eigen::Vector3d c(0.0, kR, 0.0);
    Sculptor half(start->deepCopy()), full(start->deepCopy());
    half.applyStroke(dabsAt({c}, 0.5));
    full.applyStroke(dabsAt({c}, 1.0));
    const double d0 = curvatureDeviation(*start, c), d1 = curvatureDeviation(half.grid(), c),
                 d2 = curvatureDeviation(full.grid(), c);
    EXPECT_LT(d2, d1);
    EXPECT_LT(d1, d0);
}

TEST(Smooth, TheWrittenStrokeReplaysToTheSameGrid) {
    const GridPtr start = bumpySphere();
    const SmoothStroke stroke =
        dabsAt({{0.0, kR, 0.0}, {0.1, kR - 0.01, 0.0}, {0.2, kR - 0.04, 0.05}}, 4.0);
    Sculptor a(start->deepCopy());
    a.applyStroke(stroke);

    StrokeScript script;
    script.grid.voxelSize = kH;
    script.strokes = {stroke};
    const StrokeScript back = loadStrokeScript(formatStrokeScript(script), "smooth.json", ".");
    ASSERT_EQ(back.strokes.size(), 1u);
    const auto* read = std::get_if<SmoothStroke>(&back.strokes[0]);
    ASSERT_NE(read, nullptr);
    EXPECT_EQ(read->tool.path.size(), 3u);
    EXPECT_EQ(read->strength, 4.0); // past 1: a smooth stroke's strength reaches 10
    Sculptor b(start->deepCopy());
    b.applyStroke(back.strokes[0]);
    EXPECT_EQ(differingVoxels(a.grid(), b.grid()), 0u);
    EXPECT_GT(differingVoxels(a.grid(), *start), 0u);
}

TEST(Smooth, AStudyOfAHistoryThatSmoothsMeasuresNoExactError) {
    // No exact shape stands behind a smooth stroke: the run's error columns stay NaN (and
    // read back so), where the same run without it is measured.
    const auto sphere = ExactReference::sphere(Eigen::Vector3d::Zero(), kR);
    for (const bool smooth : {false, true}) {
        SweepStroke grab;
        ToolSpec tool = dabsAt({{0.0, kR, 0.0}, {0.0, kR + 0.1, 0.0}}).tool;
        grab.tools = {tool};
        std::vector<Stroke> strokes = {grab};
        if (smooth) strokes.emplace_back(dabsAt({{0.0, kR + 0.1, 0.0}}));
        const GridPtr start =
            test::gridFromSdf([](const Eigen::Vector3d& p) { return p.norm() - kR; }, 1.0 / 32, 3.0,
                              {openvdb::Coord(-24), openvdb::Coord(24)});
        const StudyRun run = runStudyCase(start, strokes, sphere, StudyVariant::Trilinear);
        const StudyRow back = studyRowFromJson(studyRowJson(run.row, true), "row");
        EXPECT_EQ(std::isnan(run.row.error.rms), smooth);
        EXPECT_EQ(std::isnan(back.error.rms), smooth);
        EXPECT_EQ(std::isnan(back.error.volumeError()), smooth);
        EXPECT_EQ(back.referenceTopologyKnown, !smooth);
    }
}

TEST(Smooth, ManyDabsKeepAValidNarrowBand) {
    // Dabs that overlap move the surface by more than the band holds around it at first:
    // the band grows with it (no hole, nothing beyond it), and the topology stays a sphere's.
    Sculptor sculptor(bumpySphere());
    std::vector<Eigen::Vector3d> path;
    for (int k = 0; k <= 8; ++k) {
        const double a = -0.6 + 0.15 * k;
        path.emplace_back(kR * std::sin(a), kR * std::cos(a), 0.1);
    }
    for (int pass = 0; pass < 3; ++pass) {
        sculptor.applyStroke(dabsAt(path));
        const BandReport r = checkBand(sculptor.grid());
        EXPECT_EQ(r.bandHoles, 0u) << "pass " << pass;
        EXPECT_EQ(r.beyondBand, 0u) << "pass " << pass;
        EXPECT_EQ(topologicalEulerCharacteristic(sculptor.grid()), 2) << "pass " << pass;
    }
}

TEST(Smooth, ABrushLargerThanTheShapeVisitsNoMoreThanItsLeaves) {
    // A ball of radius 40 around a sphere of 0.5 at 1/96: its reach box holds millions of
    // leaf places, nearly all empty; finding the leaves under it walks the grid's instead.
    const GridPtr g = bumpySphere();
    SmoothBrush brush;
    brush.center = Eigen::Vector3d(0.0, kR, 0.0);
    brush.radius = 40.0;
    brush.falloff = 0.1;
    brush.time = 1e-5;
    const std::size_t leaves = g->tree().leafCount();
    const SmoothStats s = smoothLevelSet(*g, brush);
    EXPECT_EQ(s.leaves, leaves);
    EXPECT_LE(s.leavesVisited, leaves);
    // A small brush probes its own box, fewer places than the grid has leaves.
    brush.radius = 0.05;
    const SmoothStats small = smoothLevelSet(*g, brush);
    EXPECT_LT(small.leavesVisited, g->tree().leafCount());
    EXPECT_GT(small.leaves, 0u);
}

// The limits as a test sets them, put back as they were when it ends.
struct ScopedLimits {
    Limits before = limits();
    explicit ScopedLimits(const Limits& l) { setLimits(l); }
    ~ScopedLimits() { setLimits(before); }
    ScopedLimits(const ScopedLimits&) = delete;
    ScopedLimits& operator=(const ScopedLimits&) = delete;
};

TEST(Smooth, ADabBeyondTheWorkLimitIsRefusedBeforeTheGridChanges) {
    const GridPtr g = bumpySphere();
    const GridPtr before = g->deepCopy();
    SmoothBrush brush;
    brush.center = Eigen::Vector3d(0.0, kR, 0.0);
    brush.radius = kBrush;
    brush.falloff = kFall;
    brush.time = kSmoothTimePerRadius2 * kBrush * kBrush;
    // What the dab takes, as planned: the grid does not change.
    const SmoothStats s = CurvatureSmoother(*g, brush).plan();
    EXPECT_EQ(test::differingBits(*g, *before), 0u);
    ASSERT_GT(s.work, 1000.0);
    {
        const ScopedLimits tight({0.0, s.work / 2});
        try {
            smoothLevelSet(*g, brush);
            ADD_FAILURE() << "a dab of " << s.work << " updates passed a limit of half that";
        } catch (const LimitExceeded& e) {
            EXPECT_NE(std::string(e.what()).find("more than the limit of"), std::string::npos)
                << e.what();
        }
        EXPECT_EQ(test::differingBits(*g, *before), 0u);
        EXPECT_EQ(g->tree().leafCount(), before->tree().leafCount());
    }
    // Within the limit, it runs, and its work was the one planned.
    const ScopedLimits enough({0.0, s.work * 1.01});
    const SmoothStats ran = smoothLevelSet(*g, brush);
    EXPECT_EQ(ran.work, s.work);
    EXPECT_GT(ran.updates, 1000u);
}

namespace {

// A sphere of radius 0.5 with ridges a sin(k x) (wavelength l) across its top, renormalized.
GridPtr ridgedSphere(double h, double l, double amplitude) {
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 0.5, h, 3.0);
    const double k = 2.0 * M_PI / l;
    const float bg = g->background();
    for (auto it = g->beginValueOn(); it; ++it) {
        const Eigen::Vector3d p = toEigen(g->indexToWorld(it.getCoord()));
        const double d = p.norm() - 0.5 - amplitude * std::sin(k * p.x());
        it.setValue(float(std::clamp(d, -double(bg), double(bg))));
    }
    renormalize(*g);
    return g;
}

// The distance from the centre of the surface of a sphere of radius about 0.5, along the ray
// through (x, y, z) on it (y > 0): bisection of the trilinear field.
double surfaceRadius(const Grid& g, double x, double z) {
    const double h = g.voxelSize()[0];
    const Eigen::Vector3d dir = Eigen::Vector3d(x, std::sqrt(0.25 - x * x - z * z), z) / 0.5;
    double in = 0.5 - 4.0 * h, out = 0.5 + 4.0 * h;
    for (int it = 0; it < 40; ++it) {
        const double mid = 0.5 * (in + out);
        const Eigen::Vector3d p = mid * dir;
        (openvdb::tools::BoxSampler::sample(g.tree(), g.worldToIndex(toVdb(p))) < 0.0f ? in : out) =
            mid;
    }
    return 0.5 * (in + out);
}

// The ridges' amplitude on the grid: the surface's radius along rays in the planes z = 0 and
// z = +-l / 2 across |x| < half, projected on sin(k x) (the sphere's own shape, even in x,
// drops out).
double ridgeAmplitude(const Grid& g, double l, double half) {
    const double k = 2.0 * M_PI / l;
    double num = 0.0, den = 0.0;
    const int n = 400;
    for (const double z : {-0.5 * l, 0.0, 0.5 * l})
        for (int j = 0; j <= n; ++j) {
            const double x = -half + 2.0 * half * j / n, s = std::sin(k * x);
            num += surfaceRadius(g, x, z) * s;
            den += s * s;
        }
    return num / den;
}

// The ridges' amplitude before and after a dab whose time fades ridges of wavenumber k by
// exp(-k^2 t) = 1 / e under the ball (weight 1): the measured exponent, -log(after/before).
double ridgeExponent(const Grid& start, double l, double r, SmoothStats* stats = nullptr,
                     const SmoothOptions& options = {}) {
    const double k = 2.0 * M_PI / l;
    // Whole wavelengths within 0.8 r of the centre (weight 1), and a quarter more.
    const double half = std::floor(0.8 * r / l) * l / 2 + 0.25 * l;
    const double before = ridgeAmplitude(start, l, half);
    const GridPtr g = start.deepCopy();
    SmoothBrush brush;
    brush.center = Eigen::Vector3d(0.0, 0.5, 0.0);
    brush.radius = r;
    brush.falloff = 0.5 * r;
    brush.time = 1.0 / (k * k);
    const SmoothStats s = smoothLevelSet(*g, brush, nullptr, options);
    if (stats) *stats = s;
    return -std::log(ridgeAmplitude(*g, l, half) / before);
}

} // namespace

TEST(Smooth, RidgesFadeAsTheLawSays) {
    // Ridges from 4 voxels long to the ball's radius, each dab's time set so that the law
    // gives an exponent of 1: the measured exponent is within a tenth of it, whichever
    // scheme the dab runs (the filter from 8 voxels on; the flow at 4, whose dab is shorter
    // than the filter's narrowest Gaussian).
    const double r = 0.125;
    std::vector<double> sizes{1.0 / 64, 1.0 / 128, 1.0 / 256};
    if (test::coarse()) sizes.pop_back();
    for (const double h : sizes) {
        std::set<double> lengths;
        for (const double l : {4 * h, 8 * h, 16 * h, r})
            if (l <= r) lengths.insert(l); // (the ball's radius may be one of the others)
        for (const double l : lengths) {
            const double amplitude = std::min(0.1 * h * (l / (4 * h)), 0.25 * h);
            const GridPtr start = ridgedSphere(h, l, amplitude);
            SmoothStats s;
            SmoothOptions filter;
            filter.scheme = SmoothScheme::Filter;
            const double exponent = ridgeExponent(*start, l, r, &s, filter);
            std::printf("[ smooth ] 1/%g, ridges %g voxels long: exponent %.3f (%s)\n", 1 / h,
                        l / h, exponent,
                        s.scheme == SmoothScheme::Filter ? "filter" : "explicit flow");
            EXPECT_NEAR(exponent, 1.0, 0.1) << "1/" << 1 / h << ", " << l / h << " voxels";
            EXPECT_EQ(s.scheme == SmoothScheme::Filter, l >= 8 * h) << 1 / h << ", " << l / h;
        }
    }
}

TEST(Smooth, TheFilterMovesTheFormAsTheFlowDoes) {
    // A ridge as long as the ball is wide (the form at the brush's scale, a voxel high) under
    // a dab of strength 2: the surface the filter leaves lies within a tenth of a voxel of
    // the one the explicit flow leaves, across the ball and its falloff.
    const double r = 0.125;
    std::vector<double> sizes{1.0 / 128, 1.0 / 256};
    if (test::coarse()) sizes.pop_back();
    for (const double h : sizes) {
        const GridPtr start = ridgedSphere(h, 2 * r, h);
        SmoothBrush brush;
        brush.center = Eigen::Vector3d(0.0, 0.5, 0.0);
        brush.radius = r;
        brush.falloff = r;
        brush.time = 2.0 * kSmoothTimePerRadius2 * r * r;
        const GridPtr filtered = start->deepCopy(), flowed = start->deepCopy();
        SmoothOptions flow;
        flow.scheme = SmoothScheme::ExplicitFlow;
        SmoothOptions filter;
        filter.scheme = SmoothScheme::Filter;
        ASSERT_EQ(smoothLevelSet(*filtered, brush, nullptr, filter).scheme, SmoothScheme::Filter);
        smoothLevelSet(*flowed, brush, nullptr, flow);
        double differs = 0.0, moved = 0.0;
        for (const double z : {-0.5 * r, 0.0, 0.5 * r})
            for (int j = -40; j <= 40; ++j) {
                const double x = 2.0 * r * j / 40.0;
                const double a = surfaceRadius(*filtered, x, z), b = surfaceRadius(*flowed, x, z);
                differs = std::max(differs, std::abs(a - b));
                moved = std::max(moved, std::abs(b - surfaceRadius(*start, x, z)));
            }
        std::printf("[ smooth ] 1/%g: the flow moves the form by up to %.3f voxel, the filter "
                    "differs from it by %.3f\n",
                    1 / h, moved / h, differs / h);
        EXPECT_GT(moved, 0.1 * h);
        EXPECT_LT(differs, 0.1 * h) << "1/" << 1 / h;
    }
}

TEST(Smooth, TheFilterGivesTheSameGridOnAnyThreadCount) {
    const GridPtr start = bumpySphere();
    SmoothBrush brush;
    brush.center = Eigen::Vector3d(0.0, kR, 0.0);
    brush.radius = kBrush;
    brush.falloff = kFall;
    brush.time = kSmoothTimePerRadius2 * kBrush * kBrush;
    std::vector<GridPtr> grids;
    for (const int threads : {1, 3}) {
        const tbb::global_control c(tbb::global_control::max_allowed_parallelism,
                                    std::size_t(threads));
        grids.push_back(start->deepCopy());
        SmoothOptions filter;
        filter.scheme = SmoothScheme::Filter;
        EXPECT_EQ(smoothLevelSet(*grids.back(), brush, nullptr, filter).scheme,
                  SmoothScheme::Filter);
    }
    EXPECT_EQ(test::differingBits(*grids[0], *grids[1]), 0u);
    EXPECT_GT(test::differingBits(*grids[0], *start), 0u);
}

TEST(Smooth, TheFilterWorkFollowsTheBandUnderTheBrush) {
    // The same dab (strength 10) on the same sphere at r/h = 8, 16 and 32: the filter's work
    // per voxel under the brush stays flat, where the explicit flow's grows as (r/h)^2. The
    // work is counted as planned; the grids do not change.
    const double r = 0.125;
    std::vector<double> filterPerVoxel, flowPerVoxel;
    for (const double h : {1.0 / 64, 1.0 / 128, 1.0 / 256}) {
        const GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 0.5, h, 3.0);
        SmoothBrush brush;
        brush.center = Eigen::Vector3d(0.0, 0.5, 0.0);
        brush.radius = r;
        brush.falloff = r;
        brush.time = 10.0 * kSmoothTimePerRadius2 * r * r;
        const SmoothStats s = CurvatureSmoother(*g, brush).plan();
        ASSERT_GT(s.filterWork, 0.0);
        filterPerVoxel.push_back(s.filterWork / double(s.weighted));
        flowPerVoxel.push_back(s.flowWork / double(s.weighted));
        std::printf("[ smooth ] r/h %g: %zu voxels under the brush; updates a voxel: filter "
                    "%.1f (lattice of %d voxels), explicit flow %.0f\n",
                    r / h, s.weighted, filterPerVoxel.back(), s.latticeSpacing,
                    flowPerVoxel.back());
    }
    EXPECT_LT(filterPerVoxel.back(), 1.25 * filterPerVoxel.front());
    EXPECT_GT(flowPerVoxel.back(), 8.0 * flowPerVoxel.front());
    // Where the flow takes less (the coarsest), it is what the dab runs.
    EXPECT_LT(flowPerVoxel.front(), filterPerVoxel.front());
    // At the finest, a dab of the filter runs and updates no more voxels than it weighs.
    const GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 0.5, 1.0 / 256, 3.0);
    SmoothBrush brush;
    brush.center = Eigen::Vector3d(0.0, 0.5, 0.0);
    brush.radius = r;
    brush.falloff = r;
    brush.time = 10.0 * kSmoothTimePerRadius2 * r * r;
    const SmoothStats s = smoothLevelSet(*g, brush);
    EXPECT_EQ(s.scheme, SmoothScheme::Filter);
    EXPECT_LE(s.updates, s.weighted);
    EXPECT_GT(s.updates, s.weighted / 2);
}

TEST(Smooth, ACancelledDabLeavesTheDocumentAsItWas) {
    // An interrupter that stops at its n-th poll: whichever phase of the dab it stops, the
    // recording puts the grid back bit for bit.
    class StopAt : public Interrupter {
      public:
        explicit StopAt(int n) : left_(n) {}
        bool wasInterrupted(int = -1) override { return --left_ < 0; }

      private:
        std::atomic<int> left_;
    };
    const GridPtr start = bumpySphere();
    int stopped = 0;
    for (int n = 0; n < 12; ++n) {
        Sculptor sculptor(start->deepCopy());
        SmoothOptions filter;
        filter.scheme = SmoothScheme::Filter;
        sculptor.setSmoothOptions(filter);
        StopAt stop(n);
        sculptor.setInterrupter(&stop);
        sculptor.startRecording();
        bool cancelled = false;
        try {
            sculptor.applyStroke(dabsAt({{0.0, kR, 0.0}}));
        } catch (const Cancelled&) {
            cancelled = true;
            sculptor.restoreRecording();
        }
        stopped += cancelled;
        EXPECT_EQ(test::differingBits(sculptor.grid(), *start) == 0, cancelled) << n;
    }
    // Stopped before, within and after the filter, and within the renormalization.
    EXPECT_GE(stopped, 4);
}
