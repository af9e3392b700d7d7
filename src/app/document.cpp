#include "app/document.h"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "deform/step_deformation.h"
#include "deform/sweep.h"
#include "io/mesh_file.h"
#include "io/vdb_file.h"
#include "levelset/advect.h"
#include "levelset/level_set.h"

namespace sweepers {

Document::Document(StrokeScript script, const std::string& scriptDir, const Progress& progress,
                   GridPtr start)
    : script_(std::move(script)), scriptDir_(scriptDir), grid_(std::move(start)) {
    RunOptions options;
    if (!grid_) grid_ = makeStartGrid(script_, scriptDir_, options);
    if (script_.start.kind == StartShape::Kind::Vdb &&
        std::abs(grid_->voxelSize()[0] - script_.grid.voxelSize) > 1e-9 * script_.grid.voxelSize)
        throw std::runtime_error(
            "the document starts from a VDB file at voxel size " +
            std::to_string(grid_->voxelSize()[0]) +
            "; it cannot be replayed at another voxel size (start from a sphere or a mesh)");
    applyStrokes(*grid_, script_, options, progress);
    markAsDocument(*grid_);
    mesher_.rebuild(*grid_);
}

StrokeScript Document::sphereScript(double voxelSize) {
    StrokeScript s;
    s.grid.voxelSize = voxelSize;
    s.grid.halfWidth = 3.0;
    s.start.kind = StartShape::Kind::Sphere;
    s.start.radius = 1.0;
    return s;
}

Document Document::open(const std::string& path, double meshVoxelSize, const Progress& progress) {
    const bool isScript = path.size() >= 5 && path.compare(path.size() - 5, 5, ".json") == 0;
    if (isScript) return Document(readStrokeScript(path), directoryOf(path), progress);
    if (isMeshPath(path)) {
        // A mesh becomes the start of a new script, at the given voxel size.
        StrokeScript s = sphereScript(meshVoxelSize);
        s.start.kind = StartShape::Kind::Mesh;
        s.start.file = std::filesystem::absolute(path).string();
        return Document(s, directoryOf(s.start.file), progress);
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
    return Document(std::move(s), dir, {}, std::move(g));
}

void Document::beginStroke(const ToolSpec& tool, MirrorAxis mirror) {
    if (tool.path.size() != 1) throw std::invalid_argument("a stroke starts at one placement");
    beginEdit();
    current_ = SweepStroke{mirror, {tool}};
    inStroke_ = true;
}

void Document::beginEdit() {
    endEdit();
    applied_.clear();
    before_ = LeafSnapshot();
    inEdit_ = true;
}

// One deformation, exactly as applyStrokes does it (so the recorded script replays to the
// same grid), after saving the blocks it may change.
SegmentReport Document::advect(const StepDeformation& deformation) {
    before_.capture(*grid_, changedRegion(*grid_, deformation));
    SegmentReport r;
    r.stroke = script_.strokes.size() + applied_.size();
    const auto t0 = std::chrono::steady_clock::now();
    r.stats = advectSegment(*grid_, deformation);
    const auto t1 = std::chrono::steady_clock::now();
    r.seconds = std::chrono::duration<double>(t1 - t0).count();
    r.remeshedLeaves = mesher_.update(*grid_, r.stats.touched);
    r.meshSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    modified_ = true;
    return r;
}

SegmentReport Document::extendStroke(const Placement& next) {
    if (!inStroke_) throw std::logic_error("extendStroke outside a stroke");
    SweepStroke trial = current_;
    trial.tools[0].path.push_back(next);
    const Sweep sweep = toSweep(trial); // throws for a motion without a logarithm
    const std::size_t k = sweep.segmentCount() - 1;
    SegmentReport r = advect(SweepSegment(sweep, k));
    r.segment = k;
    current_ = std::move(trial);
    return r;
}

SegmentReport Document::applyStroke(const Stroke& stroke) {
    if (!inEdit_ || inStroke_) throw std::logic_error("applyStroke outside an edit");
    SegmentReport last;
    const auto parts = planStroke(*grid_, stroke);
    for (std::size_t k = 0; k < parts.size(); ++k) {
        last = advect(*parts[k]);
        last.segment = k;
    }
    applied_.push_back(stroke);
    return last;
}

void Document::endEdit() {
    if (!inEdit_) return;
    // A click without a drag changes nothing and is not kept.
    if (inStroke_ && current_.tools[0].path.size() >= 2) applied_.push_back(current_);
    inEdit_ = inStroke_ = false;
    if (applied_.empty()) return;
    script_.strokes.insert(script_.strokes.end(), applied_.begin(), applied_.end());
    undo_.push_back({std::move(applied_), std::move(before_)});
    applied_.clear();
    before_ = LeafSnapshot();
    redo_.clear();
    trimToBudget();
}

// Puts an edit's snapshot back and returns the same edit holding the blocks as they were
// just before (so undo gives what redo needs, and the other way round).
Document::Edit Document::swapIn(Edit e) {
    LeafSnapshot current = LeafSnapshot::sameBlocks(*grid_, e.snapshot);
    e.snapshot.restore(*grid_);
    mesher_.update(*grid_, e.snapshot.bounds());
    modified_ = true;
    return {std::move(e.strokes), std::move(current)};
}

void Document::undo() {
    endEdit();
    if (undo_.empty()) return;
    Edit e = swapIn(std::move(undo_.back()));
    undo_.pop_back();
    script_.strokes.resize(script_.strokes.size() - e.strokes.size());
    redo_.push_back(std::move(e));
}

void Document::redo() {
    endEdit();
    if (redo_.empty()) return;
    Edit e = swapIn(std::move(redo_.back()));
    redo_.pop_back();
    script_.strokes.insert(script_.strokes.end(), e.strokes.begin(), e.strokes.end());
    undo_.push_back(std::move(e));
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
    // The oldest strokes stop being undoable first; they stay in the script.
    while (!undo_.empty() && undoBytes() > budget_)
        undo_.pop_front();
}

void Document::saveVdb(const std::string& path) {
    writeLevelSet(*grid_, path);
}

void Document::saveScript(const std::string& path) {
    // The start file is named so that the script works from wherever it is saved.
    StrokeScript s = script_;
    if (s.start.kind != StartShape::Kind::Sphere && !s.start.file.empty() &&
        s.start.file.front() != '/')
        s.start.file = std::filesystem::absolute(scriptDir_ + "/" + s.start.file).string();
    writeStrokeScript(s, path);
}

Document Document::replayAt(StrokeScript script, const std::string& scriptDir, double voxelSize,
                            const Progress& progress) {
    if (!(voxelSize > 0.0) || !std::isfinite(voxelSize))
        throw std::runtime_error("the voxel size must be a positive number");
    script.grid.voxelSize = voxelSize;
    return Document(std::move(script), scriptDir, progress);
}

} // namespace sweepers
