// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include "deform/step_prefix.h"
#include "deform/sweep.h"
#include "random.h"
#include "tools/ellipsoid.h"

using namespace sweepers;
using sweepers::test::Rng;

namespace {

Placement at(Eigen::Vector3d t, Eigen::Vector3d axis = Eigen::Vector3d::UnitZ(), double deg = 0,
             Eigen::Vector3d s = Eigen::Vector3d::Ones()) {
    Placement p;
    p.t = t;
    p.axis = axis;
    p.angleDegrees = deg;
    p.scale = s;
    return p;
}

SweptTool ball(double r, double falloff, std::vector<Placement> path) {
    return {std::make_shared<EllipsoidShape>(r), falloff, std::move(path)};
}

SweptTool ellipsoid(Eigen::Vector3d a, double falloff, std::vector<Placement> path) {
    return {std::make_shared<EllipsoidShape>(a), falloff, std::move(path)};
}

struct Case {
    const char* name;
    Sweep sweep;
    double toolSize;
};

std::vector<Case> cases() {
    const Eigen::Vector3d z = Eigen::Vector3d::UnitZ(), y = Eigen::Vector3d::UnitY();
    std::vector<Case> out;
    out.push_back({"translation", {{ball(0.3, 0.3, {at({0, 1, 0}), at({0, 1.6, 0})})}}, 0.3});
    out.push_back({"rotation",
                   {{ellipsoid({0.2, 0.4, 0.3}, 0.25, {at({0.5, 0, 0}), at({0.5, 0, 0}, z, 75)})}},
                   0.3});
    out.push_back({"orbit", {{ball(0.2, 0.3, {at({1, 0, 0}), at({0, 1, 0}, z, 90)})}}, 0.2});
    out.push_back(
        {"scale", {{ball(0.3, 0.3, {at({0, 0, 1}), at({0, 0, 1}, z, 0, {1.8, 1.8, 1.8})})}}, 0.3});
    out.push_back({"non-uniform scale",
                   {{ball(0.3, 0.3, {at({0, 0, 1}), at({0, 0, 1}, z, 0, {1.0, 1.6, 1.0})})}},
                   0.3});
    out.push_back({"combined",
                   {{ellipsoid({0.3, 0.2, 0.25}, 0.3,
                               {at({0, 0, 0}), at({0.4, 0.2, 0}, y, 40, {1.3, 0.8, 1.1})})}},
                   0.25});
    out.push_back({"two tools",
                   {{ball(0.25, 0.3, {at({-0.2, 0, 0}), at({-0.5, 0.4, 0})}),
                     ball(0.2, 0.25, {at({0.25, 0, 0}), at({0.25, 0, 0}, z, 60)})}},
                   0.2});
    Sweep mirrored{{ball(0.25, 0.3, {at({0.3, 0, 0}), at({0.7, 0.4, 0.1}, z, 30)})}, MirrorAxis::X};
    out.push_back({"mirrored", mirrored, 0.25});
    return out;
}

double jacobianDeterminant(const SweepSegment& seg, const Eigen::Vector3d& p, double h) {
    Eigen::Matrix3d J;
    for (int i = 0; i < 3; ++i) {
        Eigen::Vector3d e = Eigen::Vector3d::Zero();
        e[i] = h;
        J.col(i) = (seg.inverseMap(p + e) - seg.inverseMap(p - e)) / (2 * h);
    }
    return J.determinant();
}

} // namespace

TEST(Sweep, InverseUndoesForward) {
    Rng rng(41);
    double worst = 0.0;
    for (const Case& c : cases()) {
        const SweepSegment seg(c.sweep, 0);
        const Box& box = seg.affectedBox();
        double caseWorst = 0.0;
        for (int i = 0; i < 2000; ++i) {
            const Eigen::Vector3d p = rng.inBox(box.min, box.max);
            const ForwardResult f = seg.forwardMap(p);
            ASSERT_TRUE(f.converged) << c.name;
            caseWorst = std::max(caseWorst, (seg.inverseMap(f.p) - p).norm());
            // and the other way round
            const ForwardResult g = seg.forwardMap(seg.inverseMap(p));
            caseWorst = std::max(caseWorst, (g.p - p).norm());
        }
        EXPECT_LT(caseWorst, 1e-6 * c.toolSize) << c.name;
        worst = std::max(worst, caseWorst / c.toolSize);
        std::printf("[ residual ] %-18s steps %3d  max |inverse(forward(p)) - p| = %.3g\n", c.name,
                    seg.steps(), caseWorst);
    }
    std::printf("[ residual ] worst relative to tool size: %.3g\n", worst);
}

// A sweep of one tool applies its influence times its log directly; the blend of several
// tools (3.17), which the base class applies, reduces to that: both give the same points to
// the bit, for every kind of motion.
TEST(Sweep, OneToolStepsAreTheBlendsOfOne) {
    Rng rng(7);
    for (const Case& c : cases()) {
        const SweepSegment seg(c.sweep, 0);
        if (seg.toolCount() != 1) continue;
        const Box& box = seg.affectedBox();
        int moved = 0;
        for (int i = 0; i < 500; ++i) {
            const Eigen::Vector3d p = rng.inBox(box.min, box.max);
            for (int k = 0; k < seg.steps(); ++k) {
                const Eigen::Vector3d q = seg.inverseStep(k, p);
                ASSERT_EQ(q, seg.StepDeformation::inverseStep(k, p)) << c.name;
                ASSERT_EQ(seg.forwardStep(k, p).p, seg.StepDeformation::forwardStep(k, p).p)
                    << c.name;
                moved += q != p;
            }
        }
        EXPECT_GT(moved, 100) << c.name;
    }
}

// Sampling maps a leaf's voxels in one call, and the band's growth a run of interface
// voxels: the batches give what the maps give one point at a time, to the bit, for every
// kind of motion, one tool or several, with points inside the tools, on their coatings and
// beyond the affected box.
TEST(Sweep, BatchesMapAsOnePointAtATime) {
    Rng rng(19);
    for (const Case& c : cases()) {
        const SweepSegment seg(c.sweep, 0);
        const Box& box = seg.affectedBox();
        const Eigen::Vector3d margin = 0.2 * (box.max - box.min);
        std::vector<Eigen::Vector3d> p(700), batch(p.size());
        for (Eigen::Vector3d& x : p)
            x = rng.inBox(box.min - margin, box.max + margin);
        seg.inverseMaps(p.data(), p.size(), batch.data());
        int moved = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            ASSERT_EQ(batch[i], seg.inverseMap(p[i])) << c.name << " point " << i;
            moved += batch[i] != p[i];
        }
        EXPECT_GT(moved, 50) << c.name;
        for (int k = 0; k < seg.steps(); ++k)
            for (const double tolerance : {0.0, 1e-4}) {
                seg.forwardSteps(k, p.data(), p.size(), tolerance, batch.data());
                for (std::size_t i = 0; i < p.size(); ++i)
                    ASSERT_EQ(batch[i], seg.forwardStep(k, p[i], tolerance).p)
                        << c.name << " sub-step " << k << " point " << i;
            }
    }
}

TEST(Sweep, SegmentMapIsFoldOverFree) {
    // Random tools and motions; the finite-difference Jacobian determinant of the composed
    // segment map is positive everywhere in the affected box.
    Rng rng(42);
    // The points must exercise the deformation, not the identity around it: count those
    // the segment moves, and the range of volume change they see.
    int moved = 0;
    double minDet = 1.0, maxDet = 1.0;
    for (int c = 0; c < 24; ++c) {
        const double r = rng.uniform(0.1, 0.4), lambda = rng.uniform(0.1, 0.4);
        const Eigen::Vector3d a(r, r * rng.uniform(0.5, 1.5), r * rng.uniform(0.5, 1.5));
        Placement A = at(rng.vec(-1, 1), rng.unit(), rng.uniform(-90, 90));
        Placement B = at(A.t + rng.vec(-0.8, 0.8), A.axis, A.angleDegrees + rng.uniform(-120, 120),
                         Eigen::Vector3d::Constant(std::exp(rng.uniform(-0.5, 0.5))));
        Sweep sweep{{ellipsoid(a, lambda, {A, B})}};
        if (c % 3 == 1) // a second tool moving on its own
            sweep.tools.push_back(
                ball(r, lambda, {at(A.t + rng.vec(-0.3, 0.3)), at(A.t + rng.vec(-0.8, 0.8))}));
        if (c % 3 == 2) sweep.mirror = MirrorAxis::Y;
        const SweepSegment seg(sweep, 0);
        const Box& box = seg.affectedBox();
        const double h = 1e-5 * box.extent().maxCoeff();
        for (int i = 0; i < 500; ++i) {
            const Eigen::Vector3d p = rng.inBox(box.min, box.max);
            const double det = jacobianDeterminant(seg, p, h);
            ASSERT_GT(det, 0.0) << "case " << c << " at " << p.transpose();
            minDet = std::min(minDet, det);
            maxDet = std::max(maxDet, det);
            moved += (seg.forwardMap(p).p - p).norm() > 1e-3 * r;
        }
    }
    std::printf("[ fold-over ] 12000 points, %d moved, Jacobian determinant in [%.3f, %.3f]\n",
                moved, minDet, maxDet);
    EXPECT_GT(moved, 3000); // a quarter of the points lie where the tools act
    EXPECT_LT(minDet, 0.5); // strong compression was sampled ...
    EXPECT_GT(maxDet, 2.0); // ... and strong expansion
}

TEST(Sweep, OneStepOnALargeMotionFoldsOver) {
    // The same check can fail: a pull of 4 falloff widths in a single step folds space.
    const Sweep sweep{{ball(0.3, 0.3, {at({0, 0, 0}), at({1.2, 0, 0})})}};
    SegmentOptions one;
    one.forceSteps = 1;
    const SweepSegment naive(sweep, 0, one), planned(sweep, 0);
    EXPECT_GT(planned.steps(), 1);
    Rng rng(43);
    int folded = 0;
    const Box& box = naive.affectedBox();
    for (int i = 0; i < 5000; ++i) {
        const Eigen::Vector3d p = rng.inBox(box.min, box.max);
        if (jacobianDeterminant(naive, p, 1e-6) <= 0.0) ++folded;
    }
    EXPECT_GT(folded, 0);
}

TEST(Sweep, InnerZoneMovesWithTheTool) {
    // 3.9: a point inside the tool moves exactly by the tool's motion M.
    Rng rng(44);
    for (const Case& c : cases()) {
        if (c.sweep.tools.size() > 1 || c.sweep.mirror != MirrorAxis::None) continue;
        const SweepSegment seg(c.sweep, 0);
        const Eigen::Matrix4d M = seg.motionLog(0).exp();
        const PlacedTool& start = seg.placedTool(0, 0);
        const PlacedTool& end = seg.placedTool(0, seg.steps());
        int inside = 0;
        for (int i = 0; i < 4000; ++i) {
            const Box& b = start.coatingBounds();
            const Eigen::Vector3d p = rng.inBox(b.min, b.max);
            if (start.distance(p) == 0.0) {
                ++inside;
                EXPECT_LT((seg.forwardMap(p).p - sweepers::test::apply(M, p)).norm(), 1e-9)
                    << c.name;
            }
            const Box& e = end.coatingBounds();
            const Eigen::Vector3d q = rng.inBox(e.min, e.max);
            if (end.distance(q) == 0.0) {
                EXPECT_LT((seg.inverseMap(q) - sweepers::test::apply(M.inverse(), q)).norm(), 1e-12)
                    << c.name;
            }
        }
        EXPECT_GT(inside, 100) << c.name;
    }
}

TEST(Sweep, OutsideTheAffectedBoxNothingMoves) {
    Rng rng(45);
    for (const Case& c : cases()) {
        const SweepSegment seg(c.sweep, 0);
        const Box big = seg.affectedBox().expanded(2.0);
        int outside = 0;
        for (int i = 0; i < 3000; ++i) {
            const Eigen::Vector3d p = rng.inBox(big.min, big.max);
            if (seg.affectedBox().contains(p)) continue;
            ++outside;
            EXPECT_EQ(seg.inverseMap(p), p) << c.name;
            EXPECT_EQ(seg.forwardMap(p).p, p) << c.name;
        }
        EXPECT_GT(outside, 1000);
    }
}

TEST(Sweep, NormalizedBlendOfIdenticalTranslationsIsThatTranslation) {
    // 3.17: two identical tools moved by d move their common inside by d, not 2d.
    const std::vector<Placement> path{at({0, 0, 0}), at({0.3, 0, 0})};
    const Sweep twice{{ball(0.3, 0.3, path), ball(0.3, 0.3, path)}};
    const Sweep once{{ball(0.3, 0.3, path)}};
    const SweepSegment a(twice, 0), b(once, 0);
    EXPECT_LT((a.forwardMap({0, 0, 0}).p - Eigen::Vector3d(0.3, 0, 0)).norm(), 1e-9);
    // In the coating the blended weight is 1 - (1 - phi)^2 <= 1, so no sub-step moves a
    // point further than the tools move; plain addition would reach 2 phi.
    const double stepLength = 0.3 / a.steps();
    Rng rng(46);
    for (int i = 0; i < 2000; ++i) {
        const Eigen::Vector3d p = rng.inBox(a.affectedBox().min, a.affectedBox().max);
        for (int k = 0; k < a.steps(); ++k)
            EXPECT_LE((a.inverseStep(k, p) - p).norm(), stepLength * (1 + 1e-12));
    }
    EXPECT_EQ(b.steps() * 2, a.steps()); // 3.19 sums the tools' bounds
    // A mirrored tool straddling its mirror plane, moved within the plane, is the same.
    const Sweep straddle{{ball(0.3, 0.3, {at({0, 0, 0}), at({0, 0.3, 0})})}, MirrorAxis::X};
    EXPECT_LT(
        (SweepSegment(straddle, 0).forwardMap({0, 0, 0}).p - Eigen::Vector3d(0, 0.3, 0)).norm(),
        1e-9);
}

TEST(Sweep, StepCountsFollowTheBound) {
    // 3.14: s is the smallest integer above (15 / (8 lambda)) max |log M . p_l|.
    const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
    const double r = 0.3, lambda = 0.3, k = 15.0 / (8.0 * lambda);
    // A pull of twice the tool radius: velocity 0.6 everywhere.
    const SweepSegment pull(Sweep{{ball(r, lambda, {at({0, 1, 0}), at({0, 1.6, 0})})}}, 0);
    EXPECT_NEAR(pull.stepBound(), k * 0.6, 1e-9);
    // A 90-degree twist about the tool's own centre: velocity theta * distance to the axis,
    // largest at the coating box corners (distance 0.6 sqrt 2).
    const SweepSegment twist(Sweep{{ball(r, lambda, {at({0, 1, 0}), at({0, 1, 0}, z, 90)})}}, 0);
    EXPECT_NEAR(twist.stepBound(), k * M_PI / 2 * 0.6 * std::sqrt(2.0), 1e-9);
    // A 2x scale about the tool centre: velocity log 2 |p - c|, largest at the corners of
    // the grown coating box (half-width 2 r + lambda).
    const SweepSegment grow(
        Sweep{{ball(r, lambda, {at({0, 1, 0}), at({0, 1, 0}, z, 0, {2, 2, 2})})}}, 0);
    EXPECT_NEAR(grow.stepBound(), k * std::log(2.0) * (2 * r + lambda) * std::sqrt(3.0), 1e-9);
    for (const SweepSegment* s : {&pull, &twist, &grow})
        EXPECT_EQ(s->steps(), int(std::floor(s->stepBound())) + 1);
    std::printf("[ steps ] pull 2r: %d, twist 90: %d, scale 2x: %d\n", pull.steps(), twist.steps(),
                grow.steps());
    // Two tools add their bounds (3.19).
    const SweepSegment pair(Sweep{{ball(r, lambda, {at({0, 1, 0}), at({0, 1.6, 0})}),
                                   ball(r, lambda, {at({2, 1, 0}), at({2, 1.6, 0})})}},
                            0);
    EXPECT_NEAR(pair.stepBound(), 2 * k * 0.6, 1e-9);
}

TEST(Sweep, RefusesMalformedSweeps) {
    EXPECT_THROW(Sweep{}.segmentCount(), std::invalid_argument);
    const Sweep single{{ball(0.3, 0.3, {at({0, 0, 0})})}};
    EXPECT_THROW(single.segmentCount(), std::invalid_argument);
    const Sweep uneven{{ball(0.3, 0.3, {at({0, 0, 0}), at({1, 0, 0})}),
                        ball(0.3, 0.3, {at({0, 0, 0}), at({1, 0, 0}), at({2, 0, 0})})}};
    EXPECT_THROW(uneven.segmentCount(), std::invalid_argument);
    // A half turn between placements is ambiguous; an enormous pull is refused, not planned.
    const Sweep halfTurn{
        {ball(0.3, 0.3, {at({0, 0, 0}), at({0, 0, 0}, Eigen::Vector3d::UnitZ(), 180)})}};
    EXPECT_THROW(SweepSegment(halfTurn, 0), std::domain_error);
    const Sweep huge{{ball(0.3, 0.01, {at({0, 0, 0}), at({100, 0, 0})})}};
    EXPECT_THROW(SweepSegment(huge, 0), std::domain_error);
}

TEST(Sweep, IdentityOnlyWhereNoToolReaches) {
    // Boxes the segment claims it leaves alone must hold only fixed points; of the boxes
    // inside the affected box, some (beyond the coatings) must be claimed, or the test
    // would not tell the sweep's answer from the affected-box default.
    Rng rng(7);
    for (const Case& c : cases()) {
        const SweepSegment seg(c.sweep, 0);
        const Box& affected = seg.affectedBox();
        int claimed = 0, claimedInside = 0;
        for (int trial = 0; trial < 400; ++trial) {
            const Eigen::Vector3d centre =
                rng.inBox(affected.min.array() - 0.2, affected.max.array() + 0.2);
            const Box box(centre.array() - 0.05, centre.array() + 0.05);
            if (!seg.identityOn(box)) continue;
            ++claimed;
            claimedInside += affected.overlaps(box);
            for (int i = 0; i < 20; ++i) {
                const Eigen::Vector3d p = rng.inBox(box.min, box.max);
                ASSERT_EQ(seg.inverseMap(p), p) << c.name << " at " << p.transpose();
            }
        }
        EXPECT_GT(claimed, 0) << c.name;
        EXPECT_GT(claimedInside, 0) << c.name;
        // A box around the tool is never left alone.
        const Eigen::Vector3d t = c.sweep.tools[0].path[0].t;
        EXPECT_FALSE(seg.identityOn(Box(t.array() - 0.01, t.array() + 0.01))) << c.name;
    }
}

// A translated tool's bound on the stretch holds where advection measures it: the largest
// singular value of the inverse map's central differences over a voxel, of any size, at
// points of the coating, for moves of one to several sub-steps and for their first sub-steps
// alone. Turning, scaling or several tools give no bound.
TEST(Sweep, ATranslatedToolBoundsTheStretch) {
    Rng rng(41);
    double closest = 0.0; // the largest measured excess over 1, as a part of the bound's
    int prefixes = 0;
    for (int trial = 0; trial < 40; ++trial) {
        const double radius = rng.uniform(0.1, 0.4), falloff = rng.uniform(0.05, 0.4);
        // Moves from a hundredth of the falloff to twice it: one sub-step to several.
        const Eigen::Vector3d move = rng.unit() * falloff * std::pow(10.0, rng.uniform(-2.0, 0.3));
        const Sweep sweep{
            {ball(radius, falloff, {at({0, 0, 1}), at(Eigen::Vector3d(0, 0, 1) + move)})}};
        const SweepSegment seg(sweep, 0);
        const double bound = seg.stretchBound();
        ASSERT_TRUE(std::isfinite(bound));
        // The segment, and the first half of its sub-steps where it has several (a film's
        // frame between placements).
        std::vector<std::unique_ptr<StepDeformation>> parts;
        if (seg.steps() > 1) parts.push_back(std::make_unique<StepPrefix>(seg, seg.steps() / 2));
        EXPECT_EQ(parts.empty() ? bound : parts[0]->stretchBound(), bound);
        const Box box = seg.affectedBox();
        for (int k = 0; k < 200; ++k) {
            const Eigen::Vector3d p = rng.inBox(box.min, box.max);
            const double h = std::pow(2.0, -rng.uniform(4.0, 9.0));
            const StepDeformation& map =
                parts.empty() || k % 2 ? static_cast<const StepDeformation&>(seg) : *parts[0];
            Eigen::Matrix3d J;
            for (int a = 0; a < 3; ++a) {
                Eigen::Vector3d e = Eigen::Vector3d::Zero();
                e[a] = 0.5 * h;
                J.col(a) = (map.inverseMap(p + e) - map.inverseMap(p - e)) / h;
            }
            const double stretch = J.jacobiSvd().singularValues()[0];
            ASSERT_LE(stretch, bound) << "trial " << trial << ", " << map.steps() << " sub-steps";
            closest = std::max(closest, (stretch - 1.0) / (bound - 1.0));
        }
        prefixes += !parts.empty();
    }
    EXPECT_GT(prefixes, 5);
    std::printf("[ sweep ] measured stretch beyond 1 at most %.3f of its bound's\n", closest);
    EXPECT_GT(closest, 0.3); // the bound is near what is measured, not vacuous
    for (const Case& c : cases())
        if (std::string(c.name) != "translation")
            EXPECT_TRUE(std::isinf(SweepSegment(c.sweep, 0).stretchBound())) << c.name;
}
