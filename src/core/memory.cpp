#include "core/memory.h"

#include <cstdio>
#include <fstream>
#include <string>

namespace sweepers {

namespace {

// The figure of the line "<key>: <n> kB" of a /proc file, in bytes; 0 when there is none.
double kilobytesLine(const char* path, const char* key) {
    std::ifstream file(path);
    const std::string format = std::string(key) + ": %lf kB";
    std::string line;
    double kib = 0.0;
    while (std::getline(file, line))
        if (std::sscanf(line.c_str(), format.c_str(), &kib) == 1) return kib * 1024.0;
    return 0.0;
}

} // namespace

double availableMemoryBytes() {
    return kilobytesLine("/proc/meminfo", "MemAvailable");
}

double peakResidentBytes() {
    return kilobytesLine("/proc/self/status", "VmHWM");
}

bool restartPeakResident() {
    std::ofstream refs("/proc/self/clear_refs");
    refs << "5"; // resets the peak resident set size to the current one
    refs.flush();
    return bool(refs);
}

} // namespace sweepers
