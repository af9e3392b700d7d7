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
// The displacement decays like rho^3 / (3 |p - c|^2) and never vanishes, so the caller
// gives the box beyond which it is neglected; the engine passes the shape's box, where
// nothing but empty space lies beyond.
#pragma once

#include <memory>
#include <vector>

#include "deform/step_deformation.h"
#include "deform/swirl.h"

namespace sweepers {

class Inflation : public StepDeformation {
  public:
    // `remove` swaps the map and its inverse: the ball is sucked back into c.
    Inflation(const Eigen::Vector3d& centre, double radius, const Box& reach, bool remove = false);

    Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const override;
    ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                              double tolerance = 0.0) const override;

  private:
    Eigen::Vector3d blowUp(const Eigen::Vector3d& p) const; // 2.30
    Eigen::Vector3d suckIn(const Eigen::Vector3d& p) const; // 2.31, c inside the ball
    Eigen::Vector3d c_;
    double rho3_;
    bool remove_;
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
