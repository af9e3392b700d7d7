#include "core/memory.h"

#include <cstdio>
#include <fstream>
#include <string>

namespace sweepers {

double availableMemoryBytes() {
    std::ifstream info("/proc/meminfo");
    std::string line;
    double kib = 0.0;
    while (std::getline(info, line))
        if (std::sscanf(line.c_str(), "MemAvailable: %lf kB", &kib) == 1) return kib * 1024.0;
    return 0.0;
}

double peakResidentBytes() {
    std::ifstream status("/proc/self/status");
    std::string line;
    double kib = 0.0;
    while (std::getline(status, line))
        if (std::sscanf(line.c_str(), "VmHWM: %lf kB", &kib) == 1) return kib * 1024.0;
    return 0.0;
}

bool restartPeakResident() {
    std::ofstream refs("/proc/self/clear_refs");
    refs << "5"; // resets the peak resident set size to the current one
    refs.flush();
    return bool(refs);
}

} // namespace sweepers
