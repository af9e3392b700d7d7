// SPDX-License-Identifier: Apache-2.0
// Decaudin's inflation (thesis 2.30, 2.31, after [Dec96]) and the star-shaped
// swirling-sweepers built on it (4.16-4.19).
//
// Inflating a ball of radius rho at c blows it up through the point c:
//     f(p)    = c + (|p - c|^3 + rho^3)^(1/3) n,   n = (p - c) / |p - c|
//     f^-1(p) = c + (|p - c|^3 - rho^3)^(1/3) n    outside the ball.
// Space outside the ball keeps its volume, so a ball blown up inside the shape adds its
// volume ("add clay") and one blown up outside only pushes the shape aside. The inverse
// has no pre-image inside the ball: those voxels take the value at c, i.e. the material
// (or emptiness) at the centre.
//
// A centre on the surface leaves that value about zero across the whole new ball, with no
// sign: the thesis's map is discontinuous there (just inside, the ball is clay and the shape
// smooth; just outside, it is empty and the pushed surface closes round it in a cusp as thin
// as a razor). For a centre at depth s inside, the new surface lies about s^3 / (3 rho^2)
// beyond the ball's edge, where the inverse squeezes a whole band into the centre's
// neighbourhood (its stretch grows without bound), and the values sampled there are no
// distances. So an inflation whose centre's value (as the grid holds it when the inflation
// comes) lies within the band, either side of the surface, fills its ball
// (InflationFill): the value inside is the distance to the sphere of radius
// (rho^3 + s^3)^(1/3) about c, which the new surface encloses and touches where the old
// surface is nearest (a small fraction of a voxel from the edge), and a value sampled just
// beyond the edge outside the shape is capped by the distance to that sphere, no smaller than
// the distance to the new surface. Deeper centres keep the thesis's value. The stroke first
// puts a centre just outside the surface, within the band, on the surface along the normal
// (sculpt/stroke.cpp).
//
#pragma once

#include <memory>
#include <vector>

#include "deform/step_deformation.h"
#include "deform/swirl.h"

namespace sweepers {

// How an inflation fills its new ball: `band`, the grid's half-width (where its values are
// distances), the least value a filled voxel takes and how far beyond the edge sampled
// values are capped. 0: never (the thesis's value at c everywhere in the ball).
struct InflationFill {
    double band = 0.0;
};

class Inflation : public StepDeformation {
  public:
    // `remove` swaps the map and its inverse: the ball is sucked back into c (no ball is
    // filled then: the inverse reaches every point).
    Inflation(const Eigen::Vector3d& centre, double radius, const Box& reach, bool remove = false,
              InflationFill fill = {});

    Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const override;
    ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                              double tolerance = 0.0) const override;
    Eigen::Vector3d filledFrom() const override { return c_; }
    bool fillsWith(double fromValue) const override;
    double filledValue(const Eigen::Vector3d& x, double value, double fromValue) const override;
    Box filledBox() const override;

  private:
    Eigen::Vector3d blowUp(const Eigen::Vector3d& p) const; // 2.30
    Eigen::Vector3d suckIn(const Eigen::Vector3d& p) const; // 2.31, c inside the ball
    Eigen::Vector3d c_;
    double rho_, rho3_;
    bool remove_;
    InflationFill fill_;
};

// Sub-steps of several deformations applied one after the other.
class Sequence : public StepDeformation {
  public:
    explicit Sequence(std::vector<std::unique_ptr<StepDeformation>> parts);
    Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const override;
    ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                              double tolerance = 0.0) const override;

  private:
    std::pair<const StepDeformation*, int> locate(int k) const;
    std::vector<std::unique_ptr<StepDeformation>> parts_;
};

// Star-shaped swirling-sweepers for a ball of radius rho (4.19): take the ball out at h,
// swirl space along t, put it back at h + t. The ball must lie wholly inside or wholly
// outside the shape.
std::unique_ptr<StepDeformation> starShapedSwirl(const SwirlSpec& swirl, double rho,
                                                 const Box& reach);

} // namespace sweepers
