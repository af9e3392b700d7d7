// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include "core/falloff.h"

using namespace sweepers;

TEST(Falloff, MuEndsAndSymmetry) {
    for (double lambda : {0.1, 0.3, 2.0}) {
        EXPECT_EQ(falloffMu(0.0, lambda), 1.0);
        EXPECT_EQ(falloffMu(-1.0, lambda), 1.0);
        EXPECT_EQ(falloffMu(lambda, lambda), 0.0);
        EXPECT_EQ(falloffMu(5.0 * lambda, lambda), 0.0);
        // mu(d) = 1 - mu(lambda - d), the symmetry noted after 3.2.
        for (double x = 0.0; x <= 1.0; x += 0.01)
            EXPECT_NEAR(falloffMu(x * lambda, lambda), 1.0 - falloffMu((1 - x) * lambda, lambda),
                        1e-14);
    }
}

TEST(Falloff, MuDerivativeMatchesFiniteDifferences) {
    const double lambda = 0.7, h = 1e-6;
    for (double d = 0.01; d < lambda; d += 0.013) {
        const double fd = (falloffMu(d + h, lambda) - falloffMu(d - h, lambda)) / (2 * h);
        EXPECT_NEAR(falloffMuDerivative(d, lambda), fd, 1e-8) << d;
    }
}

TEST(Falloff, MuMinimumSlopeIsExact) {
    // 3.4: the minimum of mu' is -15 / (8 lambda), reached at lambda / 2.
    for (double lambda : {0.05, 0.3, 1.0, 4.0}) {
        double minSlope = 0.0, at = -1.0;
        for (int i = 0; i <= 100000; ++i) {
            const double d = lambda * i / 100000.0;
            const double s = falloffMuDerivative(d, lambda);
            if (s < minSlope) {
                minSlope = s;
                at = d;
            }
        }
        EXPECT_NEAR(minSlope, falloffMuMinSlope(lambda), 1e-9 / lambda);
        EXPECT_NEAR(at, 0.5 * lambda, 1e-4 * lambda);
        EXPECT_DOUBLE_EQ(falloffMuMinSlope(lambda), -15.0 / (8.0 * lambda));
    }
}

TEST(Falloff, MuIsC2AtTheSupportEnds) {
    // The first and second derivatives vanish at 0 and lambda, so mu o d is C2 where d is.
    const double lambda = 1.0, h = 1e-4;
    EXPECT_NEAR(falloffMuDerivative(h, lambda), 0.0, 1e-6);
    EXPECT_NEAR(falloffMuDerivative(lambda - h, lambda), 0.0, 1e-6);
    const double second0 =
        (falloffMuDerivative(2 * h, lambda) - falloffMuDerivative(h, lambda)) / h;
    const double second1 =
        (falloffMuDerivative(lambda - h, lambda) - falloffMuDerivative(lambda - 2 * h, lambda)) / h;
    EXPECT_NEAR(second0, 0.0, 1e-2);
    EXPECT_NEAR(second1, 0.0, 1e-2);
}

TEST(Falloff, BetaIsTheRisingQuintic) {
    EXPECT_EQ(falloffBeta(-0.5), 0.0);
    EXPECT_EQ(falloffBeta(0.0), 0.0);
    EXPECT_EQ(falloffBeta(1.0), 1.0);
    EXPECT_EQ(falloffBeta(3.0), 1.0);
    for (double v = 0.0; v <= 1.0; v += 0.01) {
        EXPECT_NEAR(falloffBeta(v), 1.0 - falloffMu(v, 1.0), 1e-14);
        EXPECT_NEAR(falloffBeta(v) + falloffBeta(1.0 - v), 1.0, 1e-14);
    }
    EXPECT_NEAR(falloffBeta(0.5), 0.5, 1e-15);
}

TEST(Falloff, GammaValues) {
    EXPECT_EQ(falloffGamma(0.0, 0.4), 1.0);
    EXPECT_NEAR(falloffGamma(0.4, 0.4), 0.25, 1e-15);
    EXPECT_NEAR(falloffGamma(1.2, 0.4), 1.0 / 100.0, 1e-15);
    double prev = 2.0;
    for (double d = 0.0; d < 10.0; d += 0.1) {
        const double g = falloffGamma(d, 0.5);
        EXPECT_GT(g, 0.0);
        EXPECT_LT(g, prev);
        prev = g;
    }
}
