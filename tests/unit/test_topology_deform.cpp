// SPDX-License-Identifier: Apache-2.0
// The deformations of the topology tools (thesis 3.5): the tear (3.41, 3.42), the pinch's
// needles (3.39, 3.40) and the strangle's noose (3.43-3.45), as maps of space.
#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "deform/pinch.h"
#include "deform/strangle.h"
#include "deform/tear.h"
#include "random.h"

using namespace sweepers;
using sweepers::test::Rng;

TEST(Tear, InverseUndoesTheForwardMapOffTheTornRegion) {
    Rng rng(71);
    const Tear tears[] = {
        Tear::alongSegment({0, -1, 0}, {0, 1, 0}, 0.2, 0.5),
        Tear::acrossDisc({0.1, 0, 0}, {0, 1, 1}, 0.6, 0.15, 0.4),
    };
    for (const Tear& tear : tears) {
        double worst = 0.0;
        for (int i = 0; i < 3000; ++i) {
            const Eigen::Vector3d p = rng.inBox(tear.affectedBox().min, tear.affectedBox().max);
            if ((p - tear.nearest(p)).norm() < 1e-6) continue; // on S: torn
            const Eigen::Vector3d x = tear.forwardStep(0, p).p;
            // Nothing the forward map reaches is torn, and its pre-image is p again.
            EXPECT_LE(tear.openedDepth(x), 1e-12);
            worst = std::max(worst, (tear.inverseStep(0, x) - p).norm());
        }
        EXPECT_LT(worst, 1e-9);
    }
}

TEST(Tear, TheOpenedRegionTakesItsTornPointPlusItsDepth) {
    const Tear tear = Tear::alongSegment({0, -1, 0}, {0, 1, 0}, 0.2, 0.5);
    EXPECT_TRUE(tear.tears());
    const Eigen::Vector3d x(0.05, 0.3, 0.0); // 0.05 from the segment: 0.15 inside the hole
    EXPECT_TRUE(tear.inverseStep(0, x).isApprox(Eigen::Vector3d(0, 0.3, 0)));
    EXPECT_NEAR(tear.openedDepth(x), 0.15, 1e-12);
    // Just outside the opening, the pre-image is next to the segment: the values match at the
    // rim.
    const Eigen::Vector3d rim(0.2 + 1e-9, 0.3, 0.0);
    EXPECT_LT((tear.inverseStep(0, rim) - Eigen::Vector3d(0, 0.3, 0)).norm(), 1e-6);
    EXPECT_NEAR(tear.openedDepth(rim), 0.0, 1e-8);
    // Beyond the reach, and far away, nothing moves.
    EXPECT_EQ(tear.inverseStep(0, {0.6, 0.3, 0}), Eigen::Vector3d(0.6, 0.3, 0));
    EXPECT_EQ(tear.inverseStep(0, {5, 5, 5}), Eigen::Vector3d(5, 5, 5));
    // Every opened point lies in the opened box.
    const Box opened = tear.openedBox();
    EXPECT_TRUE(opened.contains(x));
    EXPECT_FALSE(opened.contains({0.25, 0, 0}));
}

TEST(Tear, NoDistanceIsBelowMinusTheWayToTheTornSet) {
    // The torn set lies outside the shape: a distance there is at least 0, and at most 1 lower
    // per unit of way from it.
    const Tear segment = Tear::alongSegment({0, -1, 0}, {0, 1, 0}, 0.2, 0.5);
    EXPECT_NEAR(segment.leastValue({0, 0.4, 0}), 0.0, 1e-12);
    EXPECT_NEAR(segment.leastValue({0.3, 0.4, -0.4}), -0.5, 1e-12);
    EXPECT_NEAR(segment.leastValue({0, 1.5, 0}), -0.5, 1e-12); // past an end
    const Tear disc = Tear::acrossDisc({0, 0, 0}, {0, 0, 2}, 0.5, 0.1, 0.4);
    EXPECT_NEAR(disc.leastValue({0.2, 0.1, 0.25}), -0.25, 1e-12);
    EXPECT_NEAR(disc.leastValue({0.9, 0, 0.3}), -0.5, 1e-12);
    // A deformation that does not tear knows no bound.
    const PinchSpec spec;
    EXPECT_EQ(PinchNeedles(spec, 0.0, 0.5, 4).leastValue({0, 0, 0}),
              -std::numeric_limits<double>::infinity());
}

TEST(Tear, RefusesWhatWouldFold) {
    // d' + r beta((d_out - d') / d_out) must increase: d_out >= 2 r.
    EXPECT_THROW(Tear::alongSegment({0, 0, 0}, {0, 1, 0}, 0.3, 0.5), std::invalid_argument);
    EXPECT_THROW(Tear::alongSegment({0, 0, 0}, {0, 0, 0}, 0.1, 0.5), std::invalid_argument);
    EXPECT_THROW(Tear::acrossDisc({0, 0, 0}, {0, 0, 0}, 1.0, 0.1, 0.5), std::invalid_argument);
    EXPECT_THROW(Tear::acrossDisc({0, 0, 0}, {0, 0, 1}, 1.0, -0.1, 0.5), std::invalid_argument);
}

namespace {
PinchSpec diameterPinch() {
    PinchSpec s;
    s.at = {0, 0, 0};
    s.axis = {0, 2, 0}; // any length
    s.size = 1.25;
    s.falloff = 0.4;
    s.open = 0.3;
    return s;
}
} // namespace

TEST(Pinch, NeedlesDragWhatLiesInTheirBody) {
    const PinchSpec spec = diameterPinch();
    const PinchNeedles needles(spec, 0.0, 0.25, 50);
    // The tips travel a quarter of the way: 0.3125 each, towards `at`.
    EXPECT_TRUE(needles.tip(0, 0.25).isApprox(Eigen::Vector3d(0, 0.9375, 0)));
    EXPECT_TRUE(needles.tip(1, 0.25).isApprox(Eigen::Vector3d(0, -0.9375, 0)));
    // A point just behind the upper tip's final place, on its body, came down with it.
    const Eigen::Vector3d behind(0, 0.9375 + 0.05, 0);
    EXPECT_LT((needles.inverseMap(behind) - (behind + Eigen::Vector3d(0, 0.3125, 0))).norm(), 1e-9);
    // A point ahead of the tip, and one beside its path beyond the falloff, stay.
    EXPECT_EQ(needles.inverseMap({0, 0.5, 0}), Eigen::Vector3d(0, 0.5, 0));
    EXPECT_EQ(needles.inverseMap({0.45, 1.0, 0}), Eigen::Vector3d(0.45, 1.0, 0));
}

TEST(Pinch, NeedlesAreOneToOneAwayFromTheirTips) {
    Rng rng(72);
    const PinchSpec spec = diameterPinch();
    for (const double voxel : {1.0 / 32, 1.0 / 64}) {
        const auto parts = planPinch(spec, voxel);
        const auto& needles = dynamic_cast<const PinchNeedles&>(*parts[2]);
        double worst = 0.0;
        int tested = 0;
        for (int i = 0; i < 3000; ++i) {
            const Eigen::Vector3d p =
                rng.inBox(needles.affectedBox().min, needles.affectedBox().max);
            // Two voxels from either tip's path, where the sub-step bound holds.
            const Eigen::Vector3d q = needles.inverseMap(p);
            bool nearTip = false;
            for (int n = 0; n < 2; ++n)
                for (double u = 2.0 / 13; u <= 3.0 / 13 + 1e-12; u += 1.0 / (13 * 64))
                    nearTip = nearTip || (p - needles.tip(n, u)).norm() < 2 * voxel ||
                              (q - needles.tip(n, u)).norm() < 2 * voxel;
            if (nearTip) continue;
            ++tested;
            worst = std::max(worst, (needles.forwardMap(q).p - p).norm());
        }
        EXPECT_GT(tested, 2000);
        EXPECT_LT(worst, 1e-6) << voxel;
    }
}

TEST(Pinch, PlanHasTheNeedlesThenThePull) {
    const PinchSpec spec = diameterPinch();
    const auto coarse = planPinch(spec, 1.0 / 32), fine = planPinch(spec, 1.0 / 64);
    ASSERT_EQ(coarse.size(), pinchSegmentCount(spec));
    ASSERT_EQ(fine.size(), coarse.size());
    EXPECT_EQ(coarse.size(), 14u); // 1.25 / (0.4 / 4) = 12.5 segments, then the pull
    for (std::size_t k = 0; k + 1 < coarse.size(); ++k) {
        EXPECT_FALSE(coarse[k]->tears());
        // The discontinuity needs more sub-steps the finer the grid.
        EXPECT_GT(fine[k]->steps(), coarse[k]->steps() * 19 / 10);
    }
    EXPECT_TRUE(coarse.back()->tears());
    PinchSpec bad = spec;
    bad.axis = Eigen::Vector3d::Zero();
    EXPECT_THROW(planPinch(bad, 1.0 / 32), std::invalid_argument);
    bad = spec;
    bad.open = 0.0;
    EXPECT_THROW(planPinch(bad, 1.0 / 32), std::invalid_argument);
}

namespace {
StrangleSpec equatorStrangle() {
    StrangleSpec s;
    s.at = {0, 0, 0};
    s.axis = {0, 1, 0};
    s.size = 1.2;
    s.falloff = 0.4;
    s.open = 0.3;
    return s;
}
} // namespace

TEST(Strangle, TheNooseDrawsInWhatItPasses) {
    const StrangleSpec spec = equatorStrangle();
    const StrangleNoose noose(spec, {1.0, 0.75, 0.5});
    // In the plane, outside the circle: scaled with it (1 -> 0.5 over two sub-steps).
    EXPECT_LT((noose.inverseMap({0.6, 0, 0}) - Eigen::Vector3d(1.2, 0, 0)).norm(), 1e-12);
    // Inside the final circle, and far above the plane: still.
    EXPECT_EQ(noose.inverseMap({0.3, 0, 0}), Eigen::Vector3d(0.3, 0, 0));
    EXPECT_EQ(noose.inverseMap({0.8, 0.5, 0}), Eigen::Vector3d(0.8, 0.5, 0));
    EXPECT_THROW(StrangleNoose(spec, {1.0, 1.1}), std::invalid_argument);
}

TEST(Strangle, StillBoxesAreStill) {
    // identityOn is what lets sampling skip leaves: a box it calls still must not move.
    Rng rng(73);
    const StrangleSpec spec = equatorStrangle();
    const auto parts = planStrangle(spec, 1.0 / 32);
    ASSERT_TRUE(parts.back()->tears());
    std::size_t still = 0;
    for (std::size_t k = 0; k + 1 < parts.size(); ++k) {
        const StepDeformation& noose = *parts[k];
        for (int b = 0; b < 400; ++b) {
            const Eigen::Vector3d lo = rng.vec(-1.7, 1.5);
            const Box box(lo, lo + Eigen::Vector3d::Constant(0.25));
            if (!noose.identityOn(box)) continue;
            ++still;
            for (int i = 0; i < 20; ++i) {
                const Eigen::Vector3d p = rng.inBox(box.min, box.max);
                ASSERT_EQ(noose.inverseMap(p), p) << k;
            }
        }
    }
    EXPECT_GT(still, 1000u);
}

TEST(TopologyTools, PointsCalledStillStayUnderEverySubStep) {
    // stillAt lets inverseMap skip all sub-steps: each of them must leave such a point alone.
    Rng rng(75);
    std::vector<std::unique_ptr<StepDeformation>> parts = planStrangle(equatorStrangle(), 1.0 / 32);
    for (auto& p : planPinch(diameterPinch(), 1.0 / 32))
        parts.push_back(std::move(p));
    std::size_t still = 0, moving = 0;
    for (const auto& part : parts) {
        if (part->tears()) continue;
        for (int i = 0; i < 300; ++i) {
            const Eigen::Vector3d p = rng.inBox(part->affectedBox().min, part->affectedBox().max);
            if (!part->stillAt(p)) {
                ++moving;
                continue;
            }
            ++still;
            for (int k = 0; k < part->steps(); ++k)
                ASSERT_EQ(part->inverseStep(k, p), p) << "sub-step " << k;
        }
    }
    EXPECT_GT(still, 1000u);
    EXPECT_GT(moving, 1000u);
}

TEST(Strangle, TheCircleShrinksBelowAVoxelWithoutFolding) {
    const StrangleSpec spec = equatorStrangle();
    for (const double voxel : {1.0 / 32, 1.0 / 64}) {
        const auto parts = planStrangle(spec, voxel);
        const auto& last = dynamic_cast<const StrangleNoose&>(*parts[parts.size() - 2]);
        EXPECT_NEAR(last.radius(last.steps()), voxel / 4, 1e-12);
        const auto& first = dynamic_cast<const StrangleNoose&>(*parts[0]);
        EXPECT_EQ(first.radius(0), spec.size);
        // Away from the circle the Jacobian of every inverse sub-step keeps a positive
        // determinant (no fold).
        Rng rng(74);
        for (const auto& part : parts) {
            const auto* noose = dynamic_cast<const StrangleNoose*>(part.get());
            if (!noose) continue;
            for (int i = 0; i < 200; ++i) {
                const int k = int(rng.uniform(0, noose->steps() - 1e-9));
                const Eigen::Vector3d p = rng.vec(-1.5, 1.5);
                const double out = std::hypot(p.x(), p.z());
                if (std::hypot(out - noose->radius(k + 1), p.y()) < 2 * voxel) continue;
                Eigen::Matrix3d J;
                for (int a = 0; a < 3; ++a) {
                    Eigen::Vector3d e = Eigen::Vector3d::Zero();
                    e[a] = 1e-6;
                    J.col(a) = (noose->inverseStep(k, p + e) - noose->inverseStep(k, p - e)) / 2e-6;
                }
                EXPECT_GT(J.determinant(), 0.0) << p.transpose() << " k " << k;
            }
        }
    }
}
