// SPDX-License-Identifier: Apache-2.0
// Swirling-sweepers (thesis 4.1): volume-preserving pulls. The user gives a point h and a
// move t; a ring of n swirls of radius r, in the plane through h perpendicular to t, is
// swept along t in s = max(1, ceil(4|t|/r)) sub-steps (4.3).
//
//  - Discrete ring (4.1-4.7): swirl i of a ring centred at h_k is a rotation by theta
//    about the ring's tangent through c_i = h_k + r e_i, weighted by mu_2r(|p - c_i|);
//    the logs are summed with plain weights (4.1, not the normalized blend of 3.17), so
//    every swirl keeps volume (appendix B.1). theta = 2|t| / (n r s) (4.2) moves h by
//    exactly t: at a ring centre the swirls' rotations cancel into a translation by t/s.
//  - Convolution ring (4.8-4.15): infinitely many swirls with the falloff gamma_lambda;
//    their summed log has the closed form 4.11 and theta 4.13. gamma has no local support:
//    the work is limited to the bounding sphere 4.15, and the field is brought to zero
//    there through its stream function, so that it stays divergence-free (stepLog).
//
// As for every deformation, sub-step k is defined by its inverse with the ring at its
// next position h_{k+1} (5.18).
#pragma once

#include <vector>

#include "deform/step_deformation.h"

namespace sweepers {

enum class SwirlRing { Discrete, Convolution };

struct SwirlSpec {
    Eigen::Vector3d at = Eigen::Vector3d::Zero();   // h
    Eigen::Vector3d move = Eigen::Vector3d::Zero(); // t
    double radius = 0.3;                            // r
    SwirlRing ring = SwirlRing::Discrete;
    int swirls = 8;                // n, discrete ring
    double lambdaOverRadius = 1.2; // lambda / r, convolution ring (thesis: 1.2 r)
    double neglect = 1e-2;         // epsilon of the bounding sphere 4.15
};

class SwirlSegment : public StepDeformation {
  public:
    // Throws std::invalid_argument for a zero radius, a zero move or n < 1.
    explicit SwirlSegment(const SwirlSpec& spec);

    // Rotation angle of one swirl per sub-step (4.2 / 4.13 divided by s).
    double swirlAngle() const { return theta_; }
    // Centre of the ring at sub-step placement k in [0, s].
    Eigen::Vector3d ringCentre(int k) const { return spec_.at + spec_.move * (double(k) / steps_); }
    // Radius of the bounding sphere of a convolution ring (4.15).
    double boundingRadius() const { return reach_; }

  protected:
    std::optional<MotionLog> stepLog(int k, const Eigen::Vector3d& p) const override;

  private:
    SwirlSpec spec_;
    Eigen::Vector3d z_, u_, v_; // ring frame: z along t, u x v = z
    double theta_ = 0.0;
    double reach_ = 0.0; // distance from a ring centre beyond which nothing moves
    double inner_ = 0.0; // convolution ring: distance within which the field is 4.11's own
};

} // namespace sweepers
