// SPDX-License-Identifier: Apache-2.0
// Monotone, mostly C1 cubic interpolation (thesis appendix C.1): a Hermite cubic whose end
// slopes, central differences, are clamped to [Delta/2, 3 Delta] (or set to 0) so the
// interpolant never leaves the range of the two samples it lies between. Convecting or
// resampling with it does not overshoot, and is sharper than linear.
#pragma once

namespace sweepers {

// Interpolates between f0 (t = 0) and f1 (t = 1) with neighbours fm (t = -1), f2 (t = 2).
inline double monotoneCubic(double fm, double f0, double f1, double f2, double t) {
    const double delta = f1 - f0;
    double d0 = 0.5 * (f1 - fm), d1 = 0.5 * (f2 - f0);
    auto clamp = [delta](double& d) {
        if (delta < 0.0) {
            if (3.0 * delta > d)
                d = 3.0 * delta;
            else if (d > 0.5 * delta)
                d = 0.0;
        } else {
            if (3.0 * delta < d)
                d = 3.0 * delta;
            else if (d < 0.5 * delta)
                d = 0.0;
        }
    };
    clamp(d0);
    clamp(d1);
    const double a3 = d0 + d1 - 2.0 * delta;
    const double a2 = 3.0 * delta - 2.0 * d0 - d1;
    return f0 + t * (d0 + t * (a2 + t * a3));
}

} // namespace sweepers
