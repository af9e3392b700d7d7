// SPDX-License-Identifier: Apache-2.0
// Semi-Lagrangian advection of a level set through one deformation (thesis 5.3.3): a
// sweep segment, a swirl ring, an inflation.
//
// The new value at a voxel x is the old grid sampled at the deformation's inverse map
// f^-1(x), composed from all inverse sub-steps before a single sample (trilinear, or the
// monotone cubic of appendix C.1): the thesis's algorithm (5.3.4) resamples after every
// sub-step, which blurs the shape s times; that variant is kept as an option so the
// difference can be measured.
//
// Only the affected box is touched. Before sampling, the band is grown where the surface
// moves: the interface voxels are forward-mapped and the band is activated around their
// images, so the new surface always lies on active voxels. Strongly compressing motions
// could send the pre-image of a voxel next to the new surface outside the old band, where
// the old grid only holds +-background: the source band is then widened first (by fast
// marching, inside the affected box) to cover the stretch of the inverse map, measured on
// the forward-mapped interface (unless the deformation's own bound on it asks for nothing),
// around the leaves where it was measured. After sampling, inactive signs are re-derived by
// flood fill and the box is renormalized.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "deform/step_deformation.h"
#include "levelset/interrupt.h"
#include "levelset/renormalize.h"
#include "levelset/resample.h"
#include "vdb/vdb.h"

namespace sweepers {

struct AdvectOptions {
    bool resampleEachSubStep = false; // the thesis's 5.3.4 variant
    Sampling sampling = Sampling::Corrected;
    UpwindOrder renormalization = UpwindOrder::Second;
    bool renormalize = true;
    Interrupter* interrupter = nullptr; // polled per leaf range; throws Cancelled
};

// The phases of a segment's step, as AdvectStats::phases lists them.
inline constexpr std::array<const char*, 8> kAdvectPhases{
    "find_interface", "map_images", "widen_source", "grow_band",
    "sample",         "fix_signs",  "renormalize",  "report"};

struct AdvectStats {
    int subSteps = 0;
    std::size_t interfaceVoxels = 0; // forward-mapped to grow the band
    std::size_t sampledVoxels = 0;
    double widenedTo = 0.0;         // band half-width used for sampling, in voxels
    int sampledReach = 0;           // how far around the images of the surface the band was sampled
    std::size_t stretchSamples = 0; // interface voxels where the stretch was measured
    // The work, counted: what a segment reads and writes follows the brush, never the
    // size of the model (the same stroke counts the same on a grid holding more shapes).
    std::size_t voxelsVisited = 0; // scanned for the interface, sampled, marched over
    std::size_t leavesVisited = 0; // leaves those loops went through
    std::size_t leavesCopied = 0;  // copied as the sampling source, or sampled beside the grid
    std::size_t leavesWidened = 0; // of those, whose band a stretch asked to be widened
    std::size_t leavesFlooded = 0; // whose inactive signs were re-derived
    std::size_t tornVoxels = 0;    // inside voxels beyond the band that a tear opened
    std::size_t filledVoxels = 0;  // voxels beyond the band an inflation's filled ball reached
    double growSeconds = 0.0, sampleSeconds = 0.0, renormalizeSeconds = 0.0;
    // Each phase of SegmentAdvector, in the order of kAdvectPhases (the first four make band
    // growth, the next two sampling, the seventh renormalization): its wall time, and the
    // time one thread worked in it while the others waited (vdb/parallel.h), what more
    // cores cannot shorten.
    struct PhaseTime {
        double seconds = 0.0, serialSeconds = 0.0;
    };
    std::array<PhaseTime, 8> phases{};
    openvdb::CoordBBox touched; // index box whose values may have changed
};

// The step of one segment, as a class whose phases run in order:
//   findInterface  the interface voxels of the leaves the deformation moves;
//   mapImages      their images, forward-mapped sub-step by sub-step, and the stretch of
//                  the inverse map measured at some of them;
//   widenSource    where the stretch asks, copies of the old band widened by fast marching;
//   growBand       the band switched on around the images;
//   sample         every moving leaf's voxels sampled at their pre-images (5.3.3);
//   fixSigns       the inactive signs re-derived in the leaves sampling rewrote;
//   renormalize    the changed voxels given their distances again (fast marching);
//   report         the boxes of what changed, for the mesh.
// A Sculptor keeps one for all its segments, so the scratch the phases fill (the interface
// list, each thread's images and mapped points, the staged values) keeps its storage from
// one segment to the next instead of being allocated again each time.
//
// With `changed`, run() gives boxes (each within a voxel of one leaf) that hold every voxel
// active before or after the segment whose value or active state changed: what a mesh kept
// up to date reads again (SurfaceMesher::update). Inactive values (the signs the flood
// re-derives, tiles) are left out: the band is valid before and after, and a valid band has
// no inactive voxel within two voxels of its surface, as far as the mesh of a leaf reads.
class SegmentAdvector {
  public:
    SegmentAdvector();
    ~SegmentAdvector();
    SegmentAdvector(SegmentAdvector&&) noexcept;
    SegmentAdvector& operator=(SegmentAdvector&&) noexcept;

    AdvectStats run(Grid& grid, const StepDeformation& segment, const AdvectOptions& options = {},
                    std::vector<openvdb::CoordBBox>* changed = nullptr);

    // How many times one of its buffers (the interface list and its per-leaf counts, the
    // stretch samples, the images, the staged values) had to grow so far: a long drag's
    // segments, once the first few have sized them, should need no more.
    std::size_t scratchGrowths() const;

  private:
    struct Work;
    std::unique_ptr<Work> work_;
};

// One segment on its own (a SegmentAdvector made for it).
AdvectStats advectSegment(Grid& grid, const StepDeformation& segment,
                          const AdvectOptions& options = {},
                          std::vector<openvdb::CoordBBox>* changed = nullptr);

// The index box whose voxels advectSegment(grid, segment) may change (what undo saves).
openvdb::CoordBBox changedRegion(const Grid& grid, const StepDeformation& segment);

} // namespace sweepers
