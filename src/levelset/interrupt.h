// SPDX-License-Identifier: Apache-2.0
// Cancelling long work: an interrupter in OpenVDB's style (util::NullInterrupter), polled
// by the engine once per leaf range or batch of voxels. When it says stop, the operation
// throws Cancelled; the caller puts back what it had (a document restores its snapshot, a
// command writes no file).
#pragma once

#include <atomic>
#include <stdexcept>

#include <openvdb/util/NullInterrupter.h>

namespace sweepers {

using Interrupter = openvdb::util::NullInterrupter;

class Cancelled : public std::runtime_error {
  public:
    Cancelled() : std::runtime_error("cancelled") {}
};

// Throws Cancelled when `interrupter` (may be null) asks to stop.
inline void pollInterrupt(Interrupter* interrupter) {
    if (interrupter && interrupter->wasInterrupted()) throw Cancelled();
}

// Stopped by a flag that another thread (a button, a key) or a signal handler sets.
class FlagInterrupter : public Interrupter {
  public:
    bool wasInterrupted(int = -1) override { return flag_.load(std::memory_order_relaxed); }
    void interrupt() { flag_.store(true, std::memory_order_relaxed); }
    void reset() { flag_.store(false, std::memory_order_relaxed); }

  private:
    std::atomic<bool> flag_{false};
};

} // namespace sweepers
