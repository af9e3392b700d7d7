// SPDX-License-Identifier: Apache-2.0
// Wall-clock timing of the engine's stages and the modeler's frames.
#pragma once

#include <chrono>

namespace sweepers {

using Clock = std::chrono::steady_clock;

// Seconds from `start` to `end` (now by default).
inline double secondsSince(Clock::time_point start, Clock::time_point end = Clock::now()) {
    return std::chrono::duration<double>(end - start).count();
}

} // namespace sweepers
