// SPDX-License-Identifier: Apache-2.0
// Velocities given on a lattice (a vector grid read from a VDB file by io/, or the
// swept-fluid solver's result, swept_fluid.h) made a field defined everywhere by the
// trivariate uniform cubic B-spline of appendix C (thesis 4.2.2, "Smoothing the solution"):
// each sample is the control vector of a B-spline basis function of local support
// (4 samples a side), so the field is C2 (normals deform smoothly) and does not overshoot
// the samples. It approximates rather than interpolates; outside the lattice the samples are
// zero, so the field eases to rest two samples beyond it.
#pragma once

#include <array>
#include <vector>

#include "deform/velocity_field.h"

namespace sweepers {

struct VelocitySamples {
    std::array<int, 3> dims{0, 0, 0};                 // samples a side
    Eigen::Vector3d origin = Eigen::Vector3d::Zero(); // sample (0, 0, 0), in world units
    double spacing = 1.0;                             // between samples, in world units
    // Cell-centred: all three components of sample (i, j, k) lie at origin + spacing (i, j,
    // k). Staggered (a MAC grid, OpenVDB's GRID_STAGGERED): component a lies half a spacing
    // below along axis a, on the face of the cell.
    bool staggered = false;
    std::vector<Eigen::Vector3f> values; // x fastest, then y, then z

    std::size_t index(int i, int j, int k) const {
        return std::size_t(i) +
               std::size_t(dims[0]) * (std::size_t(j) + std::size_t(dims[1]) * std::size_t(k));
    }
    std::size_t count() const {
        return std::size_t(dims[0]) * std::size_t(dims[1]) * std::size_t(dims[2]);
    }
};

// Stationary: v(x, t) does not depend on t. Throws std::invalid_argument for samples that
// are not finite, or a lattice that is empty or does not match its values.
class SampledField : public VelocityField {
  public:
    explicit SampledField(VelocitySamples samples);

    Eigen::Vector3d at(const Eigen::Vector3d& p, double t = 0.0) const override;
    // The B-spline's derivative along an axis blends the differences of neighbouring samples
    // (a quadratic B-spline of them), so |dv_c/dx_a| is at most the largest such difference
    // over the spacing; the Frobenius norm of those bounds bounds the operator norm.
    double lipschitz() const override { return lipschitz_; }
    Box support() const override { return support_; }
    // The field's divergence at p, exactly (the B-spline's own derivatives).
    double divergence(const Eigen::Vector3d& p) const;
    // The samples it was made of (put together again from its components).
    VelocitySamples samples() const;

  private:
    // Component c and, when `along` >= 0, its derivative along that axis (per world unit).
    double component(int c, const Eigen::Vector3d& p, int along) const;
    // Component c blended over the 4 x 4 x 4 samples from `base` with weights w[axis].
    double blend(int c, const int base[3], const double* const w[3]) const;

    VelocitySamples s_;                            // the lattice; its values are in components_
    std::array<std::vector<float>, 3> components_; // the samples, component by component
    double lipschitz_ = 0.0;
    Box support_;
};

} // namespace sweepers
