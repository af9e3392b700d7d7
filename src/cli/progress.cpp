// SPDX-License-Identifier: Apache-2.0
#include "cli/progress.h"

#include <cmath>
#include <unistd.h>
#include <utility>

namespace sweepers::cli {

namespace {

// "4.2 s", "3 min 05 s", "1 h 02 min": as precise as a reader of a progress line needs.
std::string duration(double s) {
    char text[32];
    if (s < 60.0)
        std::snprintf(text, sizeof text, "%.1f s", s);
    else if (s < 3600.0)
        std::snprintf(text, sizeof text, "%d min %02d s", int(s / 60.0), int(s) % 60);
    else
        std::snprintf(text, sizeof text, "%d h %02d min", int(s / 3600.0), int(s / 60.0) % 60);
    return text;
}

// A terminal's line is redrawn at most this often: faster than the eye reads it is wasted
// on a slow terminal or an ssh link.
constexpr double kRedrawSeconds = 0.1;
constexpr int kBarWidth = 24;

} // namespace

ProgressMode progressModeFor(bool quiet, std::FILE* file) {
    if (quiet) return ProgressMode::Quiet;
    return ::isatty(::fileno(file)) ? ProgressMode::Terminal : ProgressMode::Lines;
}

ProgressLine::ProgressLine(ProgressMode mode, std::string what, std::string unit, std::FILE* file)
    : mode_(mode), what_(std::move(what)), unit_(std::move(unit)), file_(file),
      start_(Clock::now()) {}

ProgressLine::~ProgressLine() {
    finish();
}

double ProgressLine::elapsed() const {
    return secondsSince(start_);
}

std::string ProgressLine::status(std::size_t done, std::size_t total, bool bar) const {
    const double t = elapsed();
    const double fraction = total ? double(done) / double(total) : 1.0;
    std::string out = what_ + ": ";
    if (bar) {
        const int filled = int(std::lround(fraction * kBarWidth));
        out += "[" + std::string(std::size_t(filled), '#') +
               std::string(std::size_t(kBarWidth - filled), '.') + "] ";
    }
    char text[160];
    std::snprintf(text, sizeof text, "%s %zu / %zu (%.0f%%, %s", unit_.c_str(), done, total,
                  100.0 * fraction, duration(t).c_str());
    out += text;
    if (done > 0 && done < total && t > 0.0) {
        const double rate = double(done) / t;
        std::snprintf(text, sizeof text, ", %.3g/s, %s left", rate,
                      duration(double(total - done) / rate).c_str());
        out += text;
    }
    return out + ")";
}

void ProgressLine::update(std::size_t done, std::size_t total) {
    if (mode_ == ProgressMode::Quiet) return;
    if (mode_ == ProgressMode::Lines) {
        if (!eachTenth_ || total == 0) return;
        const long tenth = long(done * 10 / total);
        if (tenth == lastTenth_) return;
        lastTenth_ = tenth;
        std::fprintf(file_, "%s\n", status(done, total, false).c_str());
        std::fflush(file_);
        return;
    }
    const double t = elapsed();
    if (done < total && drawn_ && t - lastDraw_ < kRedrawSeconds) return;
    lastDraw_ = t;
    // Carriage return, then erase to the end of the line: a shorter status leaves no tail.
    std::fprintf(file_, "\r\033[K%s", status(done, total, true).c_str());
    std::fflush(file_);
    drawn_ = true;
}

void ProgressLine::print(const std::string& line) {
    if (mode_ == ProgressMode::Quiet) return;
    if (drawn_) std::fprintf(file_, "\r\033[K");
    drawn_ = false;
    std::fprintf(file_, "%s\n", line.c_str());
    std::fflush(file_);
}

void ProgressLine::finish() {
    if (mode_ != ProgressMode::Terminal || !drawn_) return;
    std::fprintf(file_, "\n");
    std::fflush(file_);
    drawn_ = false;
}

} // namespace sweepers::cli
