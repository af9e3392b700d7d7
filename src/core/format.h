// SPDX-License-Identifier: Apache-2.0
// Numbers in messages, as a user reads them: "0.015625", "1e+308", "36.2 GB", "2.1e+25 TB"
// (never the 300 digits std::to_string gives a large double).
#pragma once

#include <cstdio>
#include <string>

namespace sweepers {

inline std::string formatNumber(double v) {
    char text[64];
    std::snprintf(text, sizeof text, "%.6g", v);
    return text;
}

// All the digits a double needs to read back as itself.
inline std::string formatPrecise(double v) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", v);
    return text;
}

inline std::string formatBytes(double bytes) {
    char text[64];
    if (bytes >= 1e12)
        std::snprintf(text, sizeof text, "%.3g TB", bytes / 1e12);
    else if (bytes >= 1e9)
        std::snprintf(text, sizeof text, "%.1f GB", bytes / 1e9);
    else
        std::snprintf(text, sizeof text, "%.0f MB", bytes / 1e6);
    return text;
}

} // namespace sweepers
