// SPDX-License-Identifier: Apache-2.0
#include "core/limits.h"

#include <cstdio>
#include <mutex>

#include "core/format.h"
#include "core/memory.h"

namespace sweepers {

namespace {

std::mutex gMutex;
Limits gLimits;

} // namespace

void setLimits(const Limits& l) {
    const std::lock_guard<std::mutex> lock(gMutex);
    gLimits = l;
}

Limits limits() {
    const std::lock_guard<std::mutex> lock(gMutex);
    return gLimits;
}

double memoryLimitBytes() {
    const Limits l = limits();
    return l.memoryBytes > 0.0 ? l.memoryBytes : 0.5 * availableMemoryBytes();
}

double workLimit() {
    const Limits l = limits();
    return l.work > 0.0 ? l.work : kDefaultWork;
}

void requireMemory(double bytes, const std::string& what, const std::string& detail,
                   const std::string& advice) {
    const double limit = memoryLimitBytes();
    if (limit <= 0.0 || bytes <= limit) return;
    const std::string whose =
        limits().memoryBytes > 0.0
            ? "--max-memory"
            : "half the " + formatBytes(availableMemoryBytes()) + " available";
    throw LimitExceeded(what + " needs about " + formatBytes(bytes) + " of memory" +
                        (detail.empty() ? "" : " (" + detail + ")") + ", over its limit of " +
                        formatBytes(limit) + " (" + whose + "); " + advice);
}

void requireWork(double work, const std::string& what) {
    const double most = workLimit();
    // (NaN, from a value beyond any range, is refused too.)
    if (work <= most) return;
    char text[160];
    std::snprintf(text, sizeof text,
                  " takes about %.2g voxel updates, more than the limit of %.2g (raise it with "
                  "--max-work, or sweepers.set_limits(max_work=...) in Python)",
                  work, most);
    throw LimitExceeded(what + text);
}

} // namespace sweepers
