// SPDX-License-Identifier: Apache-2.0
// The monotone cubic of appendix C.1 (core/monotone_cubic.h) on a grid: tricubic, and so
// sharper than trilinear, without overshoot.
#pragma once

#include "core/monotone_cubic.h"
#include "vdb/vdb.h"

namespace sweepers {

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
