// SPDX-License-Identifier: Apache-2.0
#include <cmath>

#include <gtest/gtest.h>

#include "core/twist.h"
#include "random.h"

using namespace sweepers;
using sweepers::test::apply;
using sweepers::test::maxDiff;
using sweepers::test::Rng;
using sweepers::test::seriesExp;

namespace {

std::vector<Twist> sampleTwists() {
    Rng rng(7);
    std::vector<Twist> out;
    // General twists over a range of angles, including ones near the series switch-over.
    for (double angle : {1e-12, 1e-7, 1e-3, 0.05, 0.099, 0.1, 0.101, 0.5, 1.0, 2.0, 3.0, 3.1415}) {
        for (int i = 0; i < 10; ++i)
            out.push_back({rng.unit() * angle, rng.vec(-2, 2)});
    }
    out.push_back(Twist::translation({0.3, -1.0, 2.0}));
    out.push_back(Twist::rotation({0, 0, 1}, 1.2, {1, 2, 3}));
    out.push_back(Twist::screw({1, 1, 0}, 0.7, {0, -1, 0}, 0.4));
    return out;
}

} // namespace

TEST(Twist, ClosedFormExpEqualsSeries) {
    for (const Twist& t : sampleTwists())
        EXPECT_LT(maxDiff(t.exp(), seriesExp(t.logMatrix())), 1e-12)
            << t.omega.transpose() << " | " << t.m.transpose();
}

TEST(Twist, PointAndVectorFormulasMatchTheMatrix) {
    Rng rng(11);
    for (const Twist& t : sampleTwists()) {
        const Eigen::Matrix4d E = seriesExp(t.logMatrix());
        for (int i = 0; i < 5; ++i) {
            const Eigen::Vector3d p = rng.vec(-3, 3);
            EXPECT_LT((t.applyToPoint(p) - apply(E, p)).norm(), 1e-12);
            EXPECT_LT((t.applyToVector(p) - E.topLeftCorner<3, 3>() * p).norm(), 1e-12);
        }
    }
}

TEST(Twist, SpecialCasesAreTaken) {
    // A rotation about c (7.20) fixes c; a translation moves every point by m (7.19).
    const Eigen::Vector3d c(1, -2, 0.5);
    const Twist r = Twist::rotation({0, 1, 1}, 0.9, c);
    EXPECT_NEAR(r.omega.dot(r.m), 0.0, 1e-15);
    EXPECT_LT((r.applyToPoint(c) - c).norm(), 1e-14);
    const Twist t = Twist::translation({1, 2, 3});
    EXPECT_TRUE(t.isTranslation());
    EXPECT_EQ(t.applyToPoint({1, 1, 1}), Eigen::Vector3d(2, 3, 4));
    EXPECT_EQ(t.applyToVector({1, 1, 1}), Eigen::Vector3d(1, 1, 1));
    // A screw slides along its axis by `slide` per application.
    const Twist s = Twist::screw({0, 0, 1}, 2 * M_PI, {0, 0, 0}, 0.25);
    EXPECT_LT((s.applyToPoint({1, 0, 0}) - Eigen::Vector3d(1, 0, 0.25)).norm(), 1e-12);
}

TEST(Twist, WeightThenMinusWeightIsIdentity) {
    Rng rng(3);
    for (const Twist& t : sampleTwists()) {
        for (double w : {0.3, 1.0, -0.7}) {
            const Eigen::Vector3d p = rng.vec(-2, 2);
            const Eigen::Vector3d q = (t * (-w)).applyToPoint((t * w).applyToPoint(p));
            EXPECT_LT((q - p).norm(), 1e-12);
        }
    }
}

TEST(Twist, LogOfExpIsTheTwistBelowPi) {
    for (const Twist& t : sampleTwists()) {
        if (t.omega.norm() >= M_PI - 1e-3) continue; // at pi the sign of the axis is free
        const Twist back = logRigid(t.exp());
        EXPECT_LT((back.omega - t.omega).norm(), 1e-9);
        EXPECT_LT((back.m - t.m).norm(), 1e-9);
    }
}

TEST(Twist, ExpOfLogReproducesRandomRigidMotions) {
    Rng rng(5);
    for (int i = 0; i < 2000; ++i) {
        const Eigen::Matrix4d M = rng.rigid(M_PI, 3.0);
        EXPECT_LT(maxDiff(logRigid(M).exp(), M), 1e-9);
    }
}

TEST(Twist, LogIsRobustNearZeroAndPi) {
    Rng rng(9);
    for (double angle : {0.0, 1e-15, 1e-9, 1e-6, M_PI - 1e-3, M_PI - 1e-7, M_PI - 1e-12, M_PI}) {
        for (int i = 0; i < 50; ++i) {
            Eigen::Affine3d A = Eigen::Affine3d::Identity();
            A.translate(rng.vec(-2, 2));
            A.rotate(Eigen::AngleAxisd(angle, rng.unit()));
            const Twist t = logRigid(A.matrix());
            EXPECT_NEAR(t.omega.norm(), angle, 1e-7) << angle;
            EXPECT_LT(maxDiff(t.exp(), A.matrix()), 1e-9) << angle;
        }
    }
}
