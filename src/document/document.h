// SPDX-License-Identifier: Apache-2.0
// The modeler's document: a level set, its mesh kept up to date leaf by leaf, every edit
// recorded as a stroke script (which `sweepers-cli apply` replays to the same grid), and
// undo / redo that keep only the blocks a stroke touched. No GL here. Every segment goes
// through the Sculptor's applySegment, as `sweepers-cli apply` does.
//
// Long work can be cancelled through an interrupter: opening, importing and resampling
// (a new document is simply not made) and sculpting (a cancelled segment puts back the
// whole edit in progress and throws Cancelled).
#pragma once

#include <deque>
#include <functional>
#include <string>

#include "io/stroke_script.h"
#include "io/vdb_file.h"
#include "sculpt/sculptor.h"

namespace sweepers {

class Document;

// Told of every change to a document's history, in order, on the thread that made it (the
// session journal listens).
class HistoryListener {
  public:
    virtual ~HistoryListener() = default;
    // An edit ended with these strokes (one undo step), or a redo put them back. The
    // document's grid is the one after them.
    virtual void appended(const Document& doc, const std::vector<Stroke>& strokes) = 0;
    // An undo: the history keeps its first `strokes`.
    virtual void truncated(const Document& doc, std::size_t strokes) = 0;
};

class Document {
  public:
    // Builds the script's start shape and applies its strokes (they become the document's
    // history, not undoable). Throws on bad input, leaving nothing half made.
    Document(StrokeScript script, const std::string& scriptDir, const Progress& progress = {},
             GridPtr start = nullptr, // start: the script's start shape, when already made
             Interrupter* interrupter = nullptr);
    // A unit sphere at voxel size h.
    static StrokeScript sphereScript(double voxelSize);
    // Opens a .vdb (a float level set), a .json stroke script, or imports a mesh
    // (.obj, .ply, .stl) at `meshVoxelSize`.
    static Document open(const std::string& path, double meshVoxelSize = 1.0 / 64,
                         const Progress& progress = {}, Interrupter* interrupter = nullptr);
    // A history continued from a grid that holds its first `done` strokes already (a
    // checkpoint, when recovering a session).
    static Document resume(StrokeScript script, const std::string& scriptDir, GridPtr grid,
                           std::size_t done, const Progress& progress = {},
                           Interrupter* interrupter = nullptr);
    // A history replayed at another voxel size (a resolution change).
    static Document replayAt(StrokeScript script, const std::string& scriptDir, double voxelSize,
                             const Progress& progress = {}, Interrupter* interrupter = nullptr);

    const Grid& grid() const { return sculptor_.grid(); }
    const SurfaceMesher& mesher() const { return sculptor_.mesher(); }
    // Polled while sculpting; may be changed between edits.
    void setInterrupter(Interrupter* interrupter) { sculptor_.setInterrupter(interrupter); }
    const StrokeScript& script() const { return script_; }
    // Null: nobody is told.
    void setHistoryListener(HistoryListener* listener) { listener_ = listener; }
    const std::string& scriptDir() const { return scriptDir_; }

    // Sculpting: a sweep of one tool whose path grows by one placement per drag event;
    // each new placement is advected at once as one segment. One undo step.
    void beginStroke(const ToolSpec& tool, MirrorAxis mirror);
    // The same for a sweep of one tool whose path holds its first placement, with the
    // stroke's mirror, strength and radial symmetry.
    void beginStroke(const SweepStroke& start);
    bool inStroke() const { return inStroke_; }
    SegmentReport extendStroke(const Placement& next);
    void endStroke() { endEdit(); }

    // Whole strokes (swirls, inflations, or complete sweeps) applied one after another;
    // those applied between beginEdit and endEdit are one undo step (one drag).
    void beginEdit();
    // `each` sees every segment's report (its deformation as planned, for an exact reference).
    SegmentReport applyStroke(const Stroke& stroke,
                              const std::function<void(const SegmentReport&)>& each = {});
    void endEdit();

    bool canUndo() const { return !undo_.empty() || !dropped_.empty(); }
    bool canRedo() const { return !redo_.empty(); }
    // Undoes the last edit. One whose blocks were dropped to keep within the budget is
    // undone by replaying the history before it from the start (replayTo and undoByReplay
    // do the same in two steps, the long one on another thread and from a checkpoint).
    void undo();
    // Redoes the last undone edit; one undone by replay is applied again.
    void redo();

    // --- undo beyond the budget -------------------------------------------------------
    // The next undo must rebuild the grid: the edit's blocks were dropped.
    bool undoNeedsReplay() const { return undo_.empty() && !dropped_.empty(); }
    // How many strokes that undo leaves.
    std::size_t replayTarget() const;
    // The grid after the first replayTarget() strokes, made from `grid`, which holds the
    // first `done` of them (a checkpoint; null: the start shape, done = 0). Changes nothing
    // in the document: safe on another thread while the document is not edited.
    GridPtr replayTo(GridPtr grid, std::size_t done, const Progress& progress = {},
                     Interrupter* interrupter = nullptr) const;
    // Puts in the grid replayTo made: the last edit is undone.
    void undoByReplay(GridPtr grid);
    std::size_t undoBytes() const;
    std::size_t undoBudget() const { return budget_; }
    void setUndoBudget(std::size_t bytes);
    std::size_t undoCount() const { return undo_.size(); }
    // Edits undone by replay only (their blocks were dropped).
    std::size_t droppedCount() const { return dropped_.size(); }

    // Modified since opened or last saved (the grid or the script).
    bool modified() const { return modified_; }
    void saveVdb(const std::string& path, const LevelSetWriteOptions& options = {});
    void saveScript(const std::string& path);
    void markSaved() { modified_ = false; }
    void markModified() { modified_ = true; }

    // What changed in the mesh since the last call (for re-upload).
    MeshChanges takeMeshChanges() { return sculptor_.mesher().takeChanges(); }

  private:
    Document(StrokeScript script, const std::string& scriptDir, const Progress& progress,
             GridPtr start, Interrupter* interrupter, std::size_t done);
    struct Edit {
        std::vector<Stroke> strokes;
        LeafSnapshot snapshot; // undo stack: before the strokes; redo stack: after them
        bool replay = false;   // redo stack: no snapshot, the strokes are applied again
    };
    // Runs sculpting work; a cancelled one puts back the edit in progress and rethrows.
    template <typename Work> SegmentReport cancellable(const Work& work);
    Edit swapIn(Edit e);
    // Ends the edit in progress; a new edit (not a redo) empties the redo stack.
    void finishEdit(bool newEdit);
    void trimToBudget();

    StrokeScript script_;
    std::string scriptDir_;
    Sculptor sculptor_;
    std::deque<Edit> undo_;
    std::vector<Edit> redo_;
    // Stroke counts of the oldest edits, whose blocks were dropped to keep within the budget
    // (oldest first): still undoable, by replay.
    std::vector<std::size_t> dropped_;
    std::size_t budget_ = std::size_t(512) << 20;
    bool inEdit_ = false, inStroke_ = false, modified_ = false;
    SweepStroke current_;
    std::vector<Stroke> applied_; // strokes of the edit in progress
    HistoryListener* listener_ = nullptr;
};

} // namespace sweepers
