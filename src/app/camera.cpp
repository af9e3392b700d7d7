// SPDX-License-Identifier: Apache-2.0
#include "app/camera.h"

#include <algorithm>

#include <glm/gtc/matrix_transform.hpp>

namespace sweepers {

void OrbitCamera::orbit(double dyaw, double dpitch) {
    yaw += dyaw;
    pitch = std::clamp(pitch + dpitch, -1.55, 1.55);
}

void OrbitCamera::pan(double dx, double dy) {
    const glm::dmat4 v = view();
    const glm::dvec3 right(v[0][0], v[1][0], v[2][0]), up(v[0][1], v[1][1], v[2][1]);
    const double scale = 2.0 * distance * std::tan(0.5 * fovY);
    target += (-dx * right + dy * up) * scale;
}

void OrbitCamera::zoom(double factor) {
    distance = std::clamp(distance * factor, 1e-3, 1e4);
}

void OrbitCamera::frame(const glm::dvec3& lo, const glm::dvec3& hi) {
    target = 0.5 * (lo + hi);
    const double radius = std::max(0.5 * glm::length(hi - lo), 1e-3);
    distance = radius / std::sin(0.5 * fovY) * 1.1;
}

glm::dvec3 OrbitCamera::eye() const {
    return target + distance * glm::dvec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch),
                                          std::cos(pitch) * std::cos(yaw));
}

glm::dmat4 OrbitCamera::view() const {
    return glm::lookAt(eye(), target, glm::dvec3(0, 1, 0));
}

glm::dmat4 OrbitCamera::projection(double aspect) const {
    return glm::perspective(fovY, aspect, distance * 0.01, distance * 100.0);
}

Ray OrbitCamera::rayThrough(double x, double y, double width, double height) const {
    const glm::dmat4 inv = glm::inverse(projection(width / height) * view());
    const double nx = 2.0 * x / width - 1.0, ny = 1.0 - 2.0 * y / height;
    glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0), b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
    a /= a.w;
    b /= b.w;
    return {glm::dvec3(a), glm::normalize(glm::dvec3(b - a))};
}

glm::dvec3 OrbitCamera::dragInViewPlane(const glm::dvec3& at, double x0, double y0, double x1,
                                        double y1, double width, double height) const {
    const glm::dvec3 n = glm::normalize(eye() - target);
    auto hit = [&](double x, double y) {
        const Ray r = rayThrough(x, y, width, height);
        const double t = glm::dot(at - r.origin, n) / glm::dot(r.direction, n);
        return r.origin + t * r.direction;
    };
    return hit(x1, y1) - hit(x0, y0);
}

} // namespace sweepers
