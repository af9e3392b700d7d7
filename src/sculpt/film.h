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

// Plays the script's strokes on the sculptor's grid and calls show(frame, time, grid) for
// each frame from `first` to `last` (at most the film's count) for which wanted(frame)
// holds (none: every one); a frame not wanted costs no partial deformation. Returns once
// `last` is shown, leaving the sculptor with every deformation that ended by then applied.
// `progress` counts the frames from first to last.
void playFilm(Sculptor& sculptor, const StrokeScript& script, const FilmTiming& timing,
              std::size_t first, std::size_t last,
              const std::function<void(std::size_t, double, const Grid&)>& show,
              const std::function<bool(std::size_t)>& wanted = {}, const Progress& progress = {});

} // namespace sweepers
