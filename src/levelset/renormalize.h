// SPDX-License-Identifier: Apache-2.0
// Renormalization of a narrow-band level set (thesis 5.3.3, [Bae01]): after a deformation
// the values near the surface still locate it, but are no longer distances. The discrete
// equations of fast marching rebuild |grad phi| = 1 outward from the surface:
//
//  1. seeds: every voxel with a face neighbour of the other sign gets phi / |grad phi|
//     (central differences), capped by the distance to its nearest axis crossing, or the
//     root of the second-order model of phi along the normal where that lies more than a
//     twentieth of a voxel lower (the field bends within the voxel; after a tear, lower or
//     higher), or, in a second pass after a tear, the distance to the surface the values
//     place (Seeding); given the gradient norms the values had before a deformation, phi
//     over the stretch it made instead, or the second-order root where it lies more than a
//     hundredth of a voxel from that (RenormalizeOptions::gradientBefore). Values whose gradient
//     (or stretch) is already unit within 1%, and values on or within two voxels of a feature one
//     voxel thin (the surface on both sides along an axis that meets it at more than about 15
//     degrees; but for that cap), are kept, and so are seeds whose stencil a deformation did not
//     change (RenormalizeOptions::moved): the estimate is not idempotent where the surface
//     curves within a voxel, and an interface seeded again and again would creep. The sign
//     of every voxel is kept.
//  2. every other voxel gets the upwind solution from its neighbours of its own side: the
//     first-order stencil, or the second-order one (HAFMM) where the voxel beyond the upwind
//     neighbour is closer still. These are solved leaf by leaf, the leaves of one parity
//     class in parallel, each by sweeps over its rows, eight voxels at once, until no value
//     moves, and changes at a leaf's border are passed to its neighbours until none is left
//     (the fast iterative method, on leaves). It solves the equations fast marching solves
//     (every value within about 1e-6 voxel of its upwind value), without fast marching's single
//     front, which visits the whole region in the order of distance, misses the cache at
//     nearly every voxel and can use only two threads (one per side).
//  3. voxels past the half-width are deactivated and set to +-background.
//
// Only a box of the grid is recomputed, on the leaves that overlap it; the voxels around
// it keep their values and act as fixed boundary values, but an inactive voxel next to a
// recomputed one joins the band where the solve brings it in (it has no value to keep). The
// band must already lie in leaves (advection activates it before sampling).
#pragma once

#include <optional>

#include "levelset/interrupt.h"
#include "vdb/vdb.h"
#include "vdb/voxel_list.h"

namespace sweepers {

// The order of the upwind stencil every voxel but the seeds is solved with.
enum class UpwindOrder { First = 1, Second = 2 };

// How seeds are estimated.
//  Lower: a seed's second-order value replaces its first-order one only downwards, after
//    smooth deformations, where a higher second-order value is the quadratic model straddling
//    a rim or a ridge, and taking it costs the interface accuracy.
//  Either: either way, after a tear, which compresses space towards the rim of the hole and
//    stretches it around the rim by orders of magnitude: central differences there straddle
//    the steep inside and read too large a gradient, and the first-order seeds lie too
//    shallow.
//  Interface: the distance to the linear surface through the values' crossings
//    (linear_surface.h), whatever the gradient reads; thin seeds are kept, as always. For a
//    second pass over a field that is a distance already: after a tear's first pass its
//    surface is where the tear put it, but its seeds, estimated from a field whose slope
//    varies by orders of magnitude within a few voxels, still disagree with one another by a
//    tenth to a third of a voxel, more than the surface's distance does from voxel to voxel;
//    after an inflation's, likewise across the seam where its ball's values meet those carried
//    through its map.
enum class Seeding { Lower, Either, Interface };

// What a renormalization recomputes, and how. The defaults renormalize the whole band.
struct RenormalizeOptions {
    // The voxels recomputed (index space). Unset: the whole active band, after which the
    // whole tree is pruned (its internal nodes too); set, the tree is pruned there.
    std::optional<openvdb::CoordBBox> region;
    // Of the region, only the voxels also listed here (what a deformation changed, grown by
    // the band): the rest keep their values and act as boundary. The work is that of the
    // leaves listed and those next to them, however many more the region holds.
    const VoxelList* only = nullptr;
    // Only the voxels of `moved` changed since the band was last a distance (advection
    // leaves out changes of less than a hundredth of a voxel): seeds are recomputed only
    // where their stencil (the voxel and its face neighbours) holds a voxel of `moved`;
    // other seeds keep their values, as boundary.
    const VoxelList* moved = nullptr;
    UpwindOrder order = UpwindOrder::Second;
    Seeding seeding = Seeding::Lower;
    // Per leaf, the norms of the gradient the values had before a deformation (with
    // Seeding::Lower only): a seed for which it holds a value is its value divided by the
    // stretch the deformation made there: its gradient's norm (central differences) over the
    // norm the values had before, at its pre-image. Central differences read a distance's
    // gradient below 1 wherever the surface curves within a few voxels, so a seed divided by
    // its own gradient's norm grows each time it is seeded again: the surface sharpens what
    // curves, which trilinear sampling's rounding roughly cancels, but which creeps under a
    // sampling that does not round (advect.h, Sampling::Corrected). Where the stretch changes
    // along the normal (a pull stretches the band more near the tool than away), phi over the
    // stretch errs by its relative change per voxel times the squared distance: the root of
    // the second-order model of phi along the normal (its gradient divided by the norm
    // before, as the stretch is) takes its place where the two differ by more than a
    // hundredth of a voxel.
    const VoxelValues* gradientBefore = nullptr;
    // Polled between phases and during the solve: a cancelled renormalization throws
    // Cancelled before it writes anything back.
    Interrupter* interrupter = nullptr;
};

struct RenormalizeStats {
    std::size_t seeds = 0;
    std::size_t marched = 0; // voxels given a distance within the band (seeds excluded)
    // Leaves of the domain: those overlapping the region and its margin (given `only`, those
    // of them holding or next to a leaf it lists).
    std::size_t leaves = 0;
};

// Recomputes the distances of the voxels the options name. The result is a valid narrow band
// of the grid's half-width there.
RenormalizeStats renormalize(Grid& grid, const RenormalizeOptions& options = {});

} // namespace sweepers
