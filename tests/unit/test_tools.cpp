// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "core/falloff.h"
#include "random.h"
#include "tools/ellipsoid.h"

using namespace sweepers;
using sweepers::test::Rng;

namespace {

// Brute-force distance from p to the surface of the world ellipsoid X(diag(a) S^2),
// by dense sampling of the unit sphere and a local refinement.
double bruteDistance(const Eigen::Affine3d& X, const Eigen::Vector3d& a, const Eigen::Vector3d& p) {
    double best = 1e300, bu = 0, bv = 0;
    auto at = [&](double u, double v) {
        const Eigen::Vector3d q(std::sin(u) * std::cos(v), std::sin(u) * std::sin(v), std::cos(u));
        return (X * Eigen::Vector3d(a.cwiseProduct(q)) - p).norm();
    };
    const int n = 400;
    for (int i = 0; i <= n; ++i)
        for (int j = 0; j < 2 * n; ++j) {
            const double u = M_PI * i / n, v = M_PI * j / n, d = at(u, v);
            if (d < best) best = d, bu = u, bv = v;
        }
    for (double h = M_PI / n; h > 1e-12; h *= 0.5)
        for (bool moved = true; moved;) {
            moved = false;
            for (auto [du, dv] : {std::pair{h, 0.0}, {-h, 0.0}, {0.0, h}, {0.0, -h}}) {
                const double d = at(bu + du, bv + dv);
                if (d < best) best = d, bu += du, bv += dv, moved = true;
            }
        }
    return best;
}

} // namespace

TEST(Tools, BallDistanceIsClosedForm) {
    Eigen::Affine3d X = Eigen::Affine3d::Identity();
    X.translate(Eigen::Vector3d(1, 2, 3));
    X.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()));
    X.scale(2.0);
    const auto ball = EllipsoidShape(0.5).place(X); // world radius 1
    EXPECT_EQ(ball->distance({1, 2, 3}), 0.0);
    EXPECT_EQ(ball->distance({1.5, 2, 3}), 0.0);
    EXPECT_NEAR(ball->distance({1, 2, 6}), 2.0, 1e-12);
    const Box b = ball->bounds();
    EXPECT_LT((b.min - Eigen::Vector3d(0, 1, 2)).norm(), 1e-12);
    EXPECT_LT((b.max - Eigen::Vector3d(2, 3, 4)).norm(), 1e-12);
}

TEST(Tools, EllipsoidDistanceIsEuclidean) {
    // The true distance of 3.38, checked against brute force, for axis-aligned, rotated,
    // non-uniformly scaled and mirrored placements; points inside are at distance 0.
    Rng rng(31);
    for (int c = 0; c < 12; ++c) {
        const Eigen::Vector3d a(rng.uniform(0.1, 1.0), rng.uniform(0.1, 1.0),
                                rng.uniform(0.1, 1.0));
        Eigen::Affine3d X = Eigen::Affine3d::Identity();
        X.translate(rng.vec(-1, 1));
        X.rotate(Eigen::AngleAxisd(rng.uniform(0, 3), rng.unit()));
        X.scale(Eigen::Vector3d(rng.uniform(0.5, 2), rng.uniform(0.5, 2), c % 3 == 0 ? -1.0 : 1.0));
        const auto shape = EllipsoidShape(a).place(X);
        for (int i = 0; i < 10; ++i) {
            const Eigen::Vector3d p = X * rng.vec(-3, 3);
            const Eigen::Vector3d local = X.inverse() * p;
            const bool inside = local.cwiseQuotient(a).squaredNorm() <= 1.0;
            const double d = shape->distance(p);
            if (inside) {
                EXPECT_EQ(d, 0.0);
            } else {
                EXPECT_NEAR(d, bruteDistance(X, a, p), 1e-8 * (1 + d)) << c << " " << i;
            }
        }
    }
}

TEST(Tools, EllipsoidDistanceOnDegenerateAxes) {
    // Points on the axes of a very flat ellipsoid, where the closest point is not the
    // radial projection.
    const Eigen::Vector3d a(1.0, 0.5, 0.05);
    EXPECT_NEAR(distanceToFilledEllipsoid(a, {2, 0, 0}), 1.0, 1e-12);
    EXPECT_NEAR(distanceToFilledEllipsoid(a, {0, 0, 0.3}), 0.25, 1e-12);
    EXPECT_EQ(distanceToFilledEllipsoid(a, {0.5, 0.2, 0.01}), 0.0);
    EXPECT_NEAR(distanceToFilledEllipsoid(a, {0.2, 0.0, 2.0}),
                bruteDistance(Eigen::Affine3d::Identity(), a, {0.2, 0.0, 2.0}), 1e-9);
}

TEST(Tools, BoundsAreTight) {
    Rng rng(32);
    for (int c = 0; c < 20; ++c) {
        Eigen::Affine3d X = Eigen::Affine3d::Identity();
        X.translate(rng.vec(-1, 1));
        X.rotate(Eigen::AngleAxisd(rng.uniform(0, 3), rng.unit()));
        X.scale(Eigen::Vector3d(rng.uniform(0.5, 2), rng.uniform(0.5, 2), rng.uniform(0.5, 2)));
        const Eigen::Vector3d a(0.3, 0.6, 0.9);
        const Box b = EllipsoidShape(a).place(X)->bounds();
        Box sampled;
        for (int i = 0; i < 20000; ++i)
            sampled.add(X * Eigen::Vector3d(a.cwiseProduct(rng.unit())));
        EXPECT_TRUE((sampled.min.array() >= b.min.array() - 1e-12).all());
        EXPECT_TRUE((sampled.max.array() <= b.max.array() + 1e-12).all());
        EXPECT_LT((sampled.min - b.min).cwiseAbs().maxCoeff(), 0.02);
        EXPECT_LT((sampled.max - b.max).cwiseAbs().maxCoeff(), 0.02);
    }
}

TEST(Tools, InfluenceZones) {
    // Inside T: phi = 1; coating K: (0, 1); outside O: 0, and O covers everything outside
    // the coating box.
    const PlacedTool tool(EllipsoidShape(0.5).place(Eigen::Affine3d::Identity()), 0.2);
    EXPECT_EQ(tool.influence({0.4, 0, 0}), 1.0);
    EXPECT_NEAR(tool.influence({0.6, 0, 0}), falloffMu(0.1, 0.2), 1e-15);
    EXPECT_GT(tool.influence({0.6, 0, 0}), 0.0);
    EXPECT_LT(tool.influence({0.6, 0, 0}), 1.0);
    EXPECT_EQ(tool.influence({0.71, 0, 0}), 0.0);
    EXPECT_EQ(tool.influence({0.6, 0.6, 0.6}), 0.0);
    EXPECT_LT((tool.coatingBounds().max - Eigen::Vector3d::Constant(0.7)).norm(), 1e-15);
}

TEST(Tools, RefusesBadSizes) {
    EXPECT_THROW(EllipsoidShape(0.0), std::invalid_argument);
    EXPECT_THROW(EllipsoidShape(-1.0), std::invalid_argument);
    EXPECT_THROW(EllipsoidShape(Eigen::Vector3d(1, std::nan(""), 1)), std::invalid_argument);
    EXPECT_THROW(PlacedTool(EllipsoidShape(1.0).place(Eigen::Affine3d::Identity()), 0.0),
                 std::invalid_argument);
}
