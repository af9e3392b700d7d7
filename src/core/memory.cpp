// SPDX-License-Identifier: Apache-2.0
#include "core/memory.h"

#include <cstdio>
#include <fstream>
#include <string>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

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
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
    std::ofstream refs("/proc/self/clear_refs");
    refs << "5"; // resets the peak resident set size to the current one
    refs.flush();
    return bool(refs);
}

void keepFreedMemory() {
#if defined(__GLIBC__)
    // Blocks below 32 MiB (glibc's largest threshold) come from the heap rather than from
    // mappings of their own, which would go back to the kernel when freed; the heap is
    // trimmed only when 256 MiB lie free at its top. A fixed threshold also stops glibc
    // from moving it with each large block freed, which made the cost of a segment depend
    // on what the one before had freed.
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

} // namespace sweepers
