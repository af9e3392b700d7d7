// SPDX-License-Identifier: Apache-2.0
#include "study/study.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <openvdb/tools/Interpolation.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/memory.h"
#include "core/stopwatch.h"
#include "levelset/measure.h"
#include "mesh/marching_cubes.h"

namespace sweepers {

namespace {

struct Tally {
    double sum = 0.0, sumSq = 0.0, max = 0.0;
    std::size_t count = 0, unmatched = 0, flips = 0;
    void add(double e) {
        sum += e;
        sumSq += e * e;
        max = std::max(max, e);
        ++count;
    }
    void merge(const Tally& o) {
        sum += o.sum;
        sumSq += o.sumSq;
        max = std::max(max, o.max);
        count += o.count;
        unmatched += o.unmatched;
        flips += o.flips;
    }
};

} // namespace

std::string variantName(StudyVariant v) {
    switch (v) {
    case StudyVariant::Corrected:
        return "corrected";
    case StudyVariant::Trilinear:
        return "trilinear";
    case StudyVariant::Cubic:
        return "cubic";
    case StudyVariant::PerSubStep:
        return "per-substep";
    case StudyVariant::FirstOrder:
        return "first-order";
    }
    return "";
}

namespace {

constexpr StudyVariant kVariants[] = {StudyVariant::Corrected, StudyVariant::Trilinear,
                                      StudyVariant::Cubic, StudyVariant::PerSubStep,
                                      StudyVariant::FirstOrder};

} // namespace

std::optional<StudyVariant> parseVariant(const std::string& name) {
    for (StudyVariant v : kVariants)
        if (variantName(v) == name) return v;
    return std::nullopt;
}

std::string variantNames() {
    std::string names;
    for (StudyVariant v : kVariants)
        names += (names.empty() ? "" : ", ") + variantName(v);
    return names;
}

AdvectOptions variantOptions(StudyVariant v) {
    AdvectOptions o;
    o.sampling = v == StudyVariant::Cubic       ? Sampling::MonotoneCubic
                 : v == StudyVariant::Trilinear ? Sampling::Trilinear
                                                : Sampling::Corrected;
    o.resampleEachSubStep = v == StudyVariant::PerSubStep;
    o.renormalization = v == StudyVariant::FirstOrder ? UpwindOrder::First : UpwindOrder::Second;
    return o;
}

InterfaceError interfaceError(const Grid& grid, const TriangleMesh& mesh,
                              const ExactReference& reference, Interrupter* interrupter) {
    const double h = grid.voxelSize()[0];
    const double tolerance = 1e-6 * h;
    tbb::enumerable_thread_specific<Tally> tallies;

    // Grid to reference: the reference's sign at every active voxel (sign flips), and its
    // crossings on the edges between active voxels, whose distance to the grid's surface is
    // the grid's interpolated value there (a distance near the surface once renormalized).
    std::vector<const LeafNode*> leaves;
    for (auto it = grid.tree().cbeginLeaf(); it; ++it)
        leaves.push_back(&*it);
    GridPtr signs = grid.deepCopy(); // the reference's values on the grid's active voxels
    std::vector<LeafNode*> signLeaves;
    for (auto it = signs->tree().beginLeaf(); it; ++it)
        signLeaves.push_back(&*it);
    // The history as a leaf's points see it (the identity elsewhere skipped, exactly), with
    // the next voxel along each axis: the edges the crossings are looked for on.
    const auto nearLeaf = [&](const LeafNode& leaf) {
        const openvdb::CoordBBox b = leaf.getNodeBoundingBox();
        return reference.near(Box(toEigen(grid.indexToWorld(b.min())),
                                  toEigen(grid.indexToWorld(b.max().offsetBy(1)))));
    };
    InterfaceError e;
    auto phaseStart = Clock::now();
    // Ends a phase: its time into `seconds`.
    const auto endPhase = [&](double& seconds) {
        seconds = secondsSince(phaseStart);
        phaseStart = Clock::now();
    };
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, signLeaves.size()), [&](const auto& r) {
        pollInterrupt(interrupter);
        Tally& t = tallies.local();
        for (std::size_t l = r.begin(); l != r.end(); ++l) {
            const ExactReference::Near near = nearLeaf(*signLeaves[l]);
            for (auto it = signLeaves[l]->beginValueOn(); it; ++it) {
                const bool inside = *it < 0.0f;
                const double v = near.value(toEigen(grid.indexToWorld(it.getCoord())));
                if ((v < 0.0) != inside) ++t.flips;
                // Only the sign is kept; exact zeros count as outside, as in the grid.
                it.setValue(v < 0.0 ? -1.0f : 1.0f);
            }
        }
    });
    endPhase(e.phases.voxels);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& r) {
        pollInterrupt(interrupter);
        Tally& t = tallies.local();
        const auto refAcc = signs->getConstAccessor();
        const Grid::ConstAccessor acc = grid.getConstAccessor(); // the sampler keeps a reference
        const openvdb::tools::GridSampler<Grid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
            acc, grid.transform());
        for (std::size_t l = r.begin(); l != r.end(); ++l) {
            const ExactReference::Near near = nearLeaf(*leaves[l]);
            for (auto it = leaves[l]->cbeginValueOn(); it; ++it) {
                const openvdb::Coord ijk = it.getCoord();
                const bool inside = refAcc.getValue(ijk) < 0.0f;
                for (int a = 0; a < 3; ++a) {
                    openvdb::Coord next = ijk;
                    next[a] += 1;
                    float other;
                    if (!refAcc.probeValue(next, other) || (other < 0.0f) == inside) continue;
                    const auto c = near.crossing(toEigen(grid.indexToWorld(ijk)),
                                                 toEigen(grid.indexToWorld(next)), tolerance);
                    if (c) t.add(std::abs(double(sampler.wsSample(toVdb(*c)))));
                }
            }
        }
    });
    endPhase(e.phases.crossings);
    for (const Tally& t : tallies)
        e.phases.crossingCount += t.count;
    e.phases.vertexCount = mesh.positions.size();

    // Mesh to reference: the nearest bracket along the normal that holds a crossing.
    std::vector<Eigen::Vector3d> onReference(mesh.positions.size());
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, mesh.positions.size(), 256), [&](const auto& r) {
            pollInterrupt(interrupter);
            Tally& t = tallies.local();
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const Eigen::Vector3d p = mesh.positions[i].cast<double>();
                const Eigen::Vector3d n = i < mesh.normals.size()
                                              ? mesh.normals[i].cast<double>().normalized()
                                              : Eigen::Vector3d::UnitX();
                const double most = InterfaceError::kSearchVoxels * h;
                const ExactReference::Near near =
                    reference.near(Box(p.array() - most, p.array() + most));
                std::optional<Eigen::Vector3d> c;
                for (int reach = 1; reach <= int(InterfaceError::kSearchVoxels) && !c; ++reach)
                    c = near.crossing(p - reach * h * n, p + reach * h * n, tolerance);
                onReference[i] = c ? *c : p;
                if (c) {
                    t.add((*c - p).norm());
                } else {
                    t.add(InterfaceError::kSearchVoxels * h);
                    ++t.unmatched;
                }
            }
        });
    endPhase(e.phases.vertices);

    Tally all;
    for (const Tally& t : tallies)
        all.merge(t);
    // Volumes by the divergence theorem, a tetrahedron from the origin per triangle; the
    // mesh's orientation gives both the same sign.
    for (const Eigen::Vector3i& tri : mesh.triangles) {
        const auto at = [&](int k) { return mesh.positions[std::size_t(tri[k])].cast<double>(); };
        e.meshVolume += at(0).dot(at(1).cross(at(2))) / 6.0;
        e.referenceVolume +=
            onReference[std::size_t(tri[0])].dot(
                onReference[std::size_t(tri[1])].cross(onReference[std::size_t(tri[2])])) /
            6.0;
    }
    if (e.meshVolume < 0.0) {
        e.meshVolume = -e.meshVolume;
        e.referenceVolume = -e.referenceVolume;
    }
    e.samples = all.count;
    e.unmatched = all.unmatched;
    e.signFlips = all.flips;
    if (all.count > 0) {
        e.mean = all.sum / double(all.count);
        e.rms = std::sqrt(all.sumSq / double(all.count));
        e.max = all.max;
    }
    return e;
}

StudyRun runStudyCase(GridPtr start, const std::vector<Stroke>& strokes,
                      const ExactReference::StartFunction& startShape, StudyVariant variant,
                      Interrupter* interrupter, const Progress& progress) {
    // The run's own peak memory, not the process's: a finer run before it (or a variant
    // that needs more at the same size) would hide it.
    restartPeakResident();
    StudyRun run;
    StudyRow& row = run.row;
    row.variant = variantName(variant);
    row.voxelSize = start->voxelSize()[0];
    const LevelSetMeasures before = measureLevelSet(*start);
    row.referenceEuler = before.eulerCharacteristic;
    row.referenceGenus = before.genus;
    row.referenceComponents = before.components;
    for (const Stroke& s : strokes)
        if (std::holds_alternative<PinchStroke>(s) || std::holds_alternative<StrangleStroke>(s))
            row.referenceTopologyKnown = false;

    AdvectOptions options = variantOptions(variant);
    options.interrupter = interrupter;
    Sculptor sculptor(std::move(start), options);
    const auto t0 = Clock::now();
    History history;
    const std::vector<SegmentReport> reports =
        applyStrokes(sculptor, strokes, progress, {}, &history);
    for (const SegmentReport& r : reports) {
        row.advectSeconds += r.advectSeconds();
        row.renormSeconds += r.stats.renormalizeSeconds;
    }
    // A smooth dab is no deformation (its report has none): no exact shape stands behind a
    // history that smooths, and its error columns stay NaN.
    const bool exact =
        std::all_of(history.begin(), history.end(), [](const auto& d) { return bool(d); });
    ExactReference reference(startShape);
    if (exact)
        for (auto& d : history)
            reference.append(std::move(d));
    const auto t1 = Clock::now();
    SurfaceMesher mesher;
    mesher.rebuild(sculptor.grid(), interrupter);
    run.mesh = mesher.weld();
    row.meshSeconds = secondsSince(t1);
    row.wallSeconds = secondsSince(t0);
    row.peakRssMb = peakResidentBytes() / double(1 << 20);

    run.grid = sculptor.gridPtr();
    const auto t2 = Clock::now();
    const LevelSetMeasures m = measureLevelSet(*run.grid);
    row.activeVoxels = m.activeVoxels;
    row.volume = m.volume;
    row.volumeChangePct = 100.0 * (m.volume - before.volume) / before.volume;
    row.area = m.area;
    row.euler = m.eulerCharacteristic;
    row.genus = m.genus;
    row.components = m.components;
    row.gridMeasureSeconds = secondsSince(t2);
    if (exact) {
        row.error = interfaceError(*run.grid, run.mesh, reference, interrupter);
    } else {
        const double none = std::numeric_limits<double>::quiet_NaN();
        row.error.mean = row.error.rms = row.error.max = none;
        row.error.meshVolume = row.error.referenceVolume = none;
        row.referenceTopologyKnown = false;
    }
    row.measureSeconds = secondsSince(t2);
    return run;
}

void fillOrders(std::vector<StudyRow>& rows) {
    std::map<std::pair<std::string, std::string>, std::vector<StudyRow*>> byVariant;
    for (StudyRow& r : rows) {
        r.orderRms = r.orderVolume = std::numeric_limits<double>::quiet_NaN();
        if (r.failure.empty()) byVariant[{r.script, r.variant}].push_back(&r);
    }
    // p = log(e_coarse / e_fine) / log(h_coarse / h_fine)
    const auto order = [](double coarseError, double fineError, double coarseH, double fineH) {
        if (!(coarseError > 0.0 && fineError > 0.0 && coarseH > fineH))
            return std::numeric_limits<double>::quiet_NaN();
        return std::log(coarseError / fineError) / std::log(coarseH / fineH);
    };
    for (auto& [name, runs] : byVariant) {
        std::sort(runs.begin(), runs.end(),
                  [](const StudyRow* a, const StudyRow* b) { return a->voxelSize > b->voxelSize; });
        for (std::size_t k = 1; k < runs.size(); ++k) {
            const StudyRow& coarse = *runs[k - 1];
            StudyRow& fine = *runs[k];
            fine.orderRms =
                order(coarse.error.rms, fine.error.rms, coarse.voxelSize, fine.voxelSize);
            fine.orderVolume =
                order(std::abs(coarse.error.volumeError()), std::abs(fine.error.volumeError()),
                      coarse.voxelSize, fine.voxelSize);
        }
    }
}

} // namespace sweepers
