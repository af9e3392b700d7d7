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
// beyond the ball's edge where the old surface is nearest, and leaves the ball where the
// old surface is farther, while the inverse squeezes a whole shell into the centre's
// neighbourhood (its stretch grows without bound): the values sampled there are no
// distances. So an inflation whose centre's value (as the grid holds it when the inflation
// comes; below the band, the depth found from the surface) lies above -deepestFill() and
// below the band fills its ball (InflationFill): along the ray from c through x the new
// surface lies at the image of the old surface's first crossing Q, at radius
// (rho^3 + Q^3)^(1/3), so a point within a band of the edge, in the ball or beyond it (where
// the sign agrees), takes its distance along the ray times the cosine between the ray and the
// surface's normal, the old normal carried through the map. Without a probe of the old
// surface (the exact reference), Q is bounded by s, and the value inside the ball is the
// distance to the sphere of radius (rho^3 + s^3)^(1/3) the new surface encloses. Elsewhere
// beyond the ball a sample is divided by the norm of its gradient carried through the map
// (carriedValue). Deeper centres keep the thesis's value: the ball is clay a band deep. The
// stroke first puts a centre just outside the surface, within the band, on the surface along
// the normal (sculpt/stroke_plan.cpp).
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
    double filledValue(const Eigen::Vector3d& x, double value, double fromValue,
                       const SurfaceProbe* probe) const override;
    Box filledBox(double fromValue) const override;
    double deepestFill() const override;
    Box fillReach() const override;
    Box carriedReach() const override;
    double carriedValue(const Eigen::Vector3d& x, double value,
                        const Eigen::Vector3d& g) const override;

  private:
    Eigen::Vector3d blowUp(const Eigen::Vector3d& p) const; // 2.30
    Eigen::Vector3d suckIn(const Eigen::Vector3d& p) const; // 2.31, c inside the ball
    // J^T g for the inverse's Jacobian J at radius r along the unit n, q its image's radius.
    static Eigen::Vector3d carried(const Eigen::Vector3d& n, double r, double q,
                                   const Eigen::Vector3d& g);
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
