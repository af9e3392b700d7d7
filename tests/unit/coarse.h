// SPDX-License-Identifier: Apache-2.0
// The coarse variant of the slow tests, at coarser voxel sizes: SWEEPERS_COARSE_TESTS is set
// (the sanitizer build of the test command does).
#pragma once

#include <cstdlib>

namespace sweepers::test {

inline bool coarse() {
    return std::getenv("SWEEPERS_COARSE_TESTS") != nullptr;
}

} // namespace sweepers::test
