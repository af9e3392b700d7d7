// SPDX-License-Identifier: Apache-2.0
#include "python/shape.h"

#include <openvdb/tools/Interpolation.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "io/mesh_file.h"
#include "io/start_grid.h"
#include "io/vdb_file.h"
#include "mesh/marching_cubes.h"

namespace sweepers::python {

namespace {

// The engine's values at many points, in parallel: each range of points gets its own
// evaluator, `make()` (a sampler's accessor caches nodes: one per thread's range, not one
// per point), called as `at(i)` for each point.
template <typename Make> std::vector<double> forEachPoint(std::size_t n, const Make& make) {
    std::vector<double> out(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& r) {
        const auto at = make();
        for (std::size_t i = r.begin(); i != r.end(); ++i)
            out[i] = at(i);
    });
    return out;
}

} // namespace

Shape::Shape(std::shared_ptr<const Grid> grid, ExactReference::StartFunction start, History history)
    : grid_(std::move(grid)), start_(std::move(start)), history_(std::move(history)) {}

LevelSetMeasures Shape::measures() const {
    return measureLevelSet(*grid_);
}

TriangleMesh Shape::mesh() const {
    return meshLevelSet(*grid_);
}

std::vector<double> Shape::sample(const std::vector<Eigen::Vector3d>& points) const {
    return forEachPoint(points.size(), [&] {
        return [&, acc = grid_->getConstAccessor()](std::size_t i) {
            const openvdb::tools::GridSampler<Grid::ConstAccessor, openvdb::tools::BoxSampler>
                sampler(acc, grid_->transform());
            return double(sampler.wsSample(toVdb(points[i])));
        };
    });
}

ExactReference Shape::reference() const {
    ExactReference reference(start_);
    for (const auto& d : history_) {
        // A smooth dab deforms nothing: its velocity was the surface's own curvature.
        if (!d) throw std::invalid_argument("the history smooths: no exact shape stands behind it");
        reference.append(d);
    }
    return reference;
}

std::vector<double> Shape::exactValue(const std::vector<Eigen::Vector3d>& points) const {
    const ExactReference exact = reference();
    return forEachPoint(points.size(),
                        [&] { return [&](std::size_t i) { return exact.value(points[i]); }; });
}

std::vector<double> Shape::exactDistance(const std::vector<Eigen::Vector3d>& points) const {
    const ExactReference exact = reference();
    return forEachPoint(points.size(), [&] {
        return [&](std::size_t i) {
            const Eigen::Vector3d& x = points[i];
            const double value = exact.value(x);
            // The gradient by central differences, a step small against any tool or voxel and
            // large against the rounding of x's coordinates.
            const double step = 1e-6 * std::max(1.0, x.cwiseAbs().maxCoeff());
            Eigen::Vector3d gradient;
            for (int a = 0; a < 3; ++a) {
                Eigen::Vector3d e = Eigen::Vector3d::Zero();
                e[a] = step;
                gradient[a] = (exact.value(x + e) - exact.value(x - e)) / (2.0 * step);
            }
            // Where the gradient vanishes (a medial point, such as a sphere's centre) there is
            // no direction to the surface: the value itself.
            const double norm = gradient.norm();
            return norm > 1e-9 ? value / norm : value;
        };
    });
}

std::string Shape::vdbBytes() const {
    return levelSetStream(*grid_);
}

void Shape::save(const std::string& path, bool half) const {
    if (isMeshPath(path)) {
        if (half)
            throw std::invalid_argument("half: only a .vdb is written at half precision, not " +
                                        path);
        writeMesh(mesh(), path);
        return;
    }
    LevelSetWriteOptions options;
    options.half = half;
    writeLevelSet(*grid_, path, options);
}

Shape applyScript(const StrokeScript& script, const std::string& baseDir, double voxelSize,
                  Interrupter* interrupter, const Progress& progress) {
    GridPtr start = makeStartGrid(script, baseDir, voxelSize, interrupter);
    ExactReference::StartFunction exact = exactStart(script, start);
    AdvectOptions options;
    options.interrupter = interrupter;
    Sculptor sculptor(std::move(start), options);
    History history;
    applyStrokes(sculptor, script.strokes, progress, {}, &history);
    return Shape(sculptor.gridPtr(), std::move(exact), std::move(history));
}

namespace {

// The document of a start: a VDB start keeps its file's voxel size, which the script then
// says, so that it replays (the modeler's Document::open does the same).
Document startDocument(StrokeScript script, const std::string& baseDir, Interrupter* interrupter) {
    GridPtr start = makeStartGrid(script, baseDir, 0.0, interrupter);
    if (script.start.kind == StartShape::Kind::Vdb) {
        script.grid.voxelSize = start->voxelSize()[0];
        script.grid.halfWidth = halfWidthOf(*start);
        script.grid.voxelSizeGiven = script.grid.halfWidthGiven = true;
    }
    return Document(std::move(script), baseDir, {}, std::move(start), interrupter);
}

} // namespace

Session::Session(StrokeScript script, const std::string& baseDir, Interrupter* interrupter)
    : baseDir_(baseDir), document_(startDocument(std::move(script), baseDir, interrupter)) {
    // The start as the document made it: a second grid only for a sampled start.
    const StrokeScript& s = document_.script();
    start_ = s.start.kind == StartShape::Kind::Sphere ? exactStart(s, nullptr)
                                                      : exactStart(s, document_.grid().deepCopy());
}

void Session::apply(const std::vector<Stroke>& strokes, Interrupter* interrupter,
                    const Progress& progress) {
    std::size_t total = 0, done = 0;
    for (const Stroke& s : strokes)
        total += segmentCount(s, document_.grid().voxelSize()[0]);
    std::vector<History> applied;
    document_.setInterrupter(interrupter);
    try {
        document_.beginEdit();
        for (const Stroke& stroke : strokes) {
            applied.emplace_back();
            document_.applyStroke(stroke, [&](const SegmentReport& r) {
                applied.back().push_back(r.step.deformation);
                if (progress) progress(++done, total);
                // A stop asked for by the report (Python's callback raised) takes the call back
                // even after the last segment, when the engine polls no more.
                pollInterrupt(interrupter);
            });
        }
        document_.endEdit();
    } catch (const Cancelled&) {
        // The document put the grid back to where the edit began (Document::cancellable):
        // every stroke of this call is taken back.
        document_.setInterrupter(nullptr);
        throw;
    } catch (...) {
        // Any other failure: the strokes finished before it are one edit, taken back.
        const bool partly = applied.size() > 1;
        document_.endEdit();
        if (partly) document_.undo();
        document_.setInterrupter(nullptr);
        throw;
    }
    document_.setInterrupter(nullptr);
    history_.insert(history_.end(), applied.begin(), applied.end());
    undone_.clear();
}

bool Session::undo() {
    if (!document_.canUndo()) return false;
    const std::size_t before = document_.script().strokes.size();
    document_.undo();
    const std::size_t after = document_.script().strokes.size();
    undone_.insert(undone_.end(), history_.begin() + std::ptrdiff_t(after),
                   history_.begin() + std::ptrdiff_t(before));
    history_.resize(after);
    return true;
}

bool Session::redo() {
    if (!document_.canRedo()) return false;
    const std::size_t before = document_.script().strokes.size();
    document_.redo();
    const std::size_t added = document_.script().strokes.size() - before;
    // The last undone step is the one redone: its strokes are at the end of undone_.
    const auto from = undone_.end() - std::ptrdiff_t(added);
    history_.insert(history_.end(), from, undone_.end());
    undone_.erase(from, undone_.end());
    return true;
}

Session::Turn::Turn(const Session& session) : session_(session) {
    if (session.holder_.load() == std::this_thread::get_id())
        throw std::runtime_error("the Sculptor is busy with a call on this thread (a progress "
                                 "callback cannot use the Sculptor it reports on)");
    lock_ = std::unique_lock<std::mutex>(session.busy_);
    session.holder_.store(std::this_thread::get_id());
}

Session::Turn::~Turn() {
    session_.holder_.store(std::thread::id());
}

StrokeScript Session::script() const {
    return withAbsoluteFiles(document_.script(), baseDir_);
}

History Session::allHistory() const {
    History all;
    for (const History& h : history_)
        all.insert(all.end(), h.begin(), h.end());
    return all;
}

Shape Session::shape() const {
    return Shape(document_.grid().deepCopy(), start_, allHistory());
}

Shape Session::view() const {
    // Not owned: the session's grid, for as long as the call that asked for it.
    return Shape(std::shared_ptr<const Grid>(std::shared_ptr<const Grid>(), &document_.grid()),
                 start_, allHistory());
}

} // namespace sweepers::python
