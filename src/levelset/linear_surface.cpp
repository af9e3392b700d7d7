// SPDX-License-Identifier: Apache-2.0
#include "levelset/linear_surface.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <openvdb/math/Proximity.h>
#include <openvdb/math/Vec3.h>

namespace sweepers {

namespace {

using Vec = openvdb::Vec3d;

bool inside(float v) {
    return std::signbit(v);
}

// The distance from the origin to the zero set of the linear function on the tetrahedron
// with corners p[k] and values v[k]: a triangle (one corner on its own side) or a
// quadrilateral (two and two), split into two triangles along one of its diagonals.
double tetrahedronDistance(const Vec (&p)[4], const float (&v)[4]) {
    int in[4], out[4], nIn = 0, nOut = 0;
    for (int k = 0; k < 4; ++k)
        (inside(v[k]) ? in[nIn++] : out[nOut++]) = k;
    if (nIn == 0 || nOut == 0) return std::numeric_limits<double>::infinity();
    const auto crossing = [&](int a, int b) {
        // Both ends 0 (-0 inside, +0 outside): the edge lies on the surface, any point of it.
        const double step = double(v[a]) - double(v[b]);
        const double t = step != 0.0 ? double(v[a]) / step : 0.5;
        return p[a] + (p[b] - p[a]) * t;
    };
    const Vec origin(0.0, 0.0, 0.0);
    const auto triangle = [&](const Vec& a, const Vec& b, const Vec& c) {
        Vec uvw;
        return openvdb::math::closestPointOnTriangleToPoint(a, b, c, origin, uvw).length();
    };
    if (nIn == 1 || nOut == 1) {
        const int alone = nIn == 1 ? in[0] : out[0];
        int rest[3], n = 0;
        for (int k = 0; k < 4; ++k)
            if (k != alone) rest[n++] = k;
        return triangle(crossing(alone, rest[0]), crossing(alone, rest[1]),
                        crossing(alone, rest[2]));
    }
    // In order around the quadrilateral: in0-out0, in0-out1, in1-out1, in1-out0.
    const Vec a = crossing(in[0], out[0]), b = crossing(in[0], out[1]), c = crossing(in[1], out[1]),
              d = crossing(in[1], out[0]);
    return std::min(triangle(a, b, c), triangle(a, c, d));
}

} // namespace

float distanceToLinearSurface(const Block27& values) {
    const auto at = [&](int x, int y, int z) {
        return values[(x + 1) * 9 + (y + 1) * 3 + (z + 1)];
    };
    // The six tetrahedra of a cube: the paths from its lowest corner to its highest along the
    // axes in each order.
    static const int kOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                      {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    double best = std::numeric_limits<double>::infinity();
    for (int cx = -1; cx <= 0; ++cx)
        for (int cy = -1; cy <= 0; ++cy)
            for (int cz = -1; cz <= 0; ++cz) {
                int nIn = 0;
                for (int k = 0; k < 8; ++k)
                    nIn += inside(at(cx + (k >> 2), cy + ((k >> 1) & 1), cz + (k & 1)));
                if (nIn == 0 || nIn == 8) continue; // no crossing in this cube
                for (const auto& order : kOrders) {
                    Vec p[4];
                    float v[4];
                    int corner[3] = {cx, cy, cz};
                    for (int k = 0; k < 4; ++k) {
                        if (k > 0) ++corner[order[k - 1]];
                        p[k] = Vec(corner[0], corner[1], corner[2]);
                        v[k] = at(corner[0], corner[1], corner[2]);
                    }
                    best = std::min(best, tetrahedronDistance(p, v));
                }
            }
    return float(best);
}

} // namespace sweepers
