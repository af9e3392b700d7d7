// SPDX-License-Identifier: Apache-2.0
// SerialClock: the time a piece of work spends on one thread while the others wait, counted
// from what the parallel loops report. Only lower bounds of sleeps are asserted: a loaded
// machine can make anything take longer, never shorter.
#include <chrono>
#include <thread>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "vdb/parallel.h"

using namespace sweepers;

namespace {

void sleepMs(int ms) {
    std::this_thread::sleep_for(std::chrono::milliseconds(ms));
}

} // namespace

TEST(SerialClock, WorkOutsideTheLoopsIsSerial) {
    const SerialClock clock;
    sleepMs(30);
    EXPECT_GE(clock.serialSeconds(), 0.030);
    // The wall time read after the serial time (either reads the clock anew).
    const double serial = clock.serialSeconds();
    EXPECT_LE(serial, clock.wallSeconds());
}

TEST(SerialClock, ALoopWhoseWorkIsOneChunkWaitsForIt) {
    // Two threads, and all the loop's work in one of its elements: while that one runs, the
    // other thread has nothing to do, so half the loop's time is serial.
    const tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    const SerialClock clock;
    parallelFor(std::size_t(0), std::size_t(64), [](std::size_t i) {
        if (i == 0) sleepMs(40);
    });
    EXPECT_GE(clock.serialSeconds(), 0.040 / 2 - 0.002);
}

TEST(SerialClock, ABalancedLoopAddsLittle) {
    // Every element sleeps alike, so both threads stay busy: the loop adds far less serial
    // time than its wall time (with a margin for threads a loaded machine does not run).
    const tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    const SerialClock clock;
    parallelFor(tbb::blocked_range<std::size_t>(0, 8, 1), [](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
            sleepMs(10);
    });
    EXPECT_GE(clock.wallSeconds(), 0.040 - 0.002);
    EXPECT_LT(clock.serialSeconds(), clock.wallSeconds());
}

TEST(SerialClock, ClocksNestAndLoopsInsideLoopsCountOnce) {
    // Two threads, a balanced loop of 8 x 10 ms under an inner clock: neither clock counts
    // it as serial, so both stay well below the loop's 40 ms and more.
    const tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    const SerialClock outer;
    {
        const SerialClock inner;
        parallelFor(tbb::blocked_range<std::size_t>(0, 8, 1), [](const auto& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                // A loop inside a loop's body counts once, in the outer loop.
                parallelFor(std::size_t(0), std::size_t(4), [](std::size_t) {});
                sleepMs(10);
            }
        });
        EXPECT_LT(inner.serialSeconds(), inner.wallSeconds() - 0.015);
    }
    EXPECT_EQ(SerialClock::current(), &outer);
    EXPECT_GE(outer.wallSeconds(), 0.040 - 0.002);
    EXPECT_LT(outer.serialSeconds(), outer.wallSeconds() - 0.015);
}
