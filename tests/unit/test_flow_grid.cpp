// Flows on real grids (deform/flow.h through the one stroke path): a rigid rotation given as
// a velocity field against the same rotation given as a sweep, and Enright's deformation
// test, which stretches a sphere into a sheet and brings it back.
#include <cmath>

#include <gtest/gtest.h>

#include "levelset/create.h"
#include "levelset/measure.h"
#include "sculpt/sculptor.h"

using namespace sweepers;

namespace {

// The RMS difference of two grids in voxels, over the voxels next to the surface of `a`.
double interfaceRms(const Grid& a, const Grid& b) {
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
    const double rms = interfaceRms(swept.grid(), flowed.grid());
    std::printf("rotation as a field against the sweep: %.4f voxel RMS\n", rms);
    EXPECT_LT(rms, 0.05);
    // It did turn: the ball's centre went from +x to +y.
    const Box b = measureLevelSet(flowed.grid()).bounds;
    EXPECT_NEAR(0.5 * (b.min.x() + b.max.x()), 0.0, 2 * h);
    EXPECT_NEAR(0.5 * (b.min.y() + b.max.y()), 0.45, 2 * h);
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
    const double v0 = measureLevelSet(*start).volume, v1 = measureLevelSet(s.grid()).volume;
    const double rms = interfaceRms(*start, s.grid());
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
                100.0 * (measureLevelSet(half.grid()).volume - v0) / v0);
    EXPECT_GT(segments, 1u);
    EXPECT_GT(is.maxCoeff(), 1.5 * was.maxCoeff());
}
