// SPDX-License-Identifier: Apache-2.0
// Animated modeling (thesis 3.6.1, the third technique, and 3.6.2): a stroke script played
// over time, so that a film shows each stroke happening. A stroke lasts its `duration`, or
// else `secondsPerSegment` times its path segments (one for a stroke without a path); its
// deformations (a sweep's segments, a pinch's or a strangle's parts) share that time
// equally, and a frame that falls inside one shows the sub-steps done by then
// (deform/step_prefix.h), applied on top of the shape so far and taken back after the frame.
// A keyed stroke (keyframed, slide) lasts until its last key, and each of its frames is the
// shape it started from under the stroke at that time. The frames go through the one
// stroke path, so the last frame is what `apply` gives.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include "sculpt/sculptor.h"

namespace sweepers {

struct FilmTiming {
    double fps = 24.0;
    double secondsPerSegment = 0.25; // for strokes without a duration
};

// The seconds each stroke of the script lasts. Throws std::invalid_argument for a timing
// that is not positive and finite.
std::vector<double> strokeDurations(const StrokeScript& script, const FilmTiming& timing);

// Frame n (from 1) is at time (n - 1) / fps; the film runs from the start shape at frame 1
// to the first frame at or past its end, which shows the end: seconds x fps frames, plus 1.
std::size_t filmFrameCount(double seconds, double fps);
double filmFrameTime(std::size_t frame, double seconds, double fps);

// The film played on a sculptor's grid up to any frame, and on from there: a timeline's
// play head. seek(n) leaves the grid showing frame n (a frame inside a deformation holds the
// partial deformation on top of the shape so far, taken back by the next seek); going back
// needs a new player on the start shape.
class FilmPlayer {
  public:
    // The sculptor's grid is the script's start shape. Throws std::invalid_argument for a
    // timing that is not positive and finite.
    FilmPlayer(Sculptor& sculptor, StrokeScript script, const FilmTiming& timing);
    std::size_t frameCount() const { return count_; }
    double seconds() const { return seconds_; }
    double fps() const { return fps_; }
    // The frame the grid shows (0 before the first seek, which may be to any frame).
    std::size_t frame() const { return shown_; }
    // Plays on to frame n, from shown() up to frameCount(). A cancelled seek (Cancelled,
    // from the sculptor's interrupter) leaves the grid half-made: drop the player and grid.
    void seek(std::size_t n);

  private:
    void takeBackPartial();
    // Applies the deformation the play head is at, whole, and moves on to the next.
    void finishPart();

    Sculptor& sculptor_;
    StrokeScript script_;
    std::vector<double> durations_;
    double fps_ = 24.0, seconds_ = 0.0;
    std::size_t count_ = 1, shown_ = 0;
    // The play head: stroke i_, its deformations parts_ (planned when it is reached; empty
    // for a keyed stroke), the next one k_, and the time the next one starts.
    std::size_t i_ = 0, k_ = 0;
    bool planned_ = false, partialOn_ = false;
    std::vector<std::shared_ptr<const StepDeformation>> parts_;
    double start_ = 0.0;
};

// Plays the script's strokes on the sculptor's grid and calls show(frame, time, grid) for
// each frame from `first` to `last` (at most the film's count) for which wanted(frame)
// holds (none: every one), through a FilmPlayer; a frame not wanted costs no partial
// deformation. The grid is left as the last frame shown showed it. `progress` counts the
// frames from first to last.
void playFilm(Sculptor& sculptor, const StrokeScript& script, const FilmTiming& timing,
              std::size_t first, std::size_t last,
              const std::function<void(std::size_t, double, const Grid&)>& show,
              const std::function<bool(std::size_t)>& wanted = {}, const Progress& progress = {});

} // namespace sweepers
