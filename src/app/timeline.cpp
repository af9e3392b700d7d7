// SPDX-License-Identifier: Apache-2.0
#include "app/timeline.h"

#include <algorithm>
#include <cmath>

#include "io/start_grid.h"

namespace sweepers {

Timeline::Timeline(const Document& doc, const FilmTiming& timing)
    : script_(doc.script()), scriptDir_(doc.scriptDir()), timing_(timing) {
    for (double d : strokeDurations(script_, timing_))
        seconds_ += d;
    count_ = filmFrameCount(seconds_, timing_.fps);
}

Timeline::~Timeline() {
    stop_.interrupt();
    wait();
}

void Timeline::scrubTo(std::size_t n) {
    wanted_ = std::clamp<std::size_t>(n, 1, count_);
    time_ = filmFrameTime(wanted_, seconds_, timing_.fps);
    // Work towards a later frame is wasted: going back starts from the start shape.
    if (busy() && making_ > wanted_) stop_.interrupt();
}

void Timeline::play(Clock::time_point now) {
    if (wanted_ >= count_) scrubTo(1);
    time_ = filmFrameTime(wanted_, seconds_, timing_.fps);
    last_ = now;
    playing_ = true;
}

void Timeline::setSpeed(double speed) {
    if (speed > 0.0 && std::isfinite(speed)) speed_ = speed;
}

bool Timeline::step(Clock::time_point now) {
    if (playing_) {
        time_ += speed_ * secondsSince(last_, now);
        last_ = now;
        // Frame n is at (n - 1) / fps; the hair of slack keeps a frame's own time on it.
        const double due = std::floor(time_ * timing_.fps + 1e-9) + 1.0;
        wanted_ = due >= double(count_) ? count_ : std::size_t(due);
        if (wanted_ == count_) playing_ = false;
    }
    bool fresh = false;
    if (work_.valid() && work_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
        try {
            work_.get();
        } catch (const Cancelled&) {
            // Stopped for a frame behind it: the half-made grid is dropped.
        } catch (const std::exception& e) {
            message_ = std::string("the film cannot be played: ") + e.what();
            playing_ = false;
        }
        const std::size_t before = shown_;
        shown_ = player_ ? player_->frame() : 0;
        fresh = shown_ != 0 && (shown_ != before || rebuilt_);
    }
    // A frame just made waits a step before the next is begun: the window shows it first.
    if (!fresh && !work_.valid() && wanted_ != shown_ && message_.empty()) {
        stop_.reset();
        making_ = wanted_;
        const std::size_t n = wanted_;
        work_ = std::async(std::launch::async, [this, n] { make(n); });
    }
    return fresh;
}

void Timeline::make(std::size_t n) {
    try {
        if (!player_ || n < player_->frame()) {
            player_.reset();
            sculptor_.reset();
            if (!start_) start_ = makeStartGrid(script_, scriptDir_, 0.0, &stop_);
            sculptor_ = std::make_unique<Sculptor>(start_->deepCopy());
            sculptor_->setInterrupter(&stop_);
            sculptor_->startMeshing();
            player_ = std::make_unique<FilmPlayer>(*sculptor_, script_, timing_);
            rebuilt_ = true;
        }
        player_->seek(n);
    } catch (...) {
        // A grid stopped half-made (or not made) cannot be played on.
        player_.reset();
        sculptor_.reset();
        throw;
    }
}

MeshChanges Timeline::takeMeshChanges() {
    if (!sculptor_ || busy()) return {};
    MeshChanges changes = sculptor_->mesher().takeChanges();
    if (rebuilt_) changes = MeshChanges{true, {}};
    rebuilt_ = false;
    return changes;
}

} // namespace sweepers
