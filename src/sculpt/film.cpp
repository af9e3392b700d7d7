// SPDX-License-Identifier: Apache-2.0
#include "sculpt/film.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/checks.h"
#include "deform/step_prefix.h"
#include "sculpt/stroke_plan.h"

namespace sweepers {

namespace {

// Path segments of a sweep, one for any other stroke: what the sculptor sees as the
// stroke's length, whatever the voxel size makes of a pinch or a strangle.
std::size_t pathSegments(const Stroke& stroke) {
    if (const auto* sweep = std::get_if<SweepStroke>(&stroke))
        return std::max<std::size_t>(1, toSweep(*sweep).segmentCount());
    if (const auto* fluid = std::get_if<FluidStroke>(&stroke))
        return std::max<std::size_t>(1, fluid->path.size() - 1);
    return 1;
}

// Segment k of a sweep stroke done a fraction f of the way: a segment to the tools'
// placements that far along their motions (3.48), or a fluid tool moved that far; null for
// another stroke, or where those placements are not of the form T R S.
std::unique_ptr<StepDeformation> sweptPart(const Stroke& stroke, std::size_t k, double f) {
    // A fluid tool partway: the same tool moved that fraction of its segment.
    if (const auto* fluid = std::get_if<FluidStroke>(&stroke); fluid && fluid->fluid) {
        const std::vector<Eigen::Vector3d> path = fluid->ballPath();
        return sweptFluidSegment(*fluid->fluid, fluid->radius, path[k],
                                 path[k] + f * (path[k + 1] - path[k]));
    }
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
        // A keyed stroke lasts until its last key, a flow its own time unless told.
        const Stroke& stroke = script.strokes[i];
        const double keyed = keyedDuration(stroke);
        const double given = i < script.durations.size() ? script.durations[i] : 0.0;
        const auto* flow = std::get_if<FlowStroke>(&stroke);
        seconds.push_back(keyed > 0.0   ? keyed
                          : given > 0.0 ? given
                          : flow        ? flow->to - flow->from
                                        : timing.secondsPerSegment * double(pathSegments(stroke)));
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

FilmPlayer::FilmPlayer(Sculptor& sculptor, StrokeScript script, const FilmTiming& timing)
    : sculptor_(sculptor), script_(std::move(script)), durations_(strokeDurations(script_, timing)),
      fps_(timing.fps) {
    for (double d : durations_)
        seconds_ += d;
    count_ = filmFrameCount(seconds_, fps_);
}

void FilmPlayer::takeBackPartial() {
    if (!partialOn_) return;
    sculptor_.restoreRecording();
    sculptor_.stopRecording();
    partialOn_ = false;
}

void FilmPlayer::finishPart() {
    sculptor_.applySegment(*parts_[k_]);
    start_ += durations_[i_] / double(parts_.size());
    if (++k_ == parts_.size()) {
        parts_.clear();
        planned_ = false;
        ++i_;
    }
}

void FilmPlayer::seek(std::size_t n) {
    if (n < shown_ || n < 1 || n > count_)
        throw std::invalid_argument("a film player seeks forward, to a frame of the film");
    if (n == shown_) return;
    takeBackPartial();
    const double time = filmFrameTime(n, seconds_, fps_);
    // Shows the deformations on top of the shape so far until the next seek.
    auto putOn = [this](const std::vector<const StepDeformation*>& on) {
        sculptor_.startRecording();
        partialOn_ = true;
        for (const StepDeformation* d : on)
            sculptor_.applySegment(*d);
    };
    while (i_ < script_.strokes.size()) {
        const Stroke& stroke = script_.strokes[i_];
        if (keyedDuration(stroke) > 0.0) {
            // A keyed stroke: the frame is the shape the stroke starts from under the stroke
            // at that time (never the frame before), and past it the stroke at its last key.
            const double end = start_ + durations_[i_];
            if (time < end) {
                const auto parts = planKeyedStroke(stroke, time - start_);
                std::vector<const StepDeformation*> on;
                on.reserve(parts.size());
                for (const auto& part : parts)
                    on.push_back(part.get());
                putOn(on);
                break;
            }
            for (const PlannedStep& step : planStroke(sculptor_.grid(), stroke))
                sculptor_.applySegment(*step.deformation);
            start_ = end;
            ++i_;
            continue;
        }
        if (std::holds_alternative<SmoothStroke>(stroke)) {
            // Smoothing is no deformation to take part of the way: frames show the shape
            // before it until it ends, and it is applied whole then.
            const double end = start_ + durations_[i_];
            if (time < end) break;
            sculptor_.applyStroke(stroke);
            start_ = end;
            ++i_;
            continue;
        }
        if (!planned_) {
            parts_.clear();
            for (PlannedStep& step : planStroke(sculptor_.grid(), stroke))
                parts_.push_back(std::move(step.deformation));
            k_ = 0;
            planned_ = true;
            if (parts_.empty()) { // a stroke that deforms nothing still lasts
                start_ += durations_[i_];
                planned_ = false;
                ++i_;
                continue;
            }
        }
        const double each = durations_[i_] / double(parts_.size());
        if (time < start_ + each) {
            // Inside this deformation: a sweep segment goes part of the way, any other
            // deformation does the sub-steps due by then (a frame that rounds to all of
            // them is shown after it, at the start of the next).
            const StepDeformation& part = *parts_[k_];
            const double f = (time - start_) / each;
            std::unique_ptr<StepDeformation> partial;
            if (f > 0.0) {
                partial = sweptPart(stroke, k_, f);
                if (!partial) {
                    const long done = std::lround(f * part.steps());
                    if (done >= part.steps()) {
                        finishPart();
                        continue;
                    }
                    if (done > 0) partial = std::make_unique<StepPrefix>(part, int(done));
                }
            }
            if (partial) putOn({partial.get()});
            break;
        }
        finishPart();
    }
    shown_ = n;
}

void playFilm(Sculptor& sculptor, const StrokeScript& script, const FilmTiming& timing,
              std::size_t first, std::size_t last,
              const std::function<void(std::size_t, double, const Grid&)>& show,
              const std::function<bool(std::size_t)>& wanted, const Progress& progress) {
    FilmPlayer player(sculptor, script, timing);
    last = std::min(last, player.frameCount());
    if (first < 1 || first > last) return;
    for (std::size_t n = first; n <= last; ++n) {
        if (!wanted || wanted(n)) {
            player.seek(n);
            show(n, filmFrameTime(n, player.seconds(), player.fps()), sculptor.grid());
        }
        if (progress) progress(n - first + 1, last - first + 1);
    }
}

} // namespace sweepers
