// SPDX-License-Identifier: Apache-2.0
// Points between the modeler's GLM (the camera, the renderer) and the engine's Eigen.
#pragma once

#include <Eigen/Core>
#include <glm/glm.hpp>

namespace sweepers {

inline glm::dvec3 toGlm(const Eigen::Vector3d& v) {
    return {v.x(), v.y(), v.z()};
}

inline Eigen::Vector3d toEigen3(const glm::dvec3& v) {
    return {v.x, v.y, v.z};
}

} // namespace sweepers
