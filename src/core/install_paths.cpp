// SPDX-License-Identifier: Apache-2.0
#include "core/install_paths.h"

#include <filesystem>
#include <system_error>

namespace sweepers {
namespace {

namespace fs = std::filesystem;

// The checkout only for a program or module in the tree it was built in: an installed one
// names its installed examples, not a checkout that may have moved or changed since.
ProgramPlaces placesFor(const fs::path& builtIn, const fs::path& where, const fs::path& prefix) {
    std::error_code ec;
    if (fs::equivalent(where, builtIn, ec))
        return {SWEEPERS_SOURCE_DIR "/data", SWEEPERS_SOURCE_DIR};
    // The guides are in the sweepers-cli package (which the modeler's depends on), so one
    // place serves both programs and the module. (Both places are CMake's, relative to the
    // prefix.)
    return {fs::weakly_canonical(prefix / SWEEPERS_EXAMPLES_DIR, ec).string(),
            fs::weakly_canonical(prefix / SWEEPERS_GUIDES_DIR, ec).string()};
}

} // namespace

ProgramPlaces programPlaces() {
    std::error_code ec;
    const fs::path bin = fs::read_symlink("/proc/self/exe", ec).parent_path();
    if (ec) return placesFor(SWEEPERS_BUILD_DIR, "/usr/bin", "/usr");
    return placesFor(SWEEPERS_BUILD_DIR, bin, bin / "..");
}

ProgramPlaces modulePlaces(const std::string& moduleFile) {
    std::error_code ec;
    const fs::path dir = fs::absolute(fs::path(moduleFile), ec).parent_path();
    // PREFIX/lib/python3*/dist-packages: three levels up.
    return placesFor(fs::path(SWEEPERS_BUILD_DIR) / "python", dir, dir / ".." / ".." / "..");
}

} // namespace sweepers
