// SPDX-License-Identifier: Apache-2.0
#include "deform/sampled_field.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sweepers {

namespace {

// The uniform cubic B-spline's four weights at t in [0, 1) for the samples at floor - 1 ..
// floor + 2 (appendix C), or their derivatives.
void weights(double t, double w[4]) {
    const double s = 1.0 - t, t2 = t * t, t3 = t2 * t;
    w[0] = s * s * s / 6.0;
    w[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0;
    w[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0;
    w[3] = t3 / 6.0;
}
void slopes(double t, double w[4]) {
    const double s = 1.0 - t;
    w[0] = -0.5 * s * s;
    w[1] = 0.5 * (3.0 * t * t - 4.0 * t);
    w[2] = 0.5 * (-3.0 * t * t + 2.0 * t + 1.0);
    w[3] = 0.5 * t * t;
}

} // namespace

SampledField::SampledField(VelocitySamples samples) : s_(std::move(samples)) {
    const auto& d = s_.dims;
    if (d[0] < 1 || d[1] < 1 || d[2] < 1 || s_.values.size() != s_.count())
        throw std::invalid_argument("a sampled velocity field needs a lattice full of samples");
    if (!(s_.spacing > 0.0) || !std::isfinite(s_.spacing) || !s_.origin.allFinite())
        throw std::invalid_argument("a sampled velocity field needs a finite, positive spacing");
    // The largest difference of neighbouring samples, by component and axis (the samples
    // beyond the lattice being zero).
    Eigen::Matrix3d most = Eigen::Matrix3d::Zero();
    auto value = [&](int i, int j, int k) -> Eigen::Vector3d {
        if (i < 0 || j < 0 || k < 0 || i >= d[0] || j >= d[1] || k >= d[2])
            return Eigen::Vector3d::Zero();
        return s_.values[s_.index(i, j, k)].cast<double>();
    };
    for (int k = -1; k < d[2]; ++k)
        for (int j = -1; j < d[1]; ++j)
            for (int i = -1; i < d[0]; ++i) {
                const Eigen::Vector3d v = value(i, j, k);
                if (!v.allFinite())
                    throw std::invalid_argument("a sampled velocity field holds values that "
                                                "are not finite numbers");
                const Eigen::Vector3d n[3] = {value(i + 1, j, k), value(i, j + 1, k),
                                              value(i, j, k + 1)};
                for (int a = 0; a < 3; ++a)
                    most.col(a) = most.col(a).cwiseMax((n[a] - v).cwiseAbs());
            }
    lipschitz_ = most.norm() / s_.spacing;
    // Each component on its own, so that the four samples a row of the B-spline blends are
    // next to each other in memory.
    // The vectors are not kept besides (up to 768 MB for the largest lattice a file may hold).
    for (int c = 0; c < 3; ++c) {
        components_[c].reserve(s_.count());
        for (const Eigen::Vector3f& v : s_.values)
            components_[c].push_back(v[c]);
    }
    s_.values = {};
    const Eigen::Vector3d top(d[0] - 1, d[1] - 1, d[2] - 1);
    support_ = Box(s_.origin, s_.origin + s_.spacing * top).expanded(2.5 * s_.spacing);
}

VelocitySamples SampledField::samples() const {
    VelocitySamples out = s_;
    out.values.resize(s_.count());
    for (std::size_t i = 0; i < out.values.size(); ++i)
        out.values[i] = Eigen::Vector3f(components_[0][i], components_[1][i], components_[2][i]);
    return out;
}

double SampledField::blend(int c, const int base[3], const double* const w[3]) const {
    const auto& d = s_.dims;
    double sum = 0.0;
    if (base[0] >= 0 && base[1] >= 0 && base[2] >= 0 && base[0] + 3 < d[0] && base[1] + 3 < d[1] &&
        base[2] + 3 < d[2]) {
        // Inside the lattice (nearly everywhere): no sample to skip.
        for (int z = 0; z < 4; ++z)
            for (int y = 0; y < 4; ++y) {
                const float* row = &components_[c][s_.index(base[0], base[1] + y, base[2] + z)];
                sum += w[1][y] * w[2][z] *
                       (w[0][0] * row[0] + w[0][1] * row[1] + w[0][2] * row[2] + w[0][3] * row[3]);
            }
        return sum;
    }
    for (int z = 0; z < 4; ++z) {
        const int k = base[2] + z;
        if (k < 0 || k >= d[2]) continue;
        for (int y = 0; y < 4; ++y) {
            const int j = base[1] + y;
            if (j < 0 || j >= d[1]) continue;
            const float* row = &components_[c][s_.index(0, j, k)];
            for (int x = 0; x < 4; ++x) {
                const int i = base[0] + x;
                if (i >= 0 && i < d[0]) sum += w[0][x] * w[1][y] * w[2][z] * row[i];
            }
        }
    }
    return sum;
}

double SampledField::component(int c, const Eigen::Vector3d& p, int along) const {
    Eigen::Vector3d u = (p - s_.origin) / s_.spacing;
    if (s_.staggered) u[c] += 0.5;
    int base[3];
    double w[3][4];
    for (int a = 0; a < 3; ++a) {
        const double f = std::floor(u[a]);
        base[a] = int(f) - 1;
        if (a == along)
            slopes(u[a] - f, w[a]);
        else
            weights(u[a] - f, w[a]);
    }
    const double* const rows[3] = {w[0], w[1], w[2]};
    const double sum = blend(c, base, rows);
    return along >= 0 ? sum / s_.spacing : sum;
}

Eigen::Vector3d SampledField::at(const Eigen::Vector3d& p, double) const {
    if (!support_.contains(p)) return Eigen::Vector3d::Zero();
    // The weights along each axis at the samples' own places and, staggered, half a
    // spacing on (where the component along that axis lives): found once for all three.
    const Eigen::Vector3d u = (p - s_.origin) / s_.spacing;
    int base[2][3];
    double w[2][3][4];
    for (int shift = 0; shift < (s_.staggered ? 2 : 1); ++shift)
        for (int a = 0; a < 3; ++a) {
            const double x = u[a] + 0.5 * shift, f = std::floor(x);
            base[shift][a] = int(f) - 1;
            weights(x - f, w[shift][a]);
        }
    Eigen::Vector3d v;
    for (int c = 0; c < 3; ++c) {
        int b[3];
        const double* wc[3];
        for (int a = 0; a < 3; ++a) {
            const int shift = s_.staggered && a == c ? 1 : 0;
            b[a] = base[shift][a];
            wc[a] = w[shift][a];
        }
        v[c] = blend(c, b, wc);
    }
    return v;
}

double SampledField::divergence(const Eigen::Vector3d& p) const {
    if (!support_.contains(p)) return 0.0;
    return component(0, p, 0) + component(1, p, 1) + component(2, p, 2);
}

} // namespace sweepers
