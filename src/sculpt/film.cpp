#include "sculpt/film.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "deform/step_prefix.h"

namespace sweepers {

namespace {

bool finitePositive(double v) {
    return v > 0.0 && std::isfinite(v);
}

// Path segments of a sweep, one for any other stroke: what the sculptor sees as the
// stroke's length, whatever the voxel size makes of a pinch or a strangle.
std::size_t pathSegments(const Stroke& stroke) {
    if (const auto* sweep = std::get_if<SweepStroke>(&stroke))
        return std::max<std::size_t>(1, toSweep(*sweep).segmentCount());
    return 1;
}

// Segment k of a sweep stroke done a fraction f of the way: a segment to the tools'
// placements that far along their motions (3.48); null for another stroke, or where those
// placements are not of the form T R S.
std::unique_ptr<StepDeformation> sweptPart(const Stroke& stroke, std::size_t k, double f) {
    const auto* stroked = std::get_if<SweepStroke>(&stroke);
    if (!stroked) return nullptr;
    Sweep sweep = toSweep(*stroked);
    for (SweptTool& tool : sweep.tools) {
        const std::optional<Placement> along = placementAlong(tool.path[k], tool.path[k + 1], f);
        if (!along) return nullptr;
        tool.path = {tool.path[k], *along};
    }
    return std::make_unique<SweepSegment>(sweep, 0);
}

} // namespace

std::vector<double> strokeDurations(const StrokeScript& script, const FilmTiming& timing) {
    if (!finitePositive(timing.fps)) throw std::invalid_argument("the frame rate must be positive");
    if (!finitePositive(timing.secondsPerSegment))
        throw std::invalid_argument("the seconds per segment must be positive");
    std::vector<double> seconds;
    for (std::size_t i = 0; i < script.strokes.size(); ++i) {
        // A keyed stroke lasts until its last key.
        const double keyed = keyedDuration(script.strokes[i]);
        const double given = i < script.durations.size() ? script.durations[i] : 0.0;
        seconds.push_back(keyed > 0.0 ? keyed
                          : given > 0.0
                              ? given
                              : timing.secondsPerSegment * double(pathSegments(script.strokes[i])));
    }
    return seconds;
}

std::size_t filmFrameCount(double seconds, double fps) {
    // A hair of slack, so that 2 s at 24 fps is 48 intervals, not 49 by rounding.
    return std::size_t(std::ceil(seconds * fps - 1e-9)) + 1;
}

double filmFrameTime(std::size_t frame, double seconds, double fps) {
    return std::min(double(frame - 1) / fps, seconds);
}

void playFilm(Sculptor& sculptor, const StrokeScript& script, const FilmTiming& timing,
              std::size_t first, std::size_t last,
              const std::function<void(std::size_t, double, const Grid&)>& show,
              const std::function<bool(std::size_t)>& wanted, const Progress& progress) {
    const std::vector<double> durations = strokeDurations(script, timing);
    double total = 0.0;
    for (double d : durations)
        total += d;
    last = std::min(last, filmFrameCount(total, timing.fps));
    if (first < 1 || first > last) return;
    std::size_t frame = first;
    // Shows `frame` as the sculptor's grid is, and moves on to the next.
    auto emit = [&](double time) {
        if (!wanted || wanted(frame)) show(frame, time, sculptor.grid());
        if (progress) progress(frame - first + 1, last - first + 1);
        ++frame;
    };
    double start = 0.0; // of the current deformation
    // Shows `frame` with the deformations on top of the shape so far, then takes them back.
    auto emitWith = [&](double time, const std::vector<const StepDeformation*>& on) {
        if (on.empty()) return emit(time);
        sculptor.startRecording();
        for (const StepDeformation* d : on)
            sculptor.applySegment(*d);
        emit(time);
        sculptor.restoreRecording();
        sculptor.stopRecording();
    };
    for (std::size_t i = 0; i < script.strokes.size() && frame <= last; ++i) {
        if (keyedDuration(script.strokes[i]) > 0.0) {
            // A keyed stroke: each frame from the shape the stroke starts from, by the stroke
            // at that time (never from the frame before), then the stroke at its last key.
            const double end = start + durations[i];
            while (frame <= last) {
                const double time = filmFrameTime(frame, total, timing.fps);
                if (time >= end) break;
                if (wanted && !wanted(frame)) {
                    emit(time);
                    continue;
                }
                const auto parts = planKeyedStroke(script.strokes[i], time - start);
                std::vector<const StepDeformation*> on;
                on.reserve(parts.size());
                for (const auto& part : parts)
                    on.push_back(part.get());
                emitWith(time, on);
            }
            if (frame > last) break;
            for (const auto& part : planStroke(sculptor.grid(), script.strokes[i]))
                sculptor.applySegment(*part);
            start = end;
            continue;
        }
        const auto parts = planStroke(sculptor.grid(), script.strokes[i]);
        if (parts.empty()) start += durations[i]; // (a stroke that deforms nothing still lasts)
        const double each = durations[i] / double(parts.size());
        for (std::size_t k = 0; k < parts.size() && frame <= last; ++k) {
            const StepDeformation& part = *parts[k];
            const double end = start + each;
            // The frames inside this deformation: a sweep segment goes part of the way, any
            // other deformation does the sub-steps due by then (a frame that rounds to all
            // of them waits for the next deformation, which shows this one whole).
            while (frame <= last) {
                const double time = filmFrameTime(frame, total, timing.fps);
                if (time >= end) break;
                const double f = (time - start) / each;
                std::unique_ptr<StepDeformation> partial;
                if (f > 0.0 && (!wanted || wanted(frame))) {
                    partial = sweptPart(script.strokes[i], k, f);
                    if (!partial) {
                        const long done = std::lround(f * part.steps());
                        if (done >= part.steps()) break;
                        if (done > 0) partial = std::make_unique<StepPrefix>(part, int(done));
                    }
                }
                if (partial)
                    emitWith(time, {partial.get()});
                else
                    emit(time);
            }
            sculptor.applySegment(part);
            start = end;
        }
    }
    while (frame <= last)
        emit(filmFrameTime(frame, total, timing.fps));
}

} // namespace sweepers
