#include "app/document.h"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "deform/sweep.h"
#include "io/mesh_file.h"
#include "io/vdb_file.h"
#include "levelset/advect.h"
#include "levelset/level_set.h"

namespace sweepers {

Document::Document(StrokeScript script, const std::string& scriptDir, const Progress& progress)
    : script_(std::move(script)), scriptDir_(scriptDir) {
    RunOptions options;
    grid_ = makeStartGrid(script_, scriptDir_, options);
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
    // A VDB: read it first (a clear error for anything but a float level set), then start
    // a script from it.
    const GridPtr g = readLevelSet(path);
    StrokeScript s;
    s.grid.voxelSize = g->voxelSize()[0];
    s.grid.halfWidth = halfWidthOf(*g);
    s.start.kind = StartShape::Kind::Vdb;
    s.start.file = std::filesystem::absolute(path).string();
    return Document(s, directoryOf(s.start.file));
}

void Document::beginStroke(const ToolSpec& tool, MirrorAxis mirror) {
    if (inStroke_) endStroke();
    if (tool.path.size() != 1) throw std::invalid_argument("a stroke starts at one placement");
    current_ = SweepStroke{mirror, {tool}};
    before_ = LeafSnapshot();
    inStroke_ = true;
}

SegmentReport Document::extendStroke(const Placement& next) {
    if (!inStroke_) throw std::logic_error("extendStroke outside a stroke");
    SweepStroke trial = current_;
    trial.tools[0].path.push_back(next);
    const Sweep sweep = toSweep(trial); // throws for a motion without a logarithm
    const std::size_t k = sweep.segmentCount() - 1;
    const SweepSegment segment(sweep, k);
    // Exactly what applyStrokes does for segment k of this stroke, so the recorded script
    // replays to the same grid.
    before_.capture(*grid_, changedRegion(*grid_, segment));
    SegmentReport r;
    r.stroke = script_.strokes.size();
    r.segment = k;
    const auto t0 = std::chrono::steady_clock::now();
    r.stats = advectSegment(*grid_, segment);
    const auto t1 = std::chrono::steady_clock::now();
    r.seconds = std::chrono::duration<double>(t1 - t0).count();
    r.remeshedLeaves = mesher_.update(*grid_, r.stats.touched);
    r.meshSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    current_ = std::move(trial);
    modified_ = true;
    return r;
}

void Document::endStroke() {
    if (!inStroke_) return;
    inStroke_ = false;
    if (current_.tools[0].path.size() < 2) return; // a click without a drag changes nothing
    script_.strokes.push_back(current_);
    undo_.push_back({current_, std::move(before_)});
    before_ = LeafSnapshot();
    redo_.clear();
    trimToBudget();
}

void Document::undo() {
    if (inStroke_) endStroke();
    if (undo_.empty()) return;
    Edit e = std::move(undo_.back());
    undo_.pop_back();
    LeafSnapshot after = LeafSnapshot::sameBlocks(*grid_, e.snapshot);
    e.snapshot.restore(*grid_);
    mesher_.update(*grid_, e.snapshot.bounds());
    script_.strokes.pop_back();
    redo_.push_back({std::move(e.stroke), std::move(after)});
    modified_ = true;
}

void Document::redo() {
    if (inStroke_) endStroke();
    if (redo_.empty()) return;
    Edit e = std::move(redo_.back());
    redo_.pop_back();
    LeafSnapshot before = LeafSnapshot::sameBlocks(*grid_, e.snapshot);
    e.snapshot.restore(*grid_);
    mesher_.update(*grid_, e.snapshot.bounds());
    script_.strokes.push_back(e.stroke);
    undo_.push_back({std::move(e.stroke), std::move(before)});
    modified_ = true;
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
