// SPDX-License-Identifier: Apache-2.0
#include "document/document.h"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "core/format.h"
#include "io/atomic_file.h"
#include "io/mesh_file.h"
#include "io/start_grid.h"
#include "io/vdb_file.h"
#include "levelset/create.h"

namespace sweepers {

Document::Document(StrokeScript script, const std::string& scriptDir, const Progress& progress,
                   GridPtr start, Interrupter* interrupter)
    : Document(std::move(script), scriptDir, progress, std::move(start), interrupter, 0) {}

Document::Document(StrokeScript script, const std::string& scriptDir, const Progress& progress,
                   GridPtr start, Interrupter* interrupter, std::size_t done)
    : script_(std::move(script)), scriptDir_(scriptDir),
      sculptor_(start ? std::move(start) : makeStartGrid(script_, scriptDir_, 0.0, interrupter)) {
    const double h = sculptor_.grid().voxelSize()[0];
    if (script_.start.kind == StartShape::Kind::Vdb &&
        std::abs(h - script_.grid.voxelSize) > 1e-9 * script_.grid.voxelSize)
        throw std::runtime_error(
            "the document starts from a VDB file at voxel size " + formatNumber(h) +
            "; it cannot be replayed at another voxel size (start from a sphere or a mesh)");
    if (done > script_.strokes.size()) throw std::logic_error("more strokes done than there are");
    sculptor_.setInterrupter(interrupter);
    applyStrokes(
        sculptor_,
        std::vector<Stroke>(script_.strokes.begin() + std::ptrdiff_t(done), script_.strokes.end()),
        progress);
    markAsDocument(sculptor_.grid());
    sculptor_.startMeshing();
    sculptor_.setInterrupter(nullptr);
}

StrokeScript Document::sphereScript(double voxelSize) {
    StrokeScript s;
    s.grid.voxelSize = voxelSize;
    s.grid.halfWidth = 3.0;
    s.start.kind = StartShape::Kind::Sphere;
    s.start.radius = 1.0;
    return s;
}

Document Document::resume(StrokeScript script, const std::string& scriptDir, GridPtr grid,
                          std::size_t done, const Progress& progress, Interrupter* interrupter) {
    return Document(std::move(script), scriptDir, progress, std::move(grid), interrupter, done);
}

Document Document::open(const std::string& path, double meshVoxelSize, const Progress& progress,
                        Interrupter* interrupter) {
    const bool isScript = path.size() >= 5 && path.compare(path.size() - 5, 5, ".json") == 0;
    if (isScript)
        return Document(readStrokeScript(path), directoryOf(path), progress, nullptr, interrupter);
    if (isMeshPath(path)) {
        // A mesh becomes the start of a new script, at the given voxel size.
        StrokeScript s = sphereScript(meshVoxelSize);
        s.start.kind = StartShape::Kind::Mesh;
        s.start.file = std::filesystem::absolute(path).string();
        return Document(s, directoryOf(s.start.file), progress, nullptr, interrupter);
    }
    // A VDB: read once (a clear error for anything but a float level set); it is the start
    // of a new script.
    GridPtr g = readLevelSet(path);
    StrokeScript s;
    s.grid.voxelSize = g->voxelSize()[0];
    s.grid.halfWidth = halfWidthOf(*g);
    s.start.kind = StartShape::Kind::Vdb;
    s.start.file = std::filesystem::absolute(path).string();
    const std::string dir = directoryOf(s.start.file);
    return Document(std::move(s), dir, {}, std::move(g), interrupter);
}

void Document::beginStroke(const ToolSpec& tool, MirrorAxis mirror) {
    beginStroke(SweepStroke{mirror, {tool}});
}

void Document::beginStroke(const SweepStroke& start) {
    if (start.tools.size() != 1 || start.tools[0].path.size() != 1)
        throw std::invalid_argument("a stroke starts with one tool at one placement");
    beginEdit();
    current_ = start;
    inStroke_ = true;
}

void Document::beginEdit() {
    endEdit();
    applied_.clear();
    sculptor_.startRecording();
    inEdit_ = true;
}

template <typename Work> SegmentReport Document::cancellable(const Work& work) {
    try {
        SegmentReport r = work();
        r.stroke = script_.strokes.size() + applied_.size();
        modified_ = true;
        return r;
    } catch (const Cancelled&) {
        // The segment stopped half-way: the grid goes back to where the edit began.
        sculptor_.restoreRecording();
        sculptor_.stopRecording();
        applied_.clear();
        inEdit_ = inStroke_ = false;
        throw;
    }
}

SegmentReport Document::extendStroke(const Placement& next) {
    if (!inStroke_) throw std::logic_error("extendStroke outside a stroke");
    SweepStroke trial = current_;
    trial.tools[0].path.push_back(next);
    const Sweep sweep = toSweep(trial); // throws for a motion without a logarithm
    const std::size_t k = sweep.segmentCount() - 1;
    SegmentReport r = cancellable([&] { return sculptor_.applySegment(SweepSegment(sweep, k)); });
    r.segment = k;
    current_ = std::move(trial);
    return r;
}

SegmentReport Document::applyStroke(const Stroke& stroke,
                                    const std::function<void(const SegmentReport&)>& each) {
    if (!inEdit_ || inStroke_) throw std::logic_error("applyStroke outside an edit");
    SegmentReport last = cancellable([&] { return sculptor_.applyStroke(stroke, each); });
    applied_.push_back(stroke);
    return last;
}

void Document::endEdit() {
    finishEdit(/*newEdit=*/true);
}

void Document::finishEdit(bool newEdit) {
    if (!inEdit_) return;
    // A click without a drag changes nothing and is not kept.
    if (inStroke_ && current_.tools[0].path.size() >= 2) applied_.push_back(current_);
    inEdit_ = inStroke_ = false;
    LeafSnapshot before = sculptor_.stopRecording();
    if (applied_.empty()) return;
    script_.strokes.insert(script_.strokes.end(), applied_.begin(), applied_.end());
    undo_.push_back({std::move(applied_), std::move(before)});
    applied_.clear();
    if (listener_) listener_->appended(*this, undo_.back().strokes);
    // A new edit makes what was undone unreachable; a redo keeps the rest of it.
    if (newEdit) redo_.clear();
    trimToBudget();
}

// Puts an edit's snapshot back and returns the same edit holding the blocks as they were
// just before (so undo gives what redo needs, and the other way round).
Document::Edit Document::swapIn(Edit e) {
    Grid& grid = sculptor_.grid();
    LeafSnapshot current = LeafSnapshot::sameBlocks(grid, e.snapshot);
    e.snapshot.restore(grid);
    sculptor_.mesher().update(grid, e.snapshot.bounds());
    modified_ = true;
    return {std::move(e.strokes), std::move(current)};
}

void Document::undo() {
    endEdit();
    if (undoNeedsReplay()) {
        undoByReplay(replayTo(nullptr, 0));
        return;
    }
    if (undo_.empty()) return;
    Edit e = swapIn(std::move(undo_.back()));
    undo_.pop_back();
    script_.strokes.resize(script_.strokes.size() - e.strokes.size());
    redo_.push_back(std::move(e));
    if (listener_) listener_->truncated(*this, script_.strokes.size());
}

std::size_t Document::replayTarget() const {
    return dropped_.empty() ? script_.strokes.size() : script_.strokes.size() - dropped_.back();
}

GridPtr Document::replayTo(GridPtr grid, std::size_t done, const Progress& progress,
                           Interrupter* interrupter) const {
    const std::size_t target = replayTarget();
    if (done > target) throw std::logic_error("a replay from past its target");
    if (!grid) {
        grid = makeStartGrid(script_, scriptDir_, 0.0, interrupter);
        done = 0;
    }
    Sculptor replay(std::move(grid));
    replay.setInterrupter(interrupter);
    applyStrokes(replay,
                 std::vector<Stroke>(script_.strokes.begin() + std::ptrdiff_t(done),
                                     script_.strokes.begin() + std::ptrdiff_t(target)),
                 progress);
    return replay.gridPtr();
}

void Document::undoByReplay(GridPtr grid) {
    endEdit();
    if (!undoNeedsReplay()) throw std::logic_error("undoByReplay without an edit to undo so");
    const std::size_t target = replayTarget();
    Edit e;
    e.strokes.assign(script_.strokes.begin() + std::ptrdiff_t(target), script_.strokes.end());
    e.replay = true;
    dropped_.pop_back();
    markAsDocument(*grid);
    sculptor_.replaceGrid(std::move(grid));
    script_.strokes.resize(target);
    redo_.push_back(std::move(e));
    modified_ = true;
    if (listener_) listener_->truncated(*this, script_.strokes.size());
}

void Document::redo() {
    endEdit();
    if (redo_.empty()) return;
    if (redo_.back().replay) {
        // Undone by replay, so no blocks were kept: the strokes are applied again, as when
        // they were made (the same grid: the stroke step is deterministic).
        std::vector<Stroke> strokes = std::move(redo_.back().strokes);
        redo_.pop_back();
        beginEdit();
        for (const Stroke& stroke : strokes)
            applyStroke(stroke);
        finishEdit(/*newEdit=*/false);
        return;
    }
    Edit e = swapIn(std::move(redo_.back()));
    redo_.pop_back();
    script_.strokes.insert(script_.strokes.end(), e.strokes.begin(), e.strokes.end());
    undo_.push_back(std::move(e));
    if (listener_) listener_->appended(*this, undo_.back().strokes);
    trimToBudget();
}

std::size_t Document::undoBytes() const {
    std::size_t n = 0;
    for (const Edit& e : undo_)
        n += e.snapshot.bytes();
    for (const Edit& e : redo_)
        n += e.snapshot.bytes();
    return n;
}

void Document::setUndoBudget(std::size_t bytes) {
    budget_ = bytes;
    trimToBudget();
}

void Document::trimToBudget() {
    // The oldest edits give up their blocks first; they stay undoable, by replay.
    while (!undo_.empty() && undoBytes() > budget_) {
        dropped_.push_back(undo_.front().strokes.size());
        undo_.pop_front();
    }
}

void Document::saveVdb(const std::string& path, const LevelSetWriteOptions& options) {
    writeLevelSet(sculptor_.grid(), path, options);
}

void Document::saveScript(const std::string& path) {
    writeStrokeScript(withAbsoluteFiles(script_, scriptDir_), path);
}

Document Document::replayAt(StrokeScript script, const std::string& scriptDir, double voxelSize,
                            const Progress& progress, Interrupter* interrupter) {
    if (!(voxelSize > 0.0) || !std::isfinite(voxelSize))
        throw std::runtime_error("the voxel size must be a positive number");
    script.grid.voxelSize = voxelSize;
    return Document(std::move(script), scriptDir, progress, nullptr, interrupter);
}

} // namespace sweepers
