// SPDX-License-Identifier: Apache-2.0
// An orbit camera: yaw and pitch about a target, at a distance; perspective projection.
#pragma once

#include <glm/glm.hpp>

namespace sweepers {

struct Ray {
    glm::dvec3 origin, direction;
};

class OrbitCamera {
  public:
    glm::dvec3 target{0.0};
    double yaw = 0.6, pitch = 0.35, distance = 4.0; // radians, world units
    double fovY = glm::radians(40.0);

    void orbit(double dyaw, double dpitch);
    // Moves the target in the view plane by a fraction of the view's height.
    void pan(double dx, double dy);
    void zoom(double factor);
    // Looks at a box from a distance where it fills about two thirds of the view.
    void frame(const glm::dvec3& lo, const glm::dvec3& hi);

    glm::dvec3 eye() const;
    glm::dmat4 view() const;
    glm::dmat4 projection(double aspect) const;
    // The ray through a pixel (x right, y down, in pixels of a width x height view).
    Ray rayThrough(double x, double y, double width, double height) const;
    // The world displacement, in the plane through `at` facing the camera, of a cursor
    // move from (x0, y0) to (x1, y1).
    glm::dvec3 dragInViewPlane(const glm::dvec3& at, double x0, double y0, double x1, double y1,
                               double width, double height) const;
};

} // namespace sweepers
