// SPDX-License-Identifier: Apache-2.0
#include "io/atomic_file.h"

#include <array>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <ostream>
#include <stdexcept>
#include <streambuf>
#include <utility>

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

namespace sweepers {

std::string directoryOf(const std::string& path) {
    const auto slash = path.find_last_of('/');
    if (slash == std::string::npos) return ".";
    return slash == 0 ? "/" : path.substr(0, slash);
}

namespace {

std::string baseOf(const std::string& path) {
    const auto slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string systemError(const std::string& what, const std::string& path, int error) {
    return path + ": " + what + ": " + std::strerror(error);
}

// A stream buffer onto a file descriptor whose every write is checked: the first error is
// kept (and every later write refused), so a writer that ignores its stream's state cannot
// hide a full disk. Seeking is supported: OpenVDB goes back to fill in grid offsets.
class CheckedFileBuffer : public std::streambuf {
  public:
    explicit CheckedFileBuffer(int fd) : fd_(fd) {
        setp(buffer_.data(), buffer_.data() + buffer_.size());
    }
    int error() const { return error_; }

  protected:
    int_type overflow(int_type ch) override {
        if (!drain()) return traits_type::eof();
        if (!traits_type::eq_int_type(ch, traits_type::eof())) {
            *pptr() = traits_type::to_char_type(ch);
            pbump(1);
        }
        return traits_type::not_eof(ch);
    }
    int sync() override { return drain() ? 0 : -1; }
    pos_type seekoff(off_type off, std::ios_base::seekdir dir,
                     std::ios_base::openmode /*which*/) override {
        if (!drain()) return pos_type(off_type(-1));
        const int whence = dir == std::ios_base::beg   ? SEEK_SET
                           : dir == std::ios_base::cur ? SEEK_CUR
                                                       : SEEK_END;
        const off_t at = ::lseek(fd_, off_t(off), whence);
        if (at < 0) {
            fail(errno);
            return pos_type(off_type(-1));
        }
        return pos_type(off_type(at));
    }
    pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
        return seekoff(off_type(pos), std::ios_base::beg, which);
    }

  private:
    void fail(int error) {
        if (!error_) error_ = error;
    }
    // Writes out what the buffer holds.
    bool drain() {
        const char* next = pbase();
        bool ok = error_ == 0;
        while (ok && next < pptr()) {
            const ssize_t n = ::write(fd_, next, std::size_t(pptr() - next));
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                fail(n < 0 ? errno : EIO);
                ok = false;
            } else {
                next += n;
            }
        }
        setp(buffer_.data(), buffer_.data() + buffer_.size());
        return ok;
    }

    int fd_;
    int error_ = 0;
    std::array<char, 1 << 16> buffer_;
};

// Temporary files are named PATH.tmp-PID-XXXXXX: one whose process is gone was left by a
// run that was killed before its rename. Names of older versions (PATH.tmp-XXXXXX, without
// the process) are taken as left behind once an hour old.
void removeLeftovers(const std::string& path) {
    const std::string prefix = baseOf(path) + ".tmp-";
    const std::string dir = directoryOf(path);
    DIR* d = ::opendir(dir.c_str());
    if (!d) return;
    while (const dirent* e = ::readdir(d)) {
        const std::string name = e->d_name;
        if (name.compare(0, prefix.size(), prefix) != 0) continue;
        const std::string rest = name.substr(prefix.size());
        const std::string full = dir + '/' += name;
        const auto dash = rest.find('-');
        bool stale = false;
        if (dash != std::string::npos && dash > 0 && rest.find_first_not_of("0123456789") == dash &&
            rest.size() == dash + 7) {
            const long pid = std::strtol(rest.c_str(), nullptr, 10);
            stale = pid > 0 && ::kill(pid_t(pid), 0) != 0 && errno == ESRCH;
        } else if (rest.size() == 6 && dash == std::string::npos) {
            struct stat st {};
            stale = ::stat(full.c_str(), &st) == 0 && std::time(nullptr) - st.st_mtime > 3600;
        }
        if (stale) ::unlink(full.c_str());
    }
    ::closedir(d);
}

} // namespace

AtomicWrite::AtomicWrite(const std::string& path,
                         const std::function<void(std::ostream& out)>& write)
    : path_(path) {
    removeLeftovers(path);
    std::string tmpl = path + ".tmp-" + std::to_string(::getpid()) + "-XXXXXX";
    const int fd = ::mkstemp(tmpl.data());
    if (fd < 0) throw std::runtime_error(systemError("cannot write", path, errno));
    tmp_ = tmpl;
    // mkstemp creates the file 0600; give the saved file the permissions a plain save would.
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::fchmod(fd, 0666 & ~mask);
    int error = 0;
    const char* step = "cannot write";
    try {
        CheckedFileBuffer buffer(fd);
        std::ostream out(&buffer);
        write(out);
        out.flush();
        error = buffer.error();
        if (!error && !out) error = EIO;
    } catch (...) {
        ::close(fd);
        ::unlink(tmp_.c_str());
        throw;
    }
    if (!error && ::fsync(fd) != 0) {
        error = errno;
        step = "cannot flush";
    }
    if (::close(fd) != 0 && !error) error = errno;
    if (error) {
        ::unlink(tmp_.c_str());
        throw std::runtime_error(systemError(step, path, error));
    }
}

AtomicWrite::AtomicWrite(AtomicWrite&& other) noexcept
    : path_(std::move(other.path_)), tmp_(std::exchange(other.tmp_, std::string())) {}

AtomicWrite::~AtomicWrite() {
    if (!tmp_.empty()) ::unlink(tmp_.c_str());
}

void AtomicWrite::commit() {
    if (tmp_.empty()) return;
    if (::rename(tmp_.c_str(), path_.c_str()) != 0)
        throw std::runtime_error(systemError("cannot replace", path_, errno));
    tmp_.clear();
    // Make the rename itself durable.
    const int dfd = ::open(directoryOf(path_).c_str(), O_RDONLY | O_DIRECTORY);
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
}

void writeFileAtomically(const std::string& path,
                         const std::function<void(std::ostream& out)>& write) {
    AtomicWrite(path, write).commit();
}

void writeTextAtomically(const std::string& path, const std::string& text) {
    writeFileAtomically(
        path, [&](std::ostream& out) { out.write(text.data(), std::streamsize(text.size())); });
}

} // namespace sweepers
