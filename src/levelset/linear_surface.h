// SPDX-License-Identifier: Apache-2.0
// The surface a grid's values place between voxels, read linearly: the zero set of the
// piecewise-linear interpolation of the values on Kuhn tetrahedra (each cube split into six
// along its main diagonal, the same way in every cube, so the pieces meet without gaps). Its
// vertices are the crossings on the cubes' edges and diagonals, so it passes through every
// axis crossing that seeding reads.
#pragma once

namespace sweepers {

// The values of a 3 x 3 x 3 block of voxels, index (x + 1) * 9 + (y + 1) * 3 + (z + 1) for the
// voxel at offset (x, y, z) from the centre; a value is inside when its sign bit is set (so
// -0 is inside, as the renormalization reads it).
using Block27 = float[27];

// The distance (in voxels) from the block's centre to the linear surface within the eight
// cubes around it; +infinity where none of them holds a crossing. Any point of the surface
// within one voxel of the centre lies in those cubes, so a seed's distance is exact for the
// linear surface.
float distanceToLinearSurface(const Block27& values);

} // namespace sweepers
