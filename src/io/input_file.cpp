// SPDX-License-Identifier: Apache-2.0
#include "io/input_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/format.h"

namespace sweepers {

namespace {

std::string kindOf(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a plain file";
}

} // namespace

void requireRegularFile(const std::string& path, std::uintmax_t most, const std::string& what) {
    struct stat st = {};
    // stat, not open: it follows links and never waits on what it finds.
    if (::stat(path.c_str(), &st) != 0) return;
    if (!S_ISREG(st.st_mode))
        throw FileError(path + ": not a regular file (" + kindOf(st.st_mode) + ")");
    if (most > 0 && std::uintmax_t(st.st_size) > most)
        throw FileError(path + ": " + formatNumber(double(st.st_size) / double(1 << 20)) + " MB; " +
                        what + " holds at most " + std::to_string(most >> 20) + " MB");
}

std::string readWholeFile(const std::string& path, std::uintmax_t most, const std::string& what) {
    requireRegularFile(path, most, what);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path + ": cannot open the file");
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw FileError(path + ": cannot read the file");
    // (It may have grown since it was checked.)
    if (most > 0 && text.tellp() > std::streamoff(most))
        throw FileError(path + ": " + what + " holds at most " + std::to_string(most >> 20) +
                        " MB");
    return text.str();
}

} // namespace sweepers
