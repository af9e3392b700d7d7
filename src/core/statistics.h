// SPDX-License-Identifier: Apache-2.0
// Order statistics of timings (latency reports and benchmarks).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace sweepers {

// The q-quantile (0 <= q <= 1) of the values, nearest rank; 0 when there are none.
inline double percentile(std::vector<double> values, double q) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const std::size_t i =
        std::min(values.size() - 1, std::size_t(std::lround(q * double(values.size() - 1))));
    return values[i];
}

} // namespace sweepers
