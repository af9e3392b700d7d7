// SPDX-License-Identifier: Apache-2.0
// A fresh directory of its own for a test's files (mkdtemp), removed with everything in it
// when the test ends: tests running at the same time never share a file name.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <stdexcept>
#include <string>

namespace sweepers::test {

struct ScratchDir {
    std::filesystem::path path;
    ScratchDir() {
        std::string name = (std::filesystem::temp_directory_path() / "sweepers-test-XXXXXX");
        if (!::mkdtemp(name.data())) throw std::runtime_error("cannot make a scratch directory");
        path = name;
    }
    ~ScratchDir() {
        std::error_code ignored;
        std::filesystem::remove_all(path, ignored);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    std::string operator/(const std::string& file) const { return (path / file).string(); }
    std::size_t count() const {
        return std::size_t(std::distance(std::filesystem::directory_iterator(path),
                                         std::filesystem::directory_iterator()));
    }
};

} // namespace sweepers::test
