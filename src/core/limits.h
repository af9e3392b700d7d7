// SPDX-License-Identifier: Apache-2.0
// What one piece of work may ask for, checked against its estimate before it starts
// (docs/cli.md, "Limits"): the memory a start shape or a run may take, and the work of one
// stroke's deformation or smoothing dab, counted in voxel updates (a voxel's value computed
// once: one sample through one sub-step, one step of the smoothing flow). Input that asks
// for more is refused with the estimate and the limit, instead of running for hours or
// growing past the machine.
#pragma once

#include <stdexcept>
#include <string>

namespace sweepers {

// Refused: the estimate exceeds a limit. The message names both and how to raise it.
class LimitExceeded : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

struct Limits {
    double memoryBytes = 0.0; // 0: half the memory available when a check asks
    double work = 0.0;        // voxel updates per deformation or dab; 0: kDefaultWork
};

// Every number of a script (a length, a time, an angle, a strength) and every coordinate a
// shape may reach lies within kLargestNumber of zero, and every positive number of a script
// is at least kSmallestPositive: far beyond a shape's scale, but within what converts to a
// voxel index or a step count without overflow, and where a float still places a voxel.
constexpr double kLargestNumber = 1e5, kSmallestPositive = 1e-9;

// About a minute of smoothing flow on one core, several of sub-steps through a fluid's
// sampled field: beyond it a stroke is more likely a slip (a fluid ball of radius 0.01 sent
// a thousand units away) than a wish.
constexpr double kDefaultWork = 2e9;

// The process's limits (the CLI's --max-memory and --max-work, Python's set_limits);
// thread-safe.
void setLimits(const Limits& limits);
Limits limits();
// The limits in force: the memory limit resolved against what is available now (0 when
// nothing can be read about memory: no check), and the work limit.
double memoryLimitBytes();
double workLimit();

// Throws LimitExceeded when `bytes` exceed the memory limit: "WHAT needs about 2.9 GB of
// memory (DETAIL), over its limit of 12.4 GB (half the 24.8 GB available); ADVICE".
void requireMemory(double bytes, const std::string& what, const std::string& detail = "",
                   const std::string& advice = "use a coarser voxel size or raise --max-memory");

// Throws LimitExceeded when `work` voxel updates exceed the work limit: "WHAT takes about
// 2.1e+10 voxel updates, more than the limit of 2e+09 (...)".
void requireWork(double work, const std::string& what);

} // namespace sweepers
