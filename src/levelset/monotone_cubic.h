// Monotone, mostly C1 cubic interpolation (thesis appendix C.1): a Hermite cubic per
// axis whose end slopes, central differences, are clamped to [Delta/2, 3 Delta] (or set
// to 0) so the interpolant never leaves the range of the two samples it lies between.
// Resampling with it does not overshoot, and is sharper than trilinear.
#pragma once

#include "levelset/vdb.h"

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

// Tricubic sample of the grid at an index-space position: the 1D interpolant along x on
// the 16 rows of the 4x4x4 neighbourhood, then along y, then z.
template <typename Accessor>
double sampleMonotoneCubic(const Accessor& acc, const openvdb::Vec3d& x) {
    const openvdb::Coord base = openvdb::Coord::floor(x);
    const double tx = x.x() - base.x(), ty = x.y() - base.y(), tz = x.z() - base.z();
    double plane[4];
    for (int k = 0; k < 4; ++k) {
        double row[4];
        for (int j = 0; j < 4; ++j) {
            double f[4];
            for (int i = 0; i < 4; ++i)
                f[i] = acc.getValue(base.offsetBy(i - 1, j - 1, k - 1));
            row[j] = monotoneCubic(f[0], f[1], f[2], f[3], tx);
        }
        plane[k] = monotoneCubic(row[0], row[1], row[2], row[3], ty);
    }
    return monotoneCubic(plane[0], plane[1], plane[2], plane[3], tz);
}

} // namespace sweepers
