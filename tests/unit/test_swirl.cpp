// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <gtest/gtest.h>

#include "deform/inflate.h"
#include "deform/swirl.h"
#include "random.h"

using namespace sweepers;
using sweepers::test::Rng;

namespace {

Eigen::Matrix3d jacobian(const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& f,
                         const Eigen::Vector3d& p, double h) {
    Eigen::Matrix3d J;
    for (int a = 0; a < 3; ++a) {
        Eigen::Vector3d e = Eigen::Vector3d::Zero();
        e[a] = h;
        J.col(a) = (f(p + e) - f(p - e)) / (2 * h);
    }
    return J;
}

} // namespace

TEST(Swirl, BasicSwirlKeepsVolume) {
    // A ring of one swirl moved in one sub-step is one basic swirl: a rotation about an
    // axis through c by an angle that depends only on |p - c| (appendix B.1).
    Rng rng(61);
    for (int c = 0; c < 5; ++c) {
        SwirlSpec spec;
        spec.at = rng.vec(-1, 1);
        spec.radius = rng.uniform(0.2, 0.5);
        spec.move = rng.unit() * spec.radius * 0.2; // s = 1
        spec.swirls = 1;
        const SwirlSegment swirl(spec);
        ASSERT_EQ(swirl.steps(), 1);
        const Box& box = swirl.affectedBox();
        double worst = 0.0;
        for (int i = 0; i < 2000; ++i) {
            const Eigen::Vector3d p = rng.inBox(box.min, box.max);
            const double det =
                jacobian([&](const Eigen::Vector3d& x) { return swirl.inverseStep(0, x); }, p, 1e-5)
                    .determinant();
            worst = std::max(worst, std::abs(det - 1.0));
        }
        EXPECT_LT(worst, 1e-6) << c;
    }
}

TEST(Swirl, RingsMoveTheirCentreByTheMove) {
    // 4.2 / B.12 for the discrete ring, 4.13 for the convolution ring.
    Rng rng(62);
    for (SwirlRing ring : {SwirlRing::Discrete, SwirlRing::Convolution}) {
        for (int c = 0; c < 10; ++c) {
            SwirlSpec spec;
            spec.ring = ring;
            spec.at = rng.vec(-1, 1);
            spec.radius = rng.uniform(0.15, 0.4);
            spec.move = rng.unit() * rng.uniform(0.05, 1.0);
            const SwirlSegment swirl(spec);
            const ForwardResult f = swirl.forwardMap(spec.at);
            ASSERT_TRUE(f.converged);
            const double err = (f.p - (spec.at + spec.move)).norm();
            EXPECT_LT(err, 0.01 * spec.move.norm()) << int(ring) << " " << c;
            // ... and the inverse brings the target back.
            EXPECT_LT((swirl.inverseMap(spec.at + spec.move) - spec.at).norm(),
                      0.01 * spec.move.norm());
        }
    }
}

TEST(Swirl, StepsAngleAndReachFollowTheThesis) {
    SwirlSpec spec;
    spec.radius = 0.3;
    spec.move = {0, 0, 0.5};
    const SwirlSegment d(spec);
    EXPECT_EQ(d.steps(), 7);                                     // ceil(4 * 0.5 / 0.3), 4.3
    EXPECT_NEAR(d.swirlAngle(), 2 * 0.5 / (8 * 0.3 * 7), 1e-15); // 4.2 per sub-step
    spec.ring = SwirlRing::Convolution;
    const SwirlSegment c(spec);
    const double l = 1.2 * 0.3, r = 0.3;
    EXPECT_NEAR(c.swirlAngle(), 0.5 * std::pow(l * l + r * r, 2) / (2 * std::pow(l, 4) * r) / 7,
                1e-12);
    EXPECT_NEAR(c.boundingRadius(), r * std::sqrt(std::sqrt(2 * M_PI * r / 1e-2) - 1),
                1e-12); // 4.15
    // Nothing moves outside the affected box.
    const Eigen::Vector3d far(3, 3, 3);
    EXPECT_EQ(d.inverseMap(far), far);
    EXPECT_EQ(c.forwardMap(far).p, far);
}

TEST(Swirl, TheConvolutionRingPoursNoClayThroughItsBoundingSphere) {
    // The convolution ring's field is cut off at the bounding sphere 4.15. What a small move
    // carries through a closed surface is the flux of the displacement through it; for a
    // volume-keeping field it is zero, whatever the surface, also one that crosses that
    // sphere. Cut off by itself, the field would carry about a tenth of what it moves
    // across such a surface, and a swirled shape gain a few tenths of a percent.
    Rng rng(64);
    for (int c = 0; c < 4; ++c) {
        SwirlSpec spec;
        spec.ring = SwirlRing::Convolution;
        spec.at = rng.vec(-1, 1);
        spec.radius = rng.uniform(0.2, 0.4);
        spec.move = rng.unit() * spec.radius * 0.01; // one small sub-step: first order
        const SwirlSegment swirl(spec);
        ASSERT_EQ(swirl.steps(), 1);
        const double reach = swirl.boundingRadius();
        // A sphere whose surface crosses the bounding sphere, centred off the ring's axis.
        const Eigen::Vector3d centre = swirl.ringCentre(1) + 0.8 * reach * rng.unit();
        const double radius = 0.5 * reach;
        const int rows = 600, columns = 1200;
        double flux = 0.0, moved = 0.0;
        for (int i = 0; i < rows; ++i) {
            const double theta = M_PI * (i + 0.5) / rows;
            for (int j = 0; j < columns; ++j) {
                const double phi = 2.0 * M_PI * (j + 0.5) / columns;
                const Eigen::Vector3d n(std::sin(theta) * std::cos(phi),
                                        std::sin(theta) * std::sin(phi), std::cos(theta));
                const Eigen::Vector3d p = centre + radius * n;
                const double area =
                    radius * radius * std::sin(theta) * (M_PI / rows) * (2.0 * M_PI / columns);
                const double along = (p - swirl.inverseStep(0, p)).dot(n) * area;
                flux += along;
                moved += std::abs(along);
            }
        }
        std::printf("convolution ring %d: flux %.3g of %.3g moved across the sphere\n", c, flux,
                    moved);
        ASSERT_GT(moved, 0.0);
        EXPECT_LT(std::abs(flux), 2e-3 * moved) << c;
    }
}

TEST(Swirl, RefusesDegenerateRings) {
    SwirlSpec spec;
    EXPECT_THROW(SwirlSegment{spec}, std::invalid_argument); // no move
    spec.move = {0, 0, 1};
    spec.radius = 0.0;
    EXPECT_THROW(SwirlSegment{spec}, std::invalid_argument);
    spec.radius = 1e-6;
    EXPECT_THROW(SwirlSegment{spec}, std::domain_error); // millions of sub-steps
}

TEST(Inflation, ExactInverseAndVolumeOutsideTheBall) {
    Rng rng(63);
    const Eigen::Vector3d c(0.2, -0.1, 0.3);
    const double rho = 0.25;
    const Inflation inflate(c, rho,
                            Box(Eigen::Vector3d::Constant(-3), Eigen::Vector3d::Constant(3)));
    for (int i = 0; i < 2000; ++i) {
        const Eigen::Vector3d p = rng.vec(-2, 2);
        const Eigen::Vector3d q = inflate.forwardMap(p).p;
        EXPECT_LT((inflate.inverseMap(q) - p).norm(), 1e-12); // 2.31 undoes 2.30 exactly
        EXPECT_GE((q - c).norm(), rho - 1e-12);               // nothing lands in the ball
        const double det =
            jacobian([&](const Eigen::Vector3d& x) { return inflate.forwardMap(x).p; }, p, 1e-6)
                .determinant();
        if ((p - c).norm() > 0.05) {
            EXPECT_NEAR(det, 1.0, 1e-5); // volume kept outside c
        }
    }
    // Inside the ball the inverse has no pre-image but the centre.
    EXPECT_EQ(inflate.inverseMap(c + Eigen::Vector3d(0.1, 0, 0)), c);
}

TEST(Inflation, StarShapedSwirlCarriesTheBall) {
    SwirlSpec spec;
    spec.at = {0, 0, 0.5};
    spec.move = {0, 0.3, 0};
    spec.radius = 0.3;
    const double rho = 0.1;
    const auto star = starShapedSwirl(
        spec, rho, Box(Eigen::Vector3d::Constant(-2), Eigen::Vector3d::Constant(2)));
    // A point on the ball's surface at the start ends on the ball's surface at the end.
    const Eigen::Vector3d p = spec.at + Eigen::Vector3d(rho, 0, 0) * 1.0001;
    const Eigen::Vector3d q = star->forwardMap(p).p;
    EXPECT_NEAR((q - (spec.at + spec.move)).norm(), rho, 0.02 * rho);
    // Away from the ball the composition is undone by its inverse.
    Rng rng(64);
    for (int i = 0; i < 200; ++i) {
        const Eigen::Vector3d x = rng.vec(-1, 1);
        if ((x - spec.at).norm() < 2 * rho) continue;
        EXPECT_LT((star->inverseMap(star->forwardMap(x).p) - x).norm(), 1e-6);
    }
}
