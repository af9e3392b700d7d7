// SPDX-License-Identifier: Apache-2.0
// Falloff functions that turn a distance into an amount of deformation.
//
//   mu(d, lambda)     C2 piecewise quintic with support [0, lambda)   (thesis 3.2)
//   beta(v)           C2 smoothstep on [0, 1]                          (thesis 3.40)
//   gamma(d, lambda)  1 / (1 + (d/lambda)^2)^2, no local support       (thesis 4.8)
#pragma once

namespace sweepers {

// mu_lambda(d) = 1 + (d/l)^3 ((d/l)(15 - 6 d/l) - 10) for d < lambda, 0 beyond (3.2).
// Distances to a tool are never negative, so d <= 0 gives 1. Inline: the inverse map
// evaluates it at every voxel a segment samples.
inline double falloffMu(double d, double lambda) {
    if (d >= lambda) return 0.0;
    if (d <= 0.0) return 1.0;
    const double x = d / lambda;
    return 1.0 + x * x * x * (x * (15.0 - 6.0 * x) - 10.0);
}

// d mu_lambda / dd.
double falloffMuDerivative(double d, double lambda);

// min over d of d mu_lambda / dd = -15 / (8 lambda), reached at d = lambda / 2 (3.4).
// The sub-step bounds 3.14 and 3.19 use it.
double falloffMuMinSlope(double lambda);

// beta(v): 0 for v <= 0, 1 for v >= 1, v^3 (10 - v (15 - 6 v)) between (3.40).
double falloffBeta(double v);

// gamma_lambda(d) = 1 / (1 + (d / lambda)^2)^2 (4.8): its integral over a circle has a
// closed form, which the convolution swirl ring relies on.
double falloffGamma(double d, double lambda);

} // namespace sweepers
