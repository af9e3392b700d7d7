// SPDX-License-Identifier: Apache-2.0
// What OpenVDB's own diagnostics (tools::checkLevelSet, which Houdini's VDB Diagnostics and
// vdb_tool apply too) say of a level set, and how much of their eikonal complaint sits on
// features thinner than their stencil reads.
//
// The eikonal test takes |grad phi|^2 by fifth-order WENO, upwind (Godunov), at every voxel
// with a face neighbour across the surface, and refuses it outside [0.5, 1.5]. Its stencil
// reads three voxels each way along each axis. Where the shape is thinner than that, a
// distance field itself has a ridge (the shape's medial axis) or a second surface inside the
// stencil, the one-sided differences read across it, and even the exact distance can fail (a
// sheet two voxels thick does).
// Such a voxel is on a thin feature when, along the normal through it, within three voxels
// either way, the surface is crossed twice (a sheet or a gap thinner than that) or |phi|
// stops growing away from the surface (a ridge of the distance: the medial axis of a part
// thinner than that), or where the surface creases: the normal (the central gradient)
// turns by more than 15 degrees from the voxel to a face neighbour, as at a box's edge,
// where the medial axis meets the surface. The exact distance of an edge fails the test
// from a turn of about 30 degrees, which the central differences next to it see as half;
// the same test takes in parts under about four voxels in radius. And where the stencil's row
// along an axis crosses a sheet or rod under 1.25 voxels thick (along the row, between two
// crossings, a run whose length times the slope it is crossed with is under that) whose
// deepest voxel is on such a feature itself: the normal through the voxel may miss what the
// test reads across, as beside a strangle's squeezed neck.
#pragma once

#include <cstddef>
#include <string>

#include "core/box.h"
#include "vdb/vdb.h"

namespace sweepers {

struct PeerCheck {
    std::string message;           // checkLevelSet's first complaint (all nine tests); empty: none
    std::size_t eikonal = 0;       // voxels next to the surface the eikonal test refuses
    std::size_t eikonalThin = 0;   // ... of which on thin features
    std::size_t surfaceVoxels = 0; // voxels next to the surface (those the test reads)
    std::size_t thinVoxels = 0;    // ... of which on thin features
    Box thinBox;                   // world box of those, empty when none
    // World box of the refused voxels not on thin features, empty when none: where to look
    // for a complaint the shape does not account for.
    Box elsewhereBox;
};

// Runs OpenVDB's checks and classifies the eikonal test's voxels.
PeerCheck peerCheck(const Grid& grid);

} // namespace sweepers
