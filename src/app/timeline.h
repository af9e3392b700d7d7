// SPDX-License-Identifier: Apache-2.0
// The modeler's timeline: the document's history played as a film (sculpt/film.h) on a
// grid of its own, scrubbed, played, paused and sped up, while the document waits as it
// was. Frames are made on a worker thread so the window keeps drawing; the window shows
// the newest frame made and the timeline moves on to the frame due next. No GL here.
#pragma once

#include <future>
#include <memory>
#include <string>

#include "core/stopwatch.h"
#include "document/document.h"
#include "levelset/interrupt.h"
#include "sculpt/film.h"

namespace sweepers {

class Timeline {
  public:
    // The film of the document's strokes as they are now (later edits are not in it),
    // showing nothing until the first step. Throws std::invalid_argument for a bad timing.
    explicit Timeline(const Document& doc, const FilmTiming& timing = {});
    ~Timeline();
    Timeline(const Timeline&) = delete;
    Timeline& operator=(const Timeline&) = delete;

    std::size_t frameCount() const { return count_; }
    double seconds() const { return seconds_; }
    double fps() const { return timing_.fps; }

    // The frame asked for, and the one whose grid and mesh are made (0: none yet).
    std::size_t wanted() const { return wanted_; }
    std::size_t shown() const { return shown_; }
    // Asks for frame n (clamped to the film); stops a frame being made that is past it.
    void scrubTo(std::size_t n);
    // Plays from the frame asked for (from the start when at the end), at `speed` times
    // real time; frames the worker cannot make in time are skipped.
    void play(Clock::time_point now = Clock::now());
    void pause() { playing_ = false; }
    bool playing() const { return playing_; }
    void setSpeed(double speed);
    double speed() const { return speed_; }

    // Once per window frame: moves the play head on by the time since the last step when
    // playing, takes a finished frame, or else starts making the frame asked for when no
    // work runs. True when a new frame is ready to show (until the next step).
    bool step(Clock::time_point now = Clock::now());
    bool busy() const { return work_.valid(); }
    // Waits for the frame being made (batch runs: every frame asked for is made).
    void wait() const {
        if (work_.valid()) work_.wait();
    }
    // What could not be made (a start file gone, say), once.
    std::string takeMessage() { return std::exchange(message_, std::string()); }

    // The frame shown; null before the first and while work runs.
    const Grid* grid() const { return ready() ? &sculptor_->grid() : nullptr; }
    const SurfaceMesher* mesher() const { return ready() ? &sculptor_->mesher() : nullptr; }
    // What changed in the mesh since the last call: everything after a rebuild.
    MeshChanges takeMeshChanges();

  private:
    bool ready() const { return !busy() && sculptor_ && shown_ != 0; }
    // On the worker: frame n, from the start shape again when n is behind the play head.
    void make(std::size_t n);

    StrokeScript script_;
    std::string scriptDir_;
    FilmTiming timing_;
    std::size_t count_ = 1;
    double seconds_ = 0.0;
    GridPtr start_; // the start shape, made once (copied for each rebuild)
    std::unique_ptr<Sculptor> sculptor_;
    std::unique_ptr<FilmPlayer> player_;
    bool rebuilt_ = false;
    std::size_t wanted_ = 1, shown_ = 0, making_ = 0;
    bool playing_ = false;
    double speed_ = 1.0, time_ = 0.0; // the play head's time while playing
    Clock::time_point last_{};
    std::future<void> work_;
    FlagInterrupter stop_;
    std::string message_;
};

} // namespace sweepers
