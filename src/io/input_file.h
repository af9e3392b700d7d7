// SPDX-License-Identifier: Apache-2.0
// Files a user names, checked before they are opened: a FIFO, a device or a directory in a
// file's place is refused at once (opening a FIFO waits for a writer that never comes;
// /dev/zero never ends), and text files are read only up to a bound (docs/files.md).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace sweepers {

// A file that cannot be read as the file it should be, in one line that names it.
class FileError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// The most a stroke script, a study plan or a run's result may hold.
constexpr std::uintmax_t kMostTextBytes = std::uintmax_t(64) << 20;

// Throws FileError unless `path` is a regular file (or a link to one) of at most `most`
// bytes (0: any size): "PATH: not a regular file (a FIFO)", "PATH: 70.2 MB; a stroke script
// holds at most 64 MB" (`what` names the kind of file). A path that does not exist passes:
// opening it says so in the reader's own words.
void requireRegularFile(const std::string& path, std::uintmax_t most = 0,
                        const std::string& what = "a file");

// The whole of a regular file of at most `most` bytes (requireRegularFile), as bytes; throws
// FileError when it cannot be opened or read.
std::string readWholeFile(const std::string& path, std::uintmax_t most, const std::string& what);

} // namespace sweepers
