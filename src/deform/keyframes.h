// SPDX-License-Identifier: Apache-2.0
// Placements keyed over time (thesis 3.6.1: a keyframed tool's target, a sliding
// deformation's local frame), interpolated by a Catmull-Rom spline with non-uniform times
// (Hermite segments whose tangents are the central differences of the neighbouring keys,
// one-sided at the ends: C1, through every key). It interpolates the translation, the
// rotation vector (axis times angle) and the logarithm of each scale factor, so a key held
// twice in a row stays put between them, and rotations between keys less than a half turn
// apart go the short way round. Key j shapes the spline from key j - 2 to key j + 2 only.
#pragma once

#include <vector>

#include "deform/placement.h"

namespace sweepers {

struct Keyframes {
    std::vector<double> times; // seconds, from 0, increasing
    std::vector<Placement> placements;
};

// Throws std::invalid_argument, naming the key, when the keys do not start at time 0 or
// their times do not increase.
void checkKeyframes(const Keyframes& keys);

// The placement at `time` (held at the first and last keys outside their span).
Placement keyedPlacement(const Keyframes& keys, double time);

} // namespace sweepers
