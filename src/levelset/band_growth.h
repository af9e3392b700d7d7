// SPDX-License-Identifier: Apache-2.0
// What joins the band beyond the images of the surface in a segment's step (advect.h): the
// region a tear opens, the ball an inflation fills, the voxels next to the new crossing that
// sampling missed, and the leaves the band's outer voxels need; and whether sampling reached
// every voxel renormalization reads.
#pragma once

#include <vector>

#include "core/box.h"
#include "deform/step_deformation.h"
#include "levelset/resample.h"
#include "vdb/vdb.h"
#include "vdb/voxel_list.h"

namespace sweepers {

// The index box of a world box, grown by `pad` voxels.
openvdb::CoordBBox indexBox(const Grid& grid, const Box& world, int pad);

// Adds to `mask` (each leaf once) what a tearing deformation needs sampled beyond the band
// grown around the images of the surface: the inside voxels of the opened region (their sign
// changes), and the voxels near the opening's rim whose value will lie within `shell` of the
// surface. Where the surface touched the torn set, the rim is new surface, and the images of
// the few voxels near the touching point only reach it in their own directions; around the
// rim the tear stretches space along it by (d + r) / d at distance d from the torn set, and
// past a stretch of 7 (d < r / 6, less than r / 6 beyond the rim) the images of neighbouring
// voxels land farther apart than the band's dilation closes.
std::size_t markOpened(const Grid& grid, const StepDeformation& seg, double shell, VoxelList& mask);

// Adds to `mask` (each leaf once) what a filling deformation needs sampled beyond the band
// grown around the images of the surface: no surface maps into the region it fills, whose
// edge may be new surface. The voxels there whose filled value lies within `shell` of the
// surface join the band; they enclose the rest of the region, whose signs the flood after
// sampling re-derives. Nothing is marked where the fill does not apply or the centre lies
// deeper than `shell` (a dab of clay well inside the shape, as the modeler places it): its
// ball's box is not walked.
// `fromValue` is filledFromValue's.
std::size_t markFilled(const Grid& grid, const StepDeformation& seg, double shell, double fromValue,
                       VoxelList& mask);

// Whether sampling reached every voxel renormalization seeds from and every voxel their
// gradients read: each voxel of `box` in `leaves` next to the zero crossing is active, and
// so are its face neighbours. The signs are read as they stand, before inactive ones are
// re-derived: where the surface moved past an inactive voxel it reads as a crossing there,
// and the answer is no (which is only ever too cautious).
bool seedsSampled(const Grid& grid, const std::vector<LeafNode*>& leaves,
                  const openvdb::CoordBBox& box);

// What seedsSampled finds missing, voxel by voxel (where it answered no even after the images
// were dilated as far as the band reaches): the inactive voxels of `box` in `leaves` next to
// the zero crossing, and the inactive face neighbours within `box` of those next to it.
VoxelList unsampledSeeds(const Grid& grid, const std::vector<LeafNode*>& leaves,
                         const openvdb::CoordBBox& box);

// Makes the leaves of `grid` within `beyond` voxels of the mask's voxels that overlap `box`,
// exactly those dilating the mask by a cube of that radius would make: a voxel reaches the
// leaf next to it along an axis when it lies within `beyond` of it (a leaf more would only
// widen renormalization's domain). Along x the words themselves are chosen; along y and z,
// the bits of a word.
void makeLeavesWithin(Grid& grid, const VoxelList& mask, int beyond, const openvdb::CoordBBox& box);

} // namespace sweepers
