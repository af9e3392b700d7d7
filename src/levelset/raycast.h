// Where a ray first meets the surface of a level set: what the modeler grabs.
#pragma once

#include <optional>

#include "levelset/vdb.h"

namespace sweepers {

// Sphere tracing on the trilinear field (steps of |phi|, at least half a voxel, since the
// band only bounds the distance), then bisection to 1e-4 voxel. Nothing past `maxDistance`.
std::optional<Eigen::Vector3d> raycastLevelSet(const Grid& grid, const Eigen::Vector3d& origin,
                                               const Eigen::Vector3d& direction,
                                               double maxDistance);

} // namespace sweepers
