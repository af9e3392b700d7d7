// SPDX-License-Identifier: Apache-2.0
// Axis-aligned box in world units. Empty until something is added to it.
#pragma once

#include <array>
#include <limits>

#include <Eigen/Core>

namespace sweepers {

struct Box {
    Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d max = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());

    Box() = default;
    Box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) : min(lo), max(hi) {}

    bool empty() const { return (min.array() > max.array()).any(); }
    void add(const Eigen::Vector3d& p) {
        min = min.cwiseMin(p);
        max = max.cwiseMax(p);
    }
    void add(const Box& b) {
        if (b.empty()) return;
        min = min.cwiseMin(b.min);
        max = max.cwiseMax(b.max);
    }
    Box expanded(double r) const { return empty() ? *this : Box(min.array() - r, max.array() + r); }
    bool contains(const Eigen::Vector3d& p) const {
        return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
    }
    bool overlaps(const Box& b) const {
        return !empty() && !b.empty() && (min.array() <= b.max.array()).all() &&
               (b.min.array() <= max.array()).all();
    }
    Eigen::Vector3d extent() const {
        return empty() ? Eigen::Vector3d(Eigen::Vector3d::Zero()) : Eigen::Vector3d(max - min);
    }
    std::array<Eigen::Vector3d, 8> corners() const {
        std::array<Eigen::Vector3d, 8> c;
        for (int i = 0; i < 8; ++i)
            c[i] = Eigen::Vector3d(i & 1 ? max.x() : min.x(), i & 2 ? max.y() : min.y(),
                                   i & 4 ? max.z() : min.z());
        return c;
    }
};

} // namespace sweepers
