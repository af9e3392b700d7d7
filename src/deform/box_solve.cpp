// SPDX-License-Identifier: Apache-2.0
#include "deform/box_solve.h"

#include <cmath>
#include <stdexcept>

namespace sweepers {

namespace {

// An orthonormal basis of R^m whose vectors are the eigenvectors of the negative 1-D
// Laplacian of m cells, with their eigenvalues 2 - 2 cos(theta_k): for closed ends (the
// diagonal 1 at the ends, 2 inside) the cosines of DCT-II, for zero ends (2 throughout) the
// sines of DST-I.
struct Basis {
    int m;
    std::vector<double> to;   // m x m, row-major: coordinates = to * values
    std::vector<double> from; // its transpose and inverse (kept so that both read rows)
    std::vector<double> eigen;

    Basis(int size, BoxEnds ends)
        : m(size), to(std::size_t(m) * m), from(std::size_t(m) * m), eigen(std::size_t(m)) {
        const bool closed = ends == BoxEnds::Closed;
        for (int k = 0; k < m; ++k) {
            const double theta = closed ? M_PI * k / m : M_PI * (k + 1) / (m + 1);
            const double norm =
                closed ? std::sqrt((k == 0 ? 1.0 : 2.0) / m) : std::sqrt(2.0 / (m + 1));
            for (int i = 0; i < m; ++i) {
                const double v =
                    closed ? norm * std::cos(theta * (i + 0.5)) : norm * std::sin(theta * (i + 1));
                to[std::size_t(k) * m + i] = from[std::size_t(i) * m + k] = v;
            }
            eigen[k] = 2.0 - 2.0 * std::cos(theta);
        }
    }
};

// Every line of v along `axis` multiplied by the dims[axis]-square matrix `matrix`.
void transformLines(std::vector<double>& v, const std::array<int, 3>& dims, int axis,
                    const std::vector<double>& matrix) {
    const std::size_t m = std::size_t(dims[axis]);
    const std::size_t stride = axis == 0   ? 1
                               : axis == 1 ? std::size_t(dims[0])
                                           : std::size_t(dims[0]) * std::size_t(dims[1]);
    std::vector<double> line(m);
    for (std::size_t l = 0; l < v.size() / m; ++l) {
        const std::size_t first = l % stride + (l / stride) * stride * m;
        for (std::size_t i = 0; i < m; ++i)
            line[i] = v[first + i * stride];
        for (std::size_t k = 0; k < m; ++k) {
            const double* row = &matrix[k * m];
            double sum = 0.0;
            for (std::size_t i = 0; i < m; ++i)
                sum += row[i] * line[i];
            v[first + k * stride] = sum;
        }
    }
}

} // namespace

void solveBox(const BoxProblem& problem, std::vector<double>& values) {
    const auto& d = problem.dims;
    if (d[0] < 1 || d[1] < 1 || d[2] < 1 || values.size() != problem.size())
        throw std::invalid_argument("a box solve needs a box of cells full of values");
    if (!(problem.shift >= 0.0) || !(problem.scale >= 0.0) ||
        !(problem.shift + problem.scale > 0.0))
        throw std::invalid_argument("a box solve needs a shift and a scale >= 0, not both zero");
    const Basis bases[3] = {
        {d[0], problem.ends[0]}, {d[1], problem.ends[1]}, {d[2], problem.ends[2]}};
    for (int a = 0; a < 3; ++a)
        transformLines(values, d, a, bases[a].to);
    // The operator's eigenvalue for the product of basis vectors (i, j, k); only the constant
    // vector of an all-closed, unshifted box has none.
    std::size_t f = 0;
    for (int k = 0; k < d[2]; ++k)
        for (int j = 0; j < d[1]; ++j)
            for (int i = 0; i < d[0]; ++i, ++f) {
                const double l =
                    problem.shift +
                    problem.scale * (bases[0].eigen[i] + bases[1].eigen[j] + bases[2].eigen[k]);
                values[f] = l > 0.0 ? values[f] / l : 0.0;
            }
    for (int a = 0; a < 3; ++a)
        transformLines(values, d, a, bases[a].from);
}

} // namespace sweepers
