// SPDX-License-Identifier: Apache-2.0
// Where a ray first meets the surface of a level set (what the modeler grabs), and where
// it leaves the shape again (the far side a pinch goes through).
#pragma once

#include <optional>

#include "vdb/vdb.h"

namespace sweepers {

// Sphere tracing on the trilinear field (steps of |phi|, at least half a voxel, since the
// band only bounds the distance), then bisection to 1e-4 voxel. Nothing past `maxDistance`.
std::optional<Eigen::Vector3d> raycastLevelSet(const Grid& grid, const Eigen::Vector3d& origin,
                                               const Eigen::Vector3d& direction,
                                               double maxDistance);

// Where a ray from `inside` (a point of the shape) leaves the shape along `direction`: the
// same march on the field's other side. Nothing when it does not leave within
// `maxDistance`, or when `inside` is not inside.
std::optional<Eigen::Vector3d> exitLevelSet(const Grid& grid, const Eigen::Vector3d& inside,
                                            const Eigen::Vector3d& direction, double maxDistance);

} // namespace sweepers
