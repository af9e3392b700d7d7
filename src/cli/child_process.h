// SPDX-License-Identifier: Apache-2.0
// Other programs run by sweepers-cli: this program itself for the runs of a study run side
// by side (study --jobs), and Slurm's commands (study --slurm).
#pragma once

#include <string>
#include <vector>

#include <sys/types.h>

namespace sweepers::cli {

// The absolute path of this program (/proc/self/exe).
std::string thisProgram();
// Whether `name` is a program on the PATH.
bool onPath(const std::string& name);

// Starts argv[0] (looked up on the PATH) with its standard error appended to `errorLog`
// (inherited when empty); returns its pid. Throws std::runtime_error when it cannot start.
pid_t startProgram(const std::vector<std::string>& argv, const std::string& errorLog = "");

// The process's exit status as a shell gives it: its exit code, or 128 + the signal that
// ended it. Waits when `block`; returns -1 when it has not ended (and !block).
int waitProgram(pid_t pid, bool block = true);

struct ProgramOutput {
    int status = 0; // as waitProgram gives it; 127 when it could not be started
    std::string out, err;
};
// Runs argv to its end and returns what it printed.
ProgramOutput runProgram(const std::vector<std::string>& argv);

} // namespace sweepers::cli
