// SPDX-License-Identifier: Apache-2.0
// Marching-cubes case table with a preferred polarity (thesis 5.3.1), generated from the
// 256 corner configurations instead of typed in, so that it cannot hold a hole.
//
// On every cube face the crossing edges are joined by segments that depend on that face
// alone; on an ambiguous face (two inside corners on a diagonal) the inside corners are
// always cut off separately. Two cubes sharing a face therefore draw the same segments
// there, and the surface closes. Segments are directed with the inside on their left seen
// from outside the cube; they chain into cycles that are fanned into triangles whose
// normals point from the inside (phi < 0) to the outside.
//
// Corner c sits at offset (c & 1, c >> 1 & 1, c >> 2 & 1). Edge e joins kEdgeCorners[e].
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace sweepers::mc {

struct Edge {
    int c0, c1; // corners, c1 = c0 + (1 << axis)
    int axis;
};
extern const std::array<Edge, 12> kEdges;

// A vertex index below 12 names the crossing on that cube edge; kCentre + k names the
// centre of cycle k (the mean of its edge vertices). A cycle is fanned from one of its own
// vertices when no fan diagonal joins two vertices on a common cube face; otherwise from
// its centre, since such a diagonal would be shared with the neighbouring cube's fan and
// make the mesh non-manifold there.
constexpr std::uint8_t kCentre = 12;

struct Case {
    std::vector<std::array<std::uint8_t, 3>> triangles;
    std::vector<std::vector<std::uint8_t>> cycles; // edge indices, in order
};

// For configuration `mask` (bit c set: corner c inside).
const Case& lookup(int mask);
inline const std::vector<std::array<std::uint8_t, 3>>& triangles(int mask) {
    return lookup(mask).triangles;
}

} // namespace sweepers::mc
