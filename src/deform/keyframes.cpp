// SPDX-License-Identifier: Apache-2.0
#include "deform/keyframes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sweepers {

namespace {

// The quantities interpolated: translation, rotation vector, log scale.
using Coordinates = Eigen::Matrix<double, 9, 1>;

Coordinates coordinatesOf(const Placement& p) {
    Coordinates c;
    c.head<3>() = p.t;
    c.segment<3>(3) = p.hasRotation()
                          ? Eigen::Vector3d(p.axis.normalized() * p.angleDegrees * M_PI / 180.0)
                          : Eigen::Vector3d::Zero();
    c.tail<3>() = p.scale.array().log().matrix();
    return c;
}

Placement placementAt(const Coordinates& c) {
    Placement p;
    p.t = c.head<3>();
    const Eigen::Vector3d turn = c.segment<3>(3);
    if (turn.norm() > 0.0) {
        p.axis = turn.normalized();
        p.angleDegrees = turn.norm() * 180.0 / M_PI;
    }
    p.scale = c.tail<3>().array().exp().matrix();
    return p;
}

} // namespace

void checkKeyframes(const Keyframes& keys) {
    if (keys.times.size() != keys.placements.size())
        throw std::invalid_argument("every key needs a time and a placement");
    if (keys.times.size() < 2) throw std::invalid_argument("keys: at least two are needed");
    if (keys.times.front() != 0.0)
        throw std::invalid_argument("keys/0/time: the first key is at 0");
    for (std::size_t i = 1; i < keys.times.size(); ++i)
        if (!(keys.times[i] > keys.times[i - 1]))
            throw std::invalid_argument("keys/" + std::to_string(i) +
                                        "/time: keys must come in increasing time");
}

Placement keyedPlacement(const Keyframes& keys, double time) {
    const std::vector<double>& t = keys.times;
    if (time <= t.front()) return keys.placements.front();
    if (time >= t.back()) return keys.placements.back();
    const std::size_t i = std::size_t(std::upper_bound(t.begin(), t.end(), time) - t.begin()) - 1;
    const std::size_t n = t.size();
    const auto c = [&](std::size_t k) { return coordinatesOf(keys.placements[k]); };
    // Catmull-Rom tangents for non-uniform times: the central difference of the neighbours.
    const auto tangent = [&](std::size_t k) -> Coordinates {
        const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 == n ? k : k + 1;
        return (c(b) - c(a)) / (t[b] - t[a]);
    };
    const double dt = t[i + 1] - t[i], s = (time - t[i]) / dt;
    const double s2 = s * s, s3 = s2 * s;
    const Coordinates x = (2 * s3 - 3 * s2 + 1) * c(i) + (s3 - 2 * s2 + s) * dt * tangent(i) +
                          (-2 * s3 + 3 * s2) * c(i + 1) + (s3 - s2) * dt * tangent(i + 1);
    return placementAt(x);
}

} // namespace sweepers
