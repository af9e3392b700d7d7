// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "levelset/linear_surface.h"

using namespace sweepers;

namespace {

template <typename F> void fill(Block27& block, const F& f) {
    for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y)
            for (int z = -1; z <= 1; ++z)
                block[(x + 1) * 9 + (y + 1) * 3 + (z + 1)] = float(f(x, y, z));
}

} // namespace

// Linear interpolation reproduces a linear field, so its surface is the plane itself, and
// scaling the values does not move it.
TEST(LinearSurface, OfALinearFieldIsItsPlane) {
    std::mt19937 random(7);
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> offset(-0.95, 0.95);
    double worst = 0.0;
    for (int trial = 0; trial < 2000; ++trial) {
        double n[3] = {normal(random), normal(random), normal(random)};
        const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        const double c = offset(random); // the plane's distance from the centre, signed
        const double scale = trial % 2 ? 1.0 : 7.5;
        Block27 block;
        fill(block, [&](int x, int y, int z) {
            return scale * ((n[0] * x + n[1] * y + n[2] * z) / length + c);
        });
        worst = std::max(worst, std::abs(distanceToLinearSurface(block) - std::abs(c)));
    }
    std::printf("[ surface ] planes: largest error %.2g voxel\n", worst);
    EXPECT_LT(worst, 1e-5);
}

TEST(LinearSurface, NoneWhereNoValueChangesSign) {
    Block27 block;
    fill(block, [](int x, int y, int z) { return 2.0 + 0.5 * x + 0.25 * y - 0.5 * z; });
    EXPECT_EQ(distanceToLinearSurface(block), std::numeric_limits<float>::infinity());
}

// -0 reads as inside, as seeding reads it; an edge from -0 to +0 lies on the surface.
TEST(LinearSurface, MinusZeroIsInside) {
    Block27 block;
    fill(block, [](int x, int, int) { return x == 1 ? -0.0 : 1.0; });
    EXPECT_NEAR(distanceToLinearSurface(block), 1.0f, 1e-6f);
    fill(block, [](int x, int, int) { return x == 1 ? -0.0 : 0.0; });
    const float d = distanceToLinearSurface(block);
    EXPECT_FALSE(std::isnan(d));
    EXPECT_LE(d, 1.0f);
}

// Next to a sphere of radius R voxels, the linear surface through its distance's crossings
// lies within the interpolation error of the tetrahedra: a Kuhn tetrahedron's circumradius is
// sqrt(3) / 2, the distance's second derivative at most 1 / (R - 1) there, so the values
// interpolate within 3 / (8 (R - 1)) of it, and the surface lies no farther.
TEST(LinearSurface, OfASphereLiesWithinTheInterpolationError) {
    std::mt19937 random(11);
    std::uniform_real_distribution<double> unit(-0.5, 0.5);
    for (const double radius : {3.0, 6.0, 12.0}) {
        double worst = 0.0;
        for (int trial = 0; trial < 500; ++trial) {
            // A centre such that the block's centre lies within a voxel of the sphere.
            const double dir[3] = {unit(random), unit(random), unit(random)};
            const double dn = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
            const double at = radius + 1.6 * unit(random); // centre's distance from the sphere's
            double centre[3];
            for (int a = 0; a < 3; ++a)
                centre[a] = -dir[a] / dn * at;
            const auto sdf = [&](double x, double y, double z) {
                return std::sqrt((x - centre[0]) * (x - centre[0]) +
                                 (y - centre[1]) * (y - centre[1]) +
                                 (z - centre[2]) * (z - centre[2])) -
                       radius;
            };
            Block27 block;
            fill(block, [&](int x, int y, int z) { return sdf(x, y, z); });
            worst =
                std::max(worst, std::abs(distanceToLinearSurface(block) - std::abs(sdf(0, 0, 0))));
        }
        const double bound = 3.0 / (8.0 * (radius - 1.0));
        std::printf("[ surface ] a sphere of radius %.0f voxels: largest error %.3f voxel (bound "
                    "%.3f)\n",
                    radius, worst, bound);
        EXPECT_LT(worst, bound) << radius;
    }
}
