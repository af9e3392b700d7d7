// SPDX-License-Identifier: Apache-2.0
// Swept fluid (thesis 4.2): the flow of an incompressible fluid around a ball, solved once
// and swept along the tool's path, a second volume-preserving grab.
//
// The solve (4.2.2) follows Stam's stable fluids for one time step: the cells inside the ball
// get the tool's velocity v_INIT = (1, 0, 0), everything else is at rest; then convection by
// the method of characteristics with the monotone interpolant of appendix C.1, implicit
// diffusion (4.23) and the pressure projection (4.24, 4.25). The thesis solves the last two by
// conjugate gradients; in the closed cube both have constant coefficients, and box_solve.h
// solves them exactly by changing bases, in a fixed number of fast transforms, where
// conjugate gradients need hundreds of iterations for the pressure alone.
// Unlike the thesis's collocated grid (C.1-C.3), velocities live on the faces of the cells (a
// MAC grid): there the discrete Laplacian is exactly the divergence of the gradient, so the
// projected field is divergence-free to rounding, where the collocated one keeps a
// checkerboard of divergence. The density rho only scales the pressure, so it drops out.
// The cube's walls are closed: no velocity through them or beyond them.
//
// The solution is smoothed by the cubic B-spline (sampled_field.h) and swept (4.2.3): a tool
// move t is cut into s = max(1, ceil(|W^-1 t| / |v_CENTER|)) steps (4.26), and each step
// carries the shape along the field, placed at the tool's position halfway through the step
// and turned so that its x axis follows t, for the time l = |W^-1 t| / (s |v_CENTER|) (4.27),
// which moves the ball's centre by t / s. Where the thesis moves each point once by l v, we
// follow the characteristic (the exact flow of the step's field): invertible by tracing back,
// fold-over free, and changing volume only by the field's divergence.
#pragma once

#include <memory>

#include "deform/sampled_field.h"
#include "deform/step_deformation.h"

namespace sweepers {

struct FluidSpec {
    int cells = 72;         // the solver's grid: cells^3 cells of size 1
    double ballRadius = 12; // the tool, in cells, at the grid's centre
    double viscosity = 2.0; // nu (4.23)
    double timeStep = 1.0;  // the one time step solved
};

struct FluidSolution {
    // Staggered, in cell units, the centre of the grid (and of the ball) at the origin.
    VelocitySamples samples;
    double divergence = 0.0; // the largest |divergence| of a cell after projection, per cell
};

// Throws std::invalid_argument for a grid of fewer than 8 cells a side, or a ball that does
// not leave a quarter of the grid free on every side (the flow around it needs room before
// the walls).
FluidSolution solveSweptFluid(const FluidSpec& spec);

// The smoothed solution, ready to be swept.
struct SweptFluid {
    SweptFluid(const VelocitySamples& solution, double ballRadiusCells);
    std::shared_ptr<const SampledField> field; // in cell units, ball at the origin
    double ballRadius;                         // in cells
    double centerSpeed;                        // |v_CENTER|, cells per unit time
};

// The deformation of the tool (a ball of `radius`, world units) moving from `from` to `to`:
// the steps of 4.26 chained before one resample. Throws std::invalid_argument for a move of
// no length or a radius that is not positive.
std::unique_ptr<StepDeformation> sweptFluidSegment(const SweptFluid& fluid, double radius,
                                                   const Eigen::Vector3d& from,
                                                   const Eigen::Vector3d& to);

// The most flow steps one segment of a fluid stroke may take.
constexpr double kMostFluidSteps = 1e6;
// How many steps (4.26) that move takes; throws std::invalid_argument past kMostFluidSteps.
int sweptFluidSteps(const SweptFluid& fluid, double radius, const Eigen::Vector3d& from,
                    const Eigen::Vector3d& to);

} // namespace sweepers
