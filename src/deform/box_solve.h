// SPDX-License-Identifier: Apache-2.0
// Exact solves of (shift - scale Laplacian) x = b on a box of cells, the 7-point Laplacian
// with each axis's ends either closed (no flow through them: Neumann) or held at zero
// (Dirichlet, the value beyond the end being zero). The swept fluid's implicit diffusion
// (4.23) and pressure projection (4.24) are such problems. Constant coefficients make the
// operator diagonal in a product of 1-D bases (cosines for closed ends, sines for zero
// ends), so the solve is three changes of basis there and back: O(n^4) for n^3 cells, and
// exact to rounding where an iterative solver stops at its tolerance.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace sweepers {

enum class BoxEnds { Closed, Zero };

struct BoxProblem {
    std::array<int, 3> dims{0, 0, 0}; // cells a side (x fastest in the values)
    std::array<BoxEnds, 3> ends{BoxEnds::Closed, BoxEnds::Closed, BoxEnds::Closed};
    double shift = 0.0; // >= 0
    double scale = 1.0; // >= 0, and shift + scale > 0
    std::size_t size() const { return std::size_t(dims[0]) * std::size_t(dims[1]) * dims[2]; }
};

// Replaces the right-hand side `values` by the solution. With no shift and every end closed
// the operator is singular: the solve leaves out the right-hand side's mean (which a
// consistent problem does not have) and returns the solution of zero mean. Throws
// std::invalid_argument for an empty box, a negative shift or scale (or both zero), or values
// that do not fill the box.
void solveBox(const BoxProblem& problem, std::vector<double>& values);

} // namespace sweepers
