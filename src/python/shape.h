// SPDX-License-Identifier: Apache-2.0
// What the Python module (module.cpp) shows, without Python: a sculpted shape with the
// history that made it, and a sculpting session with undo (the modeler's Document without
// a window). Errors are the engine's own exceptions; the bindings turn them into Python's.
#pragma once

#include <atomic>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "document/document.h"
#include "io/stroke_script.h"
#include "levelset/measure.h"
#include "mesh/triangle_mesh.h"
#include "study/reference.h"

namespace sweepers::python {

// A level set and the exact reference of its history (the one `study` measures against).
class Shape {
  public:
    Shape(std::shared_ptr<const Grid> grid, ExactReference::StartFunction start, History history);

    const Grid& grid() const { return *grid_; }
    LevelSetMeasures measures() const;
    // The welded marching-cubes surface, as `sweepers-cli apply --mesh` exports it.
    TriangleMesh mesh() const;
    // The grid's signed distance at each point (trilinear), and the exact reference's.
    std::vector<double> sample(const std::vector<Eigen::Vector3d>& points) const;
    // The exact reference's implicit function (what `study` measures against), and the
    // first-order signed distance to its zero set: the value over its gradient's length.
    std::vector<double> exactValue(const std::vector<Eigen::Vector3d>& points) const;
    std::vector<double> exactDistance(const std::vector<Eigen::Vector3d>& points) const;
    // The level set as `apply` writes it, as the bytes of an in-memory VDB stream.
    std::string vdbBytes() const;
    // A .vdb (its values as 16-bit floats when `half`), or a mesh (.obj, .ply, .stl),
    // written atomically.
    void save(const std::string& path, bool half = false) const;

  private:
    ExactReference reference() const; // throws std::invalid_argument when the history smooths
    std::shared_ptr<const Grid> grid_;
    ExactReference::StartFunction start_;
    History history_;
};

// Applies a script (its files relative to `baseDir`) at `voxelSize` (0: the script's).
Shape applyScript(const StrokeScript& script, const std::string& baseDir, double voxelSize,
                  Interrupter* interrupter, const Progress& progress);

// A sculpting session: strokes applied one call at a time, each call one undo step; the
// session's script replays to the same grid.
class Session {
  public:
    // `script` holds the start (and no strokes).
    Session(StrokeScript script, const std::string& baseDir, Interrupter* interrupter);

    // Applies the strokes as one step; a cancelled call leaves the session as it was.
    void apply(const std::vector<Stroke>& strokes, Interrupter* interrupter,
               const Progress& progress);
    bool undo();
    bool redo();
    bool canUndo() const { return document_.canUndo(); }
    bool canRedo() const { return document_.canRedo(); }

    // The start and the strokes applied (files named absolutely).
    StrokeScript script() const;
    // The shape now (its grid a copy: later strokes do not change it).
    Shape shape() const;
    // The shape now, its grid the session's own: valid until the session changes.
    Shape view() const;
    const Grid& grid() const { return document_.grid(); }

    // One caller's turn at the session, taken around every call by whoever shares it between
    // threads (the Python module): sculpting rewrites the grid that readers walk. Waits for
    // the turn before to end; throws std::runtime_error when this thread holds a turn already
    // (a progress callback reading the session it reports on would wait for itself).
    class Turn {
      public:
        explicit Turn(const Session& session);
        ~Turn();
        Turn(const Turn&) = delete;
        Turn& operator=(const Turn&) = delete;

      private:
        const Session& session_;
        std::unique_lock<std::mutex> lock_;
    };

  private:
    mutable std::mutex busy_;
    mutable std::atomic<std::thread::id> holder_{};
    std::string baseDir_;
    Document document_;
    ExactReference::StartFunction start_;
    History allHistory() const;
    // Per stroke of the script, the deformations it applied; those undone wait for a redo.
    std::vector<History> history_, undone_;
};

} // namespace sweepers::python
