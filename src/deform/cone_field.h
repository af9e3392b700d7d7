// SPDX-License-Identifier: Apache-2.0
// The discontinuous scalar fields of the topology tools (thesis 3.39, 3.40, 3.43, 3.44):
// phi = alpha rho, where alpha is a cone-like field of the angle a between p - apex and an
// axis (1 within a_in of the axis, 0 beyond a_out) and rho a sphere-like field of a distance
// r (1 within r_in, 0 beyond r_out), both smoothed by beta. alpha is discontinuous at the
// apex, which is what lets a needle or a noose locate a point of the surface.
#pragma once

#include "core/falloff.h"

namespace sweepers {

struct ConeField {
    double aIn = 0.0, aOut = 0.0; // radians, aIn < aOut
    double rIn = 0.0, rOut = 0.0; // rIn < rOut

    double alpha(double angle) const { return falloffBeta((angle - aOut) / (aIn - aOut)); }
    double rho(double r) const { return falloffBeta((r - rOut) / (rIn - rOut)); }
    // A bound on |grad phi| at distance `apart` from the apex: the angle changes by at most
    // 1 / apart per unit of motion, and beta' <= 15/8 (3.40).
    double slopeBound(double apart) const {
        return 15.0 / 8.0 * (1.0 / ((aOut - aIn) * apart) + 1.0 / (rOut - rIn));
    }
};

// The cone angles (the thesis leaves them to the artist). Whatever lies in the cone is drawn
// along: the needles' funnels and the noose's waist lose the volume of their cones, so the
// cones are narrow; the narrower, the more sub-steps (the slope grows as 1 / (a_out - a_in)).
constexpr double kDegree = 3.14159265358979323846 / 180.0;
constexpr double kNeedleInDegrees = 10.0, kNeedleOutDegrees = 30.0;
constexpr double kNooseInDegrees = 5.0, kNooseOutDegrees = 20.0;

} // namespace sweepers
