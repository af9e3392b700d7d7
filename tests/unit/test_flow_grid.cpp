// SPDX-License-Identifier: Apache-2.0
// Flows on real grids (deform/flow.h through the one stroke path): a rigid rotation given as
// a velocity field against the same rotation given as a sweep, and sampled in a VDB file;
// Enright's deformation test, which stretches a sphere into a sheet and brings it back; and
// the swept fluid's grab against a sweep's on the same move.
#include <cmath>

#include <gtest/gtest.h>

#include <filesystem>

#include "coarse.h"
#include "io/fluid_cache.h"
#include "io/stroke_script.h"
#include "io/velocity_file.h"
#include "levelset/create.h"
#include "levelset/measure.h"
#include "sculpt/sculptor.h"

using namespace sweepers;

namespace {

// The RMS difference of two grids in voxels, over the voxels next to the surface of `a`.
double rmsNearTheSurfaceOf(const Grid& a, const Grid& b) {
    const double h = a.voxelSize()[0];
    const auto bacc = b.getConstAccessor();
    double sum = 0.0;
    std::size_t n = 0;
    for (auto it = a.cbeginValueOn(); it; ++it) {
        if (std::abs(*it) >= h) continue;
        const double d = (double(*it) - double(bacc.getValue(it.getCoord()))) / h;
        sum += d * d;
        ++n;
    }
    EXPECT_GT(n, 100u);
    return std::sqrt(sum / double(n));
}

} // namespace

TEST(Flow, ARotationFieldTurnsTheShapeAsARotatingSweepDoes) {
    // A ball off the axis, turned a quarter turn about z: by a ball tool of radius 1 that
    // turns in place (rigid within its radius), and by a rotation field as fast over a
    // second, rigid within the same radius.
    const double h = 1.0 / 32;
    auto start = [&] { return makeSphere({0.45, 0.0, 0.1}, 0.35, h, 3.0); };
    SweepStroke sweep;
    ToolSpec tool;
    tool.size = Eigen::Vector3d::Constant(1.0);
    tool.falloff = 0.5;
    Placement turned;
    turned.angleDegrees = 90.0;
    tool.path = {Placement(), turned};
    sweep.tools = {tool};
    FlowStroke flow;
    flow.field.kind = FieldSpec::Kind::Rotation;
    flow.field.degreesPerSecond = 90.0;
    flow.field.radius = 1.0;
    flow.field.falloff = 0.5;
    flow.from = 0.0;
    flow.to = 1.0;
    Sculptor swept(start()), flowed(start());
    swept.applyStroke(sweep);
    flowed.applyStroke(flow);
    const double rms = rmsNearTheSurfaceOf(swept.grid(), flowed.grid());
    std::printf("rotation as a field against the sweep: %.4f voxel RMS\n", rms);
    EXPECT_LT(rms, 0.05);
    // It did turn: the ball's centre went from +x to +y.
    const Box b = measureLevelSet(flowed.grid()).bounds;
    EXPECT_NEAR(0.5 * (b.min.x() + b.max.x()), 0.0, 2 * h);
    EXPECT_NEAR(0.5 * (b.min.y() + b.max.y()), 0.45, 2 * h);
}

TEST(Flow, ARotationSampledInAVdbFileTurnsTheShapeAsTheFieldDoes) {
    // The rigid rotation of the test above, 90 degrees a second about z, sampled every 0.2 in
    // [-1.2, 1.2]^3 into a velocity VDB, cell-centred and staggered: the B-spline reproduces a
    // linear field two samples in from the lattice's edge (here [-1, 1]^3), so the flow read from
    // the file turns the ball as the analytic field does (at 1/32; 1/16 in the coarse variant).
    const double h = test::coarse() ? 1.0 / 16 : 1.0 / 32, w = M_PI / 2;
    auto start = [&] { return makeSphere({0.45, 0.0, 0.1}, 0.35, h, 3.0); };
    FlowStroke exact;
    exact.field.kind = FieldSpec::Kind::Rotation;
    exact.field.degreesPerSecond = 90.0;
    exact.field.radius = 2.0;
    exact.to = 1.0;
    Sculptor analytic(start());
    analytic.applyStroke(exact);
    const std::string dir = ::testing::TempDir();
    for (const bool staggered : {false, true}) {
        VelocitySamples s;
        s.dims = {13, 13, 13};
        s.origin = Eigen::Vector3d::Constant(-1.2);
        s.spacing = 0.2;
        s.staggered = staggered;
        for (int k = 0; k < 13; ++k)
            for (int j = 0; j < 13; ++j)
                for (int i = 0; i < 13; ++i) {
                    const Eigen::Vector3d x = s.origin + s.spacing * Eigen::Vector3d(i, j, k);
                    // (-w y, w x, 0): the same on the faces, since the x component does
                    // not vary along x, nor y along y.
                    s.values.emplace_back(float(-w * x.y()), float(w * x.x()), 0.0f);
                }
        const std::string file = dir + (staggered ? "/turn_staggered.vdb" : "/turn.vdb");
        writeVelocity(s, file, "v");
        const StrokeScript script = loadStrokeScript(
            R"({"sweepers": 1, "start": {"sphere": {"center": [0, 0, 0], "radius": 1}},
                "strokes": [{"type": "flow", "field": {"vdb": ")" +
                file + R"(", "grid": "v"}, "from": 0, "to": 1}]})",
            "sampled.json");
        Sculptor sampled(start());
        sampled.applyStroke(script.strokes.at(0));
        const double rms = rmsNearTheSurfaceOf(analytic.grid(), sampled.grid());
        std::printf("rotation sampled in a VDB (%s) against the field: %.4f voxel RMS\n",
                    staggered ? "staggered" : "cell-centred", rms);
        EXPECT_LT(rms, 0.05);
    }
}

TEST(SweptFluid, AFluidGrabKeepsTheVolumeASweepGainsOnTheSameMove) {
    // A ball of radius 0.3 from just inside a unit sphere (a nose pulled, Figure 4.14), at
    // 1/64 (1/32 in the coarse variant), as the swept fluid and as a sweep of the same ball
    // with the same falloff.
    const double h = test::coarse() ? 1.0 / 32 : 1.0 / 64;
    const Eigen::Vector3d from(0, 0.85, 0), to(0, 1.15, 0);
    FluidStroke fluid;
    fluid.radius = 0.3;
    fluid.path = {from, to};
    fluid.fluid = sweptFluid();
    SweepStroke sweep;
    ToolSpec tool;
    tool.size = Eigen::Vector3d::Constant(0.3);
    tool.falloff = 0.3;
    Placement a, b;
    a.t = from;
    b.t = to;
    tool.path = {a, b};
    sweep.tools = {tool};
    const GridPtr start = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3.0);
    const LevelSetMeasures before = measureLevelSet(*start);
    Sculptor fluidly(start->deepCopy()), swept(start->deepCopy());
    fluidly.applyStroke(fluid);
    swept.applyStroke(sweep);
    const LevelSetMeasures f = measureLevelSet(fluidly.grid()), s = measureLevelSet(swept.grid());
    const double df = (f.volume - before.volume) / before.volume,
                 ds = (s.volume - before.volume) / before.volume;
    std::printf("nose pulled at 1/%.0f: fluid %+.4f%%, sweep %+.4f%%; the nose reaches %.3f and "
                "%.3f\n",
                1 / h, 100 * df, 100 * ds, f.bounds.max.y(), s.bounds.max.y());
    EXPECT_LT(std::abs(df), 0.01);
    EXPECT_LT(4.0 * std::abs(df), std::abs(ds));
    // It is a grab: the surface followed the ball out.
    EXPECT_GT(f.bounds.max.y(), before.bounds.max.y() + 0.15);
}

TEST(Flow, EnrightsSphereComesBackAtTheEndOfThePeriod) {
    // The fast version of the benchmark: 1/64 of the unit box, to t = 3 in as few segments
    // as the stretch allows.
    const double h = 1.0 / 64;
    const GridPtr start = makeSphere(Eigen::Vector3d::Constant(0.35), 0.15, h, 3.0);
    Sculptor s(start->deepCopy());
    FlowStroke flow;
    flow.field.kind = FieldSpec::Kind::Enright;
    flow.from = 0.0;
    flow.to = 3.0;
    std::size_t segments = 0;
    s.applyStroke(flow, [&](const SegmentReport&) { ++segments; });
    const double v0 = levelSetVolume(*start), v1 = levelSetVolume(s.grid());
    const double rms = rmsNearTheSurfaceOf(*start, s.grid());
    std::printf("Enright at 1/64 to t = 3: %zu segment(s), volume %+.4f%%, %.4f voxel RMS\n",
                segments, 100.0 * (v1 - v0) / v0, rms);
    EXPECT_LT(std::abs(v1 - v0), 0.01 * v0);
    EXPECT_LT(rms, 1.0);
    // Halfway the sphere is a sheet spread far beyond where it began, in several segments.
    Sculptor half(start->deepCopy());
    flow.to = 1.5;
    segments = 0;
    half.applyStroke(flow, [&](const SegmentReport&) { ++segments; });
    const Eigen::Vector3d was = measureLevelSet(*start).bounds.extent(),
                          is = measureLevelSet(half.grid()).bounds.extent();
    std::printf("at t = 1.5: %zu segments, extent %.3f %.3f %.3f (from %.3f), volume %+.2f%%\n",
                segments, is.x(), is.y(), is.z(), was.x(),
                100.0 * (levelSetVolume(half.grid()) - v0) / v0);
    EXPECT_GT(segments, 1u);
    EXPECT_GT(is.maxCoeff(), 1.5 * was.maxCoeff());
}
