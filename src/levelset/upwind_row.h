// SPDX-License-Identifier: Apache-2.0
// The upwind update of renormalization for a row of eight voxels at once (eight lanes of
// vector registers): a row of a dense block of one side's distances (along the block's axis
// of stride 1), where the other side's voxels read as +infinity.
#pragma once

namespace sweepers::upwind {

struct RowBlock {
    float* values;        // one side's distances, +infinity where none (or the other side)
    int strideX, strideY; // of the block's other two axes (its rows have stride 1)
    float h, background;  // the voxel size; values past the background are +infinity
    float tolerance;      // a value that moves by less is left as it was
    int reach;            // 1: first-order stencils, 2: second order where it is upwind
};

// Solves the upwind equations at the lanes of the row starting at block index b that are
// set in `lanes` (bit z for the voxel at b + z), from the values around them as they stand,
// and writes the values that moved by more than the tolerance. Returns those lanes.
unsigned relaxRow(const RowBlock& block, int b, unsigned lanes);

// relaxRow's way for this CPU, to call directly: a solve relaxes hundreds of thousands of
// rows, and choosing the way at each of them would cost two calls instead of one.
using RowRelaxer = unsigned (*)(const RowBlock& block, int b, unsigned lanes);
RowRelaxer rowRelaxer();

namespace detail {
// The two ways relaxRow has of doing it (the same values, to the bit): four lanes at a time,
// twice, on any CPU, and eight at once with AVX2 (hasAvx2(); elsewhere the four-lane way).
unsigned relaxRowIn4s(const RowBlock& block, int b, unsigned lanes);
unsigned relaxRowIn8s(const RowBlock& block, int b, unsigned lanes);
bool hasAvx2();
} // namespace detail

} // namespace sweepers::upwind
