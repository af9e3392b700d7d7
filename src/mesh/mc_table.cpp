// SPDX-License-Identifier: Apache-2.0
#include "mesh/mc_table.h"

#include <stdexcept>

#include <Eigen/Geometry>

namespace sweepers::mc {

namespace {

constexpr std::array<Edge, 12> makeEdges() {
    std::array<Edge, 12> e{};
    int n = 0;
    for (int axis = 0; axis < 3; ++axis)
        for (int c = 0; c < 8; ++c)
            if (!(c & (1 << axis))) e[n++] = {c, c | (1 << axis), axis};
    return e;
}

Eigen::Vector3d cornerPos(int c) {
    return {double(c & 1), double(c >> 1 & 1), double(c >> 2 & 1)};
}

int edgeIndex(int a, int b) {
    for (int e = 0; e < 12; ++e)
        if ((kEdges[e].c0 == a && kEdges[e].c1 == b) || (kEdges[e].c0 == b && kEdges[e].c1 == a))
            return e;
    throw std::logic_error("not an edge");
}

// Two cube edges lie on a common face when some axis bit is fixed on all four corners.
bool shareFace(int a, int b) {
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            bool all = true;
            for (int c : {kEdges[a].c0, kEdges[a].c1, kEdges[b].c0, kEdges[b].c1})
                all = all && ((c >> axis & 1) == side);
            if (all) return true;
        }
    return false;
}

Eigen::Vector3d edgeMid(int e) {
    return 0.5 * (cornerPos(kEdges[e].c0) + cornerPos(kEdges[e].c1));
}

Case build(int mask) {
    auto inside = [&](int c) { return (mask >> c & 1) != 0; };
    std::array<int, 12> next;
    next.fill(-1);
    auto addSegment = [&](int a, int b, const Eigen::Vector3d& insidePoint,
                          const Eigen::Vector3d& normal) {
        const Eigen::Vector3d A = edgeMid(a), B = edgeMid(b);
        if ((B - A).cross(insidePoint - A).dot(normal) < 0) std::swap(a, b);
        if (next[a] != -1) throw std::logic_error("two segments leave one edge");
        next[a] = b;
    };
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (int side = 0; side < 2; ++side) {
            Eigen::Vector3d normal = Eigen::Vector3d::Zero();
            normal[axis] = side ? 1.0 : -1.0;
            // Face corners in cyclic order.
            const int base = side << axis;
            const int cyc[4] = {base, base | (1 << u), base | (1 << u) | (1 << v), base | (1 << v)};
            int crossings = 0;
            for (int k = 0; k < 4; ++k)
                crossings += inside(cyc[k]) != inside(cyc[(k + 1) % 4]);
            if (crossings == 0) continue;
            if (crossings == 2) {
                int ends[2], n = 0;
                Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
                int insideCount = 0;
                for (int k = 0; k < 4; ++k) {
                    const int c0 = cyc[k], c1 = cyc[(k + 1) % 4];
                    if (inside(c0) != inside(c1)) ends[n++] = edgeIndex(c0, c1);
                    if (inside(c0)) centroid += cornerPos(c0), ++insideCount;
                }
                addSegment(ends[0], ends[1], centroid / insideCount, normal);
            } else {
                // Ambiguous face: cut each inside corner off on its own.
                for (int k = 0; k < 4; ++k) {
                    if (!inside(cyc[k])) continue;
                    const int prev = cyc[(k + 3) % 4], next_ = cyc[(k + 1) % 4];
                    addSegment(edgeIndex(prev, cyc[k]), edgeIndex(cyc[k], next_), cornerPos(cyc[k]),
                               normal);
                }
            }
        }
    }
    Case out;
    std::array<bool, 12> used{};
    for (int start = 0; start < 12; ++start) {
        if (next[start] == -1 || used[start]) continue;
        std::vector<std::uint8_t> cycle;
        for (int e = start; !used[e]; e = next[e]) {
            if (next[e] == -1) throw std::logic_error("open cycle");
            used[e] = true;
            cycle.push_back(std::uint8_t(e));
        }
        const std::size_t n = cycle.size();
        // The segments run with the inside on their left seen from outside the cube, so the
        // cycle turns clockwise seen from outside the surface: triangles go the other way.
        int apex = -1;
        for (std::size_t k = 0; k < n && apex < 0; ++k) {
            bool clean = true;
            for (std::size_t j = 2; j + 1 < n; ++j)
                clean = clean && !shareFace(cycle[k], cycle[(k + j) % n]);
            if (clean) apex = int(k);
        }
        if (apex >= 0) {
            for (std::size_t j = 1; j + 1 < n; ++j)
                out.triangles.push_back(
                    {cycle[apex], cycle[(apex + j + 1) % n], cycle[(apex + j) % n]});
        } else {
            const std::uint8_t centre = std::uint8_t(kCentre + out.cycles.size());
            for (std::size_t j = 0; j < n; ++j)
                out.triangles.push_back({centre, cycle[(j + 1) % n], cycle[j]});
        }
        out.cycles.push_back(cycle);
    }
    return out;
}

std::array<Case, 256> buildAll() {
    std::array<Case, 256> t;
    for (int m = 0; m < 256; ++m)
        t[m] = build(m);
    return t;
}

} // namespace

const std::array<Edge, 12> kEdges = makeEdges();

const Case& lookup(int mask) {
    static const auto table = buildAll();
    return table[mask & 255];
}

} // namespace sweepers::mc
