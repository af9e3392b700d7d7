// SPDX-License-Identifier: Apache-2.0
// Grid-resolution studies: one stroke script applied at a voxel size with a numerical
// variant, measured against the exact reference of the same history (reference.h): how far
// the result's surface lies from the true one, how many voxels are on the wrong side, the
// volume, area and topology, and what the run cost.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "levelset/advect.h"
#include "mesh/triangle_mesh.h"
#include "sculpt/sculptor.h"
#include "study/reference.h"

namespace sweepers {

enum class StudyVariant { Corrected, Trilinear, Cubic, PerSubStep, FirstOrder };

// corrected, trilinear, cubic, per-substep, first-order.
std::string variantName(StudyVariant v);
std::optional<StudyVariant> parseVariant(const std::string& name);
// Every variant's name, in that order, joined by ", " (for messages and help).
std::string variantNames();
// The engine's options for a variant: the default engine (corrected trilinear sampling of
// the composed inverse, second-order fast marching), plain trilinear sampling (the thesis's
// 5.3.2), the monotone cubic of appendix C.1, one resample per sub-step (5.3.4), or
// first-order fast marching.
AdvectOptions variantOptions(StudyVariant v);

// Distances between the result's surface and the reference's, both ways: from every vertex
// of the result's mesh to the reference's crossing along the vertex normal, and from the
// reference's crossings on the edges between active voxels to the grid's surface (the
// grid's interpolated distance there).
struct InterfaceError {
    double mean = 0.0, rms = 0.0, max = 0.0; // world units
    std::size_t samples = 0;
    // Mesh vertices with no reference crossing within kSearchVoxels along their normal:
    // counted at that distance (a lower bound of their error).
    std::size_t unmatched = 0;
    std::size_t signFlips = 0; // active voxels on the other side of the reference surface
    // The volume inside the result's mesh, and inside the same mesh with every vertex moved
    // to its reference crossing (unmatched vertices stay): the reference's volume on the
    // result's own tessellation. Their difference is the signed volume between the two
    // surfaces, in which the tessellation's error of the shape cancels.
    double meshVolume = 0.0, referenceVolume = 0.0;
    double volumeError() const { return meshVolume - referenceVolume; }
    static constexpr double kSearchVoxels = 3.0;
    // What measuring took, phase by phase (seconds): the reference's sign at every active
    // voxel, its crossings on the edges between them, and its crossings along the mesh's
    // vertex normals; and how many crossings and vertices there were.
    struct Phases {
        double voxels = 0.0, crossings = 0.0, vertices = 0.0;
        std::size_t crossingCount = 0, vertexCount = 0;
    } phases;
};
InterfaceError interfaceError(const Grid& grid, const TriangleMesh& mesh,
                              const ExactReference& reference, Interrupter* interrupter = nullptr);

struct StudyRow {
    std::string script; // the script's name in a study of several (its file's stem)
    std::string variant;
    double voxelSize = 0.0;
    double wallSeconds = 0.0, advectSeconds = 0.0, renormSeconds = 0.0, meshSeconds = 0.0;
    // After the run: measuring its grid (volume, area, topology) and its error against the
    // exact reference, which wallSeconds leaves out.
    double measureSeconds = 0.0;
    double gridMeasureSeconds = 0.0; // of it, the grid's volume, area and topology
    // The whole run as a job sees it: its start built, sculpted, measured and its files
    // written (0 where only sculpted and measured).
    double runSeconds = 0.0;
    // Peak resident memory during the run, its start grid included, and measuring and
    // writing its files where the run wrote them (the process's peak so far where the
    // kernel cannot restart the count).
    double peakRssMb = 0.0;
    std::size_t activeVoxels = 0;
    double volume = 0.0, volumeChangePct = 0.0, area = 0.0;
    int euler = 0, genus = 0;
    std::size_t components = 0;
    // The exact shape's topology: the start's, since every sub-step is a fold-over-free
    // diffeomorphism of space (measured on the start grid). Where the result's differs, the
    // grid changed the topology (a feature thinner than it resolves).
    int referenceEuler = 0, referenceGenus = 0;
    std::size_t referenceComponents = 0;
    // False when a stroke tears space (a pinch or a strangle): the exact topology is then
    // not the start's, and the study does not claim one.
    bool referenceTopologyKnown = true;
    InterfaceError error;
    // Observed order of the RMS error against the next coarser run of the same variant
    // (NaN for the coarsest): p = log(e_coarse / e_fine) / log(h_coarse / h_fine).
    double orderRms = std::numeric_limits<double>::quiet_NaN();
    // The same for the size of the volume error, |error.volumeError()|.
    double orderVolume = std::numeric_limits<double>::quiet_NaN();
    std::string failure; // why the run failed; empty when it ran
    // Where the run ran: the machine's name and the worker threads it had.
    std::string host;
    int threads = 0;
};

// A run's result: the sculpted grid, its welded mesh and its row.
struct StudyRun {
    GridPtr grid;
    TriangleMesh mesh;
    StudyRow row;
};

// Applies `strokes` to `start` (which the run takes over) with the variant's options and
// measures the result against the exact reference built from `startShape` and the history
// the run applied. `progress` sees segments done and in all.
StudyRun runStudyCase(GridPtr start, const std::vector<Stroke>& strokes,
                      const ExactReference::StartFunction& startShape, StudyVariant variant,
                      Interrupter* interrupter = nullptr, const Progress& progress = {});

// Fills orderRms and orderVolume of every row from the next coarser row of its script and
// variant (failed rows and rows without a coarser one get NaN).
void fillOrders(std::vector<StudyRow>& rows);

} // namespace sweepers
