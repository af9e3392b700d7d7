// SPDX-License-Identifier: Apache-2.0
// Deformations given by a velocity field (deform/flow.h): the fields, the flow steps' inverse
// and forward maps, how many segments a flow takes, and flow strokes in scripts.
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "deform/flow.h"
#include "io/stroke_script.h"
#include "random.h"

using namespace sweepers;
using sweepers::test::Rng;

namespace {

FieldSpec rotation(double degreesPerSecond) {
    FieldSpec f;
    f.kind = FieldSpec::Kind::Rotation;
    f.center = {0.1, -0.2, 0.3};
    f.axis = {1, 2, 2};
    f.degreesPerSecond = degreesPerSecond;
    f.radius = 1.0;
    f.falloff = 0.5;
    return f;
}

// The Enright test's sphere: radius 0.15 about (0.35, 0.35, 0.35).
std::vector<Eigen::Vector3d> enrightSphere(int n) {
    std::vector<Eigen::Vector3d> points;
    Rng rng(5);
    for (int i = 0; i < n; ++i)
        points.push_back(Eigen::Vector3d::Constant(0.35) + 0.15 * rng.unit().normalized());
    return points;
}

std::string refusal(const std::string& stroke) {
    const std::string text = R"({"sweepers": 1, "grid": {"voxel_size": 0.02},
        "start": {"sphere": {"center": [0.35, 0.35, 0.35], "radius": 0.15}},
        "strokes": [)" + stroke +
                             "]}";
    try {
        loadStrokeScript(text, "flow.json");
    } catch (const ScriptError& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST(VelocityField, FieldsAreDivergenceFreeAndVanishOutside) {
    Rng rng(3);
    for (const FieldSpec::Kind kind : {FieldSpec::Kind::Enright, FieldSpec::Kind::Vortex}) {
        FieldSpec spec;
        spec.kind = kind;
        const auto v = makeField(spec);
        for (int i = 0; i < 200; ++i) {
            const Eigen::Vector3d p = rng.vec(0, 1);
            const double t = rng.uniform(0, 3);
            const Eigen::Matrix3d J = v->jacobian(p, t);
            EXPECT_NEAR(J.trace(), 0.0, 1e-7) << fieldName(kind) << " at " << p.transpose();
            // The analytic Lipschitz bound holds (the operator norm is below Frobenius').
            EXPECT_LE(J.norm(), v->lipschitz()) << fieldName(kind);
        }
        EXPECT_EQ(v->at({1.2, 0.5, 0.5}, 0.3), Eigen::Vector3d::Zero());
        // Zero on the box's faces: nothing leaves it.
        EXPECT_LT(v->at({0.0, 0.3, 0.7}, 0.1).norm(), 1e-15);
        EXPECT_LT(v->at({0.4, 1.0, 0.7}, 0.1).norm(), 1e-15);
    }
    // Enright's flow turns back at half its period: v(t) = -v(T - t).
    FieldSpec enright;
    const auto v = makeField(enright);
    const Eigen::Vector3d p(0.3, 0.6, 0.45);
    EXPECT_TRUE(v->at(p, 0.4).isApprox(-v->at(p, 2.6), 1e-12));
    EXPECT_THROW(makeField(rotation(std::nan(""))), std::invalid_argument);
}

TEST(FlowStep, ForwardUndoesTheInverseToAMillionthOfAVoxel) {
    // Voxels of 1/200 of the box (the Enright benchmark's finest): every forward image of an
    // inverse image comes back within 1e-6 of such a voxel.
    const double h = 1.0 / 200;
    FieldSpec enright;
    const FlowStep step(makeField(enright), 0.2, 0.9);
    EXPECT_GE(step.steps(), 2 * 0.7 * makeField(enright)->lipschitz());
    Rng rng(11);
    double worst = 0.0;
    for (int i = 0; i < 100; ++i) {
        const Eigen::Vector3d p = rng.vec(0.05, 0.95);
        const Eigen::Vector3d q = step.inverseMap(p);
        EXPECT_GT((q - p).norm(), 1e-4); // it moved
        const ForwardResult f = step.forwardMap(q);
        EXPECT_TRUE(f.converged);
        worst = std::max(worst, (f.p - p).norm());
    }
    EXPECT_LT(worst, 1e-6 * h);
    // Outside the box nothing moves.
    EXPECT_EQ(step.inverseMap({1.5, 0.2, 0.2}), Eigen::Vector3d(1.5, 0.2, 0.2));
}

TEST(FlowStep, EnrightsFlowComesBackAndARotationFieldRotates) {
    // Over a whole period the traced characteristic comes back to where it started.
    FieldSpec enright;
    const FlowStep period(makeField(enright), 0.0, 3.0), half(makeField(enright), 0.0, 1.5);
    Rng rng(17);
    double back = 0.0, away = 0.0;
    for (const Eigen::Vector3d& p : enrightSphere(50)) {
        back = std::max(back, (period.inverseMap(p) - p).norm());
        away = std::max(away, (half.inverseMap(p) - p).norm());
    }
    EXPECT_LT(back, 5e-5); // RK4's error: under 1e-5, 0.2% of a voxel at 1/200
    EXPECT_GT(away, 0.1);  // at half the period the sphere is spread far
    // Within its radius a rotation field turns space rigidly: a second of 60 degrees a second
    // is the rotation by 60 degrees, to RK4's error (up to 3.4e-7 here: 7e-5 of a voxel at
    // 1/200).
    const FieldSpec spec = rotation(60.0);
    const FlowStep turn(makeField(spec), 0.0, 1.0);
    const Eigen::AngleAxisd R(60.0 * M_PI / 180.0, spec.axis.normalized());
    for (int i = 0; i < 50; ++i) {
        const Eigen::Vector3d p = spec.center + 0.9 * rng.unit().normalized() * rng.uniform(0, 1);
        EXPECT_LT((turn.inverseMap(p) - (spec.center + R.inverse() * (p - spec.center))).norm(),
                  1e-6);
    }
}

TEST(FlowStep, SegmentsFollowTheStretchOfTheFlow) {
    FieldSpec enright;
    const auto v = makeField(enright);
    const auto sphere = enrightSphere(200);
    // The whole period comes back (no stretch: one segment); half of it spreads the sphere
    // into a sheet, which one resample cannot follow.
    EXPECT_EQ(flowSegments(*v, 0.0, 3.0, sphere), 1);
    const int half = flowSegments(*v, 0.0, 1.5, sphere);
    EXPECT_GT(half, 1);
    EXPECT_LE(half, 64);
    // A rigid rotation stretches nothing.
    EXPECT_EQ(flowSegments(*makeField(rotation(90.0)), 0.0, 2.0, sphere), 1);
    const auto parts = planFlow(v, 0.0, 1.5, 4);
    ASSERT_EQ(parts.size(), 4u);
    EXPECT_DOUBLE_EQ(dynamic_cast<const FlowStep&>(*parts[2]).from(), 0.75);
    EXPECT_THROW(planFlow(v, 0.0, 1.5, 0), std::invalid_argument);
    EXPECT_THROW(FlowStep(v, 1.0, 1.0), std::invalid_argument);
}

TEST(FlowStroke, RoundTripsAndBadFlowsAreRefused) {
    const std::string text = R"({"sweepers": 1, "grid": {"voxel_size": 0.02},
        "start": {"sphere": {"center": [0.35, 0.35, 0.35], "radius": 0.15}},
        "strokes": [
          {"type": "flow", "field": "enright", "from": 0, "to": 3},
          {"type": "flow", "field": {"rotation": {"center": [0, 0, 0], "axis": [0, 0, 1],
            "degrees_per_second": 45, "radius": 1, "falloff": 0.5}}, "from": 1, "to": 2,
            "segments": 3}]})";
    const StrokeScript s = loadStrokeScript(text, "flow.json");
    ASSERT_EQ(s.strokes.size(), 2u);
    const auto& a = std::get<FlowStroke>(s.strokes[0]);
    EXPECT_EQ(a.field.kind, FieldSpec::Kind::Enright);
    EXPECT_EQ(a.segments, 0);
    const auto& b = std::get<FlowStroke>(s.strokes[1]);
    EXPECT_EQ(b.field.kind, FieldSpec::Kind::Rotation);
    EXPECT_EQ(b.segments, 3);
    EXPECT_DOUBLE_EQ(b.field.degreesPerSecond, 45.0);
    EXPECT_EQ(formatStrokeScript(loadStrokeScript(formatStrokeScript(s), "again.json")),
              formatStrokeScript(s));

    EXPECT_EQ(refusal(R"({"type": "flow", "field": "enright", "from": 2, "to": 1})"),
              "flow.json: /strokes/0/to: a flow runs forward in time: to (1) must come after "
              "from (2)");
    EXPECT_EQ(refusal(R"({"type": "flow", "field": "enright", "from": 0, "to": 1,
                          "segments": 0})"),
              "flow.json: /strokes/0/segments: expected a whole number from 1 to 4096, got 0");
    EXPECT_EQ(refusal(R"({"type": "flow", "field": "gale", "from": 0, "to": 1})"),
              "flow.json: /strokes/0/field: expected \"enright\", \"vortex\", "
              "{\"rotation\": {...}} or {\"vdb\": file}, got \"gale\"");
    EXPECT_EQ(refusal(R"({"type": "flow", "field": "enright", "from": 0, "to": 1e5})"),
              "flow.json: /strokes/0: the flow would take 3.01593e+06 sub-steps (more than "
              "100000): shorten its time or slow its field");
    EXPECT_EQ(refusal(R"({"type": "flow", "field": "enright", "from": 0, "to": 1e9})"),
              "flow.json: /strokes/0/to: 1000000000.0 is beyond the largest number a script "
              "takes, 1e5");
    EXPECT_EQ(refusal(R"({"type": "flow", "field": "enright", "from": "nan", "to": 1})"),
              "flow.json: /strokes/0/from: expected a number, got \"nan\"");
}
