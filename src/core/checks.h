// SPDX-License-Identifier: Apache-2.0
// Checks of the numbers a script or a caller gives, shared by every layer.
#pragma once

#include <cmath>

namespace sweepers {

// Above zero and finite (NaN is neither).
inline bool finitePositive(double v) {
    return v > 0.0 && std::isfinite(v);
}

} // namespace sweepers
