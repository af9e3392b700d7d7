// The smooth brush (levelset/smooth.h) on a bumpy sphere: the noise under the brush goes,
// nothing beyond its reach moves, the stroke written to a script replays to the same grid,
// and a study says no exact shape stands behind it.
#include <gtest/gtest.h>

#include <cmath>

#include <openvdb/math/Stencils.h>
#include <openvdb/tools/LevelSetRebuild.h>

#include "core/limits.h"
#include "grids.h"
#include "io/stroke_script.h"
#include "io/study_files.h"
#include "levelset/band.h"
#include "levelset/fast_marching.h"
#include "levelset/measure.h"
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
        dabsAt({{0.0, kR, 0.0}, {0.1, kR - 0.01, 0.0}, {0.2, kR - 0.04, 0.05}}, 0.7);
    Sculptor a(start->deepCopy());
    a.applyStroke(stroke);

    StrokeScript script;
    script.grid.voxelSize = kH;
    script.strokes = {stroke};
    const StrokeScript back = parseStrokeScript(formatStrokeScript(script), "smooth.json", ".");
    ASSERT_EQ(back.strokes.size(), 1u);
    const auto* read = std::get_if<SmoothStroke>(&back.strokes[0]);
    ASSERT_NE(read, nullptr);
    EXPECT_EQ(read->tool.path.size(), 3u);
    EXPECT_EQ(read->strength, 0.7);
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
    // What the dab takes: its steps times the voxels under the ball.
    const SmoothStats s = smoothLevelSet(*g->deepCopy(), brush);
    ASSERT_GT(s.updates, 1000u);
    {
        const ScopedLimits tight({0.0, double(s.updates) / 2});
        try {
            smoothLevelSet(*g, brush);
            ADD_FAILURE() << "a dab of " << s.updates << " updates passed a limit of half that";
        } catch (const LimitExceeded& e) {
            EXPECT_NE(std::string(e.what()).find("more than the limit of"), std::string::npos)
                << e.what();
        }
        EXPECT_EQ(test::differingBits(*g, *before), 0u);
        EXPECT_EQ(g->tree().leafCount(), before->tree().leafCount());
    }
    // Within the limit (the estimate counts the voxels the flow updates), it runs.
    const ScopedLimits enough({0.0, double(s.updates) * 1.01});
    EXPECT_EQ(smoothLevelSet(*g, brush).updates, s.updates);
}
