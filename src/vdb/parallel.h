// SPDX-License-Identifier: Apache-2.0
// The engine's parallel loops, and how much of a piece of work runs on one thread.
//
// Amdahl's law bounds what more cores can give by the share of the work that runs on one
// thread while the others wait: the work between parallel loops, and the tail of a loop
// whose last chunks run alone. A SerialClock measures that share on any machine, a 2-core one
// included: every parallel loop of the engine goes through parallelFor, which, while a
// clock runs on the calling thread, times the loop (its wall time W) and its chunks (their
// busy time B, summed over the threads). The time outside the loops is serial, and a loop
// whose P threads were busy for B in all adds W - B / P, the time they waited for each other
// (at one thread, the loop's scheduling overhead).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/stopwatch.h"

namespace sweepers {

class SerialClock {
  public:
    // Starts timing; parallel loops called from this thread are accounted to it until it
    // ends. Clocks nest: a loop run while an inner clock runs counts in the outer ones too.
    SerialClock() : start_(Clock::now()), outer_(current()) { current() = this; }
    ~SerialClock() { current() = outer_; }
    SerialClock(const SerialClock&) = delete;
    SerialClock& operator=(const SerialClock&) = delete;

    double wallSeconds() const { return secondsSince(start_); }
    // The wall time so far during which one thread worked and the others waited.
    double serialSeconds() const { return wallSeconds() - inLoops_ + waited_; }

    // The clock running on this thread, if any.
    static SerialClock*& current() {
        static thread_local SerialClock* clock = nullptr;
        return clock;
    }

  private:
    template <typename Range, typename Body> friend void parallelFor(const Range&, const Body&);

    Clock::time_point start_;
    SerialClock* outer_;
    double inLoops_ = 0.0, waited_ = 0.0;
    bool inLoop_ = false; // a loop's body may start loops of its own: only the outer one counts
};

// The threads a loop started now may use: the arena's, within what a global_control
// (--threads) allows.
inline std::size_t loopThreads() {
    return std::min<std::size_t>(
        std::size_t(tbb::this_task_arena::max_concurrency()),
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

// The grain of a loop over n items: small enough that each thread gets several chunks (a
// loop's tail then waits for a small chunk, not a large one), and at most `most`, the
// chunk that amortizes a task's cost for items this cheap.
inline std::size_t grainFor(std::size_t n, std::size_t most) {
    return std::clamp<std::size_t>(n / (8 * loopThreads()), 1, most);
}

// tbb::parallel_for over `range`, accounted to the calling thread's SerialClock if one runs.
template <typename Range, typename Body> void parallelFor(const Range& range, const Body& body) {
    SerialClock* clock = SerialClock::current();
    if (!clock || clock->inLoop_) {
        tbb::parallel_for(range, body);
        return;
    }
    struct InLoop { // cleared however the loop ends (Cancelled is thrown through it)
        bool& flag;
        ~InLoop() { flag = false; }
    };
    clock->inLoop_ = true;
    const InLoop guard{clock->inLoop_};
    std::atomic<std::int64_t> busy{0}; // nanoseconds
    const auto start = Clock::now();
    tbb::parallel_for(range, [&](const Range& part) {
        const auto t = Clock::now();
        body(part);
        busy += std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t).count();
    });
    const double wall = secondsSince(start);
    const double threads = double(loopThreads());
    // The clocks around this one see the loop too, up to one that was in a loop itself (a
    // clock started inside a loop's body: that loop is counted there already).
    const double waited = std::max(0.0, wall - 1e-9 * double(busy.load()) / threads);
    for (SerialClock* c = clock; c && (c == clock || !c->inLoop_); c = c->outer_) {
        c->inLoops_ += wall;
        c->waited_ += waited;
    }
}

// The index form: body(i) for every i in [first, last).
template <typename Index, typename Body>
void parallelFor(Index first, Index last, const Body& body) {
    parallelFor(tbb::blocked_range<Index>(first, last), [&](const tbb::blocked_range<Index>& r) {
        for (Index i = r.begin(); i != r.end(); ++i)
            body(i);
    });
}

} // namespace sweepers
