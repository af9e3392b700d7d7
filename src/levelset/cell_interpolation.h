// SPDX-License-Identifier: Apache-2.0
// Reading a grid between its voxels, within one cell: trilinear interpolation of the cell's
// corners, the corrected sample (Sampling::Corrected, resample.h), and the cell holding a
// point.
#pragma once

#include <cmath>

#include <openvdb/openvdb.h>

namespace sweepers {

// Trilinear interpolation of a cell's corner values at offset uvw inside it, in single
// precision (the values are floats; OpenVDB's BoxSampler turns every product into a double
// and back, in the innermost loop of sampling).
inline float trilinearIn(const float (&c)[2][2][2], const openvdb::Vec3d& uvw) {
    const float u = float(uvw[0]), v = float(uvw[1]), w = float(uvw[2]);
    const auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
    return lerp(lerp(lerp(c[0][0][0], c[0][0][1], w), lerp(c[0][1][0], c[0][1][1], w), v),
                lerp(lerp(c[1][0][0], c[1][0][1], w), lerp(c[1][1][0], c[1][1][1], w), v), u);
}

// Sampling::Corrected at offset uvw in a cell: the trilinear value less half of each axis's
// second differences, interpolated from the cell's corners like the values, times t (1 - t)
// on that axis. `at(i, j, k)` reads the value at offset (i, j, k) from the cell's lowest
// corner, each from -1 to 2 (the corners and one voxel beyond them along each axis). Within
// `reach` of the surface, `slope` (when given) receives the central differences at the
// corners, interpolated likewise: those of the trilinear values one voxel either way.
template <typename At>
float correctedIn(const At& at, const openvdb::Vec3d& uvw, float reach, float* slope = nullptr) {
    float c[2][2][2];
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k)
                c[i][j][k] = at(i, j, k);
    const float linear = trilinearIn(c, uvw);
    if (!(std::abs(linear) < reach)) return linear;
    float d1[3][2][2][2], d2[3][2][2][2];
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k) {
                const int o = 1 - 2 * i, p = 1 - 2 * j, q = 1 - 2 * k; // into the cell
                const float twice = 2.0f * c[i][j][k];
                const float in[3] = {c[1 - i][j][k], c[i][1 - j][k], c[i][j][1 - k]};
                const float out[3] = {at(i - o, j, k), at(i, j - p, k), at(i, j, k - q)};
                const int into[3] = {o, p, q};
                for (int a = 0; a < 3; ++a) {
                    if (slope) d1[a][i][j][k] = 0.5f * float(into[a]) * (in[a] - out[a]);
                    d2[a][i][j][k] = in[a] - twice + out[a];
                }
            }
    float correction = 0.0f;
    for (int a = 0; a < 3; ++a) {
        const float t = float(uvw[a]);
        correction += t * (1.0f - t) * trilinearIn(d2[a], uvw);
        if (slope) slope[a] = trilinearIn(d1[a], uvw);
    }
    return linear - 0.5f * correction;
}

// The cell (its lowest corner) holding index-space point p: the floor on each axis, as a
// truncation and a compare. std::floor is a call into libm in the baseline x86-64 build, on
// every sampled voxel; the integers are the same for any point
// within a grid's coordinates.
inline openvdb::Coord cellOf(const openvdb::Vec3d& p) {
    const auto down = [](double x) {
        const int i = int(x);
        return i - int(x < double(i));
    };
    return openvdb::Coord(down(p[0]), down(p[1]), down(p[2]));
}

} // namespace sweepers
