// SPDX-License-Identifier: Apache-2.0
#include "core/falloff.h"

namespace sweepers {

double falloffMuDerivative(double d, double lambda) {
    if (d >= lambda || d <= 0.0) return 0.0;
    // d/dx (1 - 10x^3 + 15x^4 - 6x^5) = -30 x^2 (1 - x)^2
    const double x = d / lambda;
    const double y = 1.0 - x;
    return -30.0 * x * x * y * y / lambda;
}

double falloffMuMinSlope(double lambda) {
    return -15.0 / (8.0 * lambda);
}

double falloffBeta(double v) {
    if (v <= 0.0) return 0.0;
    if (v >= 1.0) return 1.0;
    return v * v * v * (10.0 - v * (15.0 - 6.0 * v));
}

double falloffGamma(double d, double lambda) {
    const double q = d / lambda;
    const double w = 1.0 + q * q;
    return 1.0 / (w * w);
}

} // namespace sweepers
