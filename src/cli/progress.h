// SPDX-License-Identifier: Apache-2.0
// How sweepers-cli shows the progress of long work on stderr, so that it reads well
// wherever stderr goes:
//  - on a terminal, one line redrawn in place: a bar, the count, the rate and the time left;
//  - in a pipe or a log file, whole lines only (one per tenth of the work and one at the
//    end), so that no two events ever share a line;
//  - with -q, nothing: errors are the caller's to print.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

#include "core/stopwatch.h"

namespace sweepers::cli {

enum class ProgressMode { Terminal, Lines, Quiet };

// Terminal when FILE is one and quiet is off; Lines when it is not; Quiet when asked.
ProgressMode progressModeFor(bool quiet, std::FILE* file = stderr);

class ProgressLine {
  public:
    // what: the work ("applying data/drag.json"); unit: what is counted ("segment").
    ProgressLine(ProgressMode mode, std::string what, std::string unit, std::FILE* file = stderr);
    ~ProgressLine();
    ProgressLine(const ProgressLine&) = delete;
    ProgressLine& operator=(const ProgressLine&) = delete;

    // done of total units are finished. In Lines mode a line is printed when a new tenth is
    // reached and at the end, unless eachTenth is off (then only print() writes lines).
    void update(std::size_t done, std::size_t total);
    // A whole line of its own (a run finished, a file written); a bar being drawn is cleared
    // first and drawn again at the next update. Printed in every mode but Quiet.
    void print(const std::string& line);
    // Ends the bar's line on a terminal; nothing otherwise. Idempotent.
    void finish();

    void setLinesEachTenth(bool on) { eachTenth_ = on; }
    ProgressMode mode() const { return mode_; }

  private:
    std::string status(std::size_t done, std::size_t total, bool bar) const;
    double elapsed() const;

    ProgressMode mode_;
    std::string what_, unit_;
    std::FILE* file_;
    Clock::time_point start_;
    double lastDraw_ = -1.0;
    long lastTenth_ = -1;
    bool drawn_ = false, eachTenth_ = true;
};

} // namespace sweepers::cli
