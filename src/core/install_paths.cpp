// SPDX-License-Identifier: Apache-2.0
#include "core/install_paths.h"

#include <filesystem>
#include <system_error>

namespace sweepers {

ProgramPlaces programPlaces() {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path bin = fs::read_symlink("/proc/self/exe", ec).parent_path();
    // The checkout only for a program in the tree it was built in: an installed one names
    // its installed examples, not a checkout that may have moved or changed since.
    if (!ec && fs::equivalent(bin, fs::path(SWEEPERS_BUILD_DIR), ec))
        return {SWEEPERS_SOURCE_DIR "/data", SWEEPERS_SOURCE_DIR};
    const fs::path share = (ec ? fs::path("/usr/bin") : bin) / ".." / "share";
    return {fs::weakly_canonical(share / "sweepers" / "examples", ec).string(),
            fs::weakly_canonical(share / "doc" / "sweepers", ec).string()};
}

} // namespace sweepers
