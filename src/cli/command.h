// SPDX-License-Identifier: Apache-2.0
// What the commands of sweepers-cli share: their exit codes, usage errors, the output
// options every command takes, and the flag that Ctrl-C and SIGTERM raise.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/progress.h"
#include "levelset/interrupt.h"

namespace sweepers::cli {

// docs/cli.md: 0 done, 1 input refused or the work failed, 2 a usage error, 3 a study that
// finished with runs failed (or without its plots), 130 interrupted.
enum ExitCode : int { kDone = 0, kFailed = 1, kUsage = 2, kPartlyDone = 3, kInterrupted = 130 };

// An option's value that makes no sense (a negative voxel size, a frame range that is not
// one): a usage error, as CLI11's own are, not a refusal of the user's input files.
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// What every command shares: -q (nothing on stderr but errors) and --json (one JSON object
// on stdout, for scripts that drive the command).
struct Output {
    bool quiet = false, json = false;
    ProgressMode progress() const { return progressModeFor(quiet); }
    // A line for the user on stderr, unless -q.
    void say(const std::string& line) const {
        if (!quiet) std::fprintf(stderr, "%s\n", line.c_str());
    }
};
extern Output gOut;

// Ctrl-C (SIGINT) or SIGTERM stops long work at the next leaf range: the handler only sets
// this flag, the engine throws Cancelled, and no output has been written yet.
extern FlagInterrupter gStop;

void printJson(const nlohmann::json& j);

// What --half says wherever a command writes level sets (apply, animate, study).
inline constexpr const char* kHalfHelp =
    "Write the level sets' values as 16-bit floats: files a third smaller, each value "
    "near the surface rounded by under 1/2048 voxel (docs/files.md)";

} // namespace sweepers::cli
