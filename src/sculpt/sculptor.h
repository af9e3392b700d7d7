// SPDX-License-Identifier: Apache-2.0
// The one stroke path: a Sculptor owns a level set, the mesh kept up to date with it, and
// the undo record of the edit in progress, and applies strokes to them segment by segment.
// The command line (applyStrokes) and the modeler's document both go through
// applySegment, so a recorded session replays to the same grid by construction.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include "levelset/advect.h"
#include "levelset/interrupt.h"
#include "levelset/leaf_snapshot.h"
#include "mesh/marching_cubes.h"
#include "sculpt/stroke.h"
#include "sculpt/stroke_plan.h"

namespace sweepers {

struct SegmentReport {
    std::size_t stroke = 0, segment = 0;
    // The step the segment applied, as planned (applyStroke; sculpt/stroke_plan.h): its
    // deformation is what an exact reference of the history composes.
    PlannedStep step;
    AdvectStats stats;
    double seconds = 0.0;     // advection, renormalization included
    double meshSeconds = 0.0; // incremental re-meshing of the touched leaves (when meshing)
    // The advection without renormalization: the band's growth and sampling, and the set-up
    // and clean-up around them (freeing the segment's masks and copies), which no stage of
    // AdvectStats times.
    double advectSeconds() const { return seconds - stats.renormalizeSeconds; }
    double meshSerialSeconds = 0.0; // of the re-meshing, on one thread while others waited
    // Work outside the advection's phases that kept its own serial clock (a smooth dab):
    // its wall time, and its time on one thread while the others waited.
    double otherSeconds = 0.0, otherSerialSeconds = 0.0;
    // The segment's serial time (vdb/parallel.h): each phase's, what runs around the
    // phases on one thread, and the re-meshing's.
    double serialSeconds() const {
        double phases = otherSeconds, serial = meshSerialSeconds + otherSerialSeconds;
        for (const AdvectStats::PhaseTime& p : stats.phases) {
            phases += p.seconds;
            serial += p.serialSeconds;
        }
        return serial + std::max(0.0, seconds - phases);
    }
    SmoothStats smooth; // of a smooth dab (scheme, voxels under the brush, work)
    std::size_t remeshedLeaves = 0;
    double meshVolume = 0.0; // enclosed volume of the mesh after the segment (applyStrokes,
                             // when meshing: it sums the whole mesh)
};

// Progress: (steps done, steps in all).
using Progress = std::function<void(std::size_t, std::size_t)>;

class Sculptor {
  public:
    explicit Sculptor(GridPtr grid, AdvectOptions options = {});

    Grid& grid() { return *grid_; }
    const Grid& grid() const { return *grid_; }
    GridPtr gridPtr() const { return grid_; }

    // Another grid (the same document rebuilt by replay), meshed whole when meshing.
    void replaceGrid(GridPtr grid);

    // Polled during every segment (and by whole-grid meshing); null: never stops. A
    // cancelled segment throws Cancelled with the grid half-advected: restore the recording
    // (or drop the grid).
    void setInterrupter(Interrupter* interrupter);
    Interrupter* interrupter() const { return options_.interrupter; }

    // How smooth dabs run (the reference explicit flow, for comparisons).
    void setSmoothOptions(const SmoothOptions& options) { smoothOptions_ = options; }

    // Keeps a marching-cubes mesh up to date after every segment (built now, whole).
    void startMeshing();
    bool meshing() const { return meshing_; }
    SurfaceMesher& mesher() { return mesher_; }
    const SurfaceMesher& mesher() const { return mesher_; }
    const SegmentAdvector& advector() const { return advector_; }

    // Undo: while recording, every block a segment may change is saved once, before it
    // changes. stopRecording hands the saved blocks over.
    void startRecording();
    LeafSnapshot stopRecording();
    // Puts the recorded blocks back (the grid as it was at startRecording) and re-meshes
    // them; the recording goes on, empty.
    void restoreRecording();

    // The stroke step: one deformation advected (band growth, sampling, renormalization),
    // then the touched leaves re-meshed.
    SegmentReport applySegment(const StepDeformation& deformation);
    // One dab of smoothing (levelset/smooth.h), recorded and re-meshed as a segment is; the
    // report has no deformation.
    SegmentReport applySmoothDab(const SmoothBrush& brush);
    // Every segment of a stroke, planned on the grid as it is now (a smooth stroke's dabs
    // each on the grid the one before left); `each` sees every
    // segment's report. Returns the last.
    SegmentReport applyStroke(const Stroke& stroke,
                              const std::function<void(const SegmentReport&)>& each = {});

  private:
    GridPtr grid_;
    AdvectOptions options_;
    SmoothOptions smoothOptions_;
    SegmentAdvector advector_; // one for every segment: its scratch is kept between them
    SurfaceMesher mesher_;
    bool meshing_ = false, recording_ = false;
    LeafSnapshot record_;
    std::vector<openvdb::CoordBBox> changed_; // what a segment changed, for the mesher
};

// The deformations a run applied, in order.
using History = std::vector<std::shared_ptr<const StepDeformation>>;

// Applies strokes in order, reporting every segment (stroke index and segment within it);
// `after` (if set) runs after each stroke with its index. The reports do not keep the
// deformations (a long script would hold them all): `history`, if set, receives them.
std::vector<SegmentReport> applyStrokes(Sculptor& sculptor, const std::vector<Stroke>& strokes,
                                        const Progress& progress = {},
                                        const std::function<void(std::size_t)>& after = {},
                                        History* history = nullptr);

} // namespace sweepers
