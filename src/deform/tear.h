// SPDX-License-Identifier: Apache-2.0
// The pulling half of the topology tools (thesis 3.41, 3.42): space is pushed away from a
// convex set S (the segment between the pinch's needle tips before pinching, or the disc the
// strangle's circle spanned), each point along the direction from its nearest point q on S:
//
//     M(p) = p + r phi(p) (p - q) / |p - q|,   phi = beta((d_out - d) / d_out),  d = |p - q|
//
// M is smooth off S and tears S open: points within r of S have no pre-image. Moving along
// p - q keeps q the nearest point of S, so the inverse only solves d' + r phi(d') = d along
// that direction (one unknown, increasing in d' when d_out >= 2 r, which the constructor
// enforces: beta' <= 15/8).
//
// A torn point x takes the value of its nearest point q of S, plus how deep x lies in the
// opened region (openedDepth: r - d). The pinch and the strangle bring the surface onto S at
// one point (the value there is zero) and leave the rest of S outside, so the opened region
// is empty, and the value is continuous across its rim: the sampled field has no step where
// the hole begins.
#pragma once

#include "deform/step_deformation.h"

namespace sweepers {

class Tear : public StepDeformation {
  public:
    // Along the segment [a, b]. Throws std::invalid_argument for a non-positive opening or
    // reach, or a degenerate segment.
    static Tear alongSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double open,
                             double reach);
    // Across the disc of the given radius at `centre`, normal to `normal`.
    static Tear acrossDisc(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal,
                           double radius, double open, double reach);

    double opening() const override { return open_; }
    double reach() const { return reach_; }
    // The nearest point of S.
    Eigen::Vector3d nearest(const Eigen::Vector3d& p) const;

    Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const override;
    ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                              double tolerance = 0.0) const override;
    double openedDepth(const Eigen::Vector3d& x) const override;
    // Minus the distance from p to S: S lies outside the shape (or on its surface), and a
    // distance is 1-Lipschitz.
    double leastValue(const Eigen::Vector3d& p) const override;
    Box openedBox() const override { return affected_.expanded(open_ - reach_); }
    Eigen::Vector3d alongTorn(const Eigen::Vector3d& x) const override;
    // Along a segment: where the pinch's needles meet, the grid rounds the membrane off past
    // the rim as well, and the hole's wall there read it as material (a ring on the wall near
    // the hole's middle, half a voxel high). Not across a disc: there the window reads along
    // the disc, outwards, where the strangle's neck has air beside it, and past the rim that
    // eats into the wall.
    bool windowPastRim() const override { return set_ == Set::Segment; }

  private:
    enum class Set { Segment, Disc };
    Tear(Set set, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius, double open,
         double reach);
    // The displacement r phi(d) of a point at distance d from S.
    double push(double d) const;

    Set set_;
    Eigen::Vector3d a_, b_; // segment ends, or the disc's centre and unit normal
    double radius_ = 0.0;   // of the disc
    double open_, reach_;
};

} // namespace sweepers
