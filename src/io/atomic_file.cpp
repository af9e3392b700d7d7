#include "io/atomic_file.h"

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace sweepers {

std::string directoryOf(const std::string& path) {
    const auto slash = path.find_last_of('/');
    if (slash == std::string::npos) return ".";
    return slash == 0 ? "/" : path.substr(0, slash);
}

namespace {

std::string systemError(const std::string& what, const std::string& path) {
    return path + ": " + what + ": " + std::strerror(errno);
}

} // namespace

void writeFileAtomically(const std::string& path,
                         const std::function<void(const std::string& tmpPath)>& write) {
    std::string tmpl = path + ".tmp-XXXXXX";
    const int fd = ::mkstemp(tmpl.data());
    if (fd < 0) throw std::runtime_error(systemError("cannot write", path));
    // mkstemp creates the file 0600; give the saved file the permissions a plain save would.
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::fchmod(fd, 0666 & ~mask);
    ::close(fd);
    const std::string tmp = tmpl;
    try {
        write(tmp);
        const int rfd = ::open(tmp.c_str(), O_RDONLY);
        if (rfd < 0 || ::fsync(rfd) != 0) {
            if (rfd >= 0) ::close(rfd);
            throw std::runtime_error(systemError("cannot flush", path));
        }
        ::close(rfd);
        if (::rename(tmp.c_str(), path.c_str()) != 0)
            throw std::runtime_error(systemError("cannot replace", path));
    } catch (...) {
        ::unlink(tmp.c_str());
        throw;
    }
    // Make the rename itself durable.
    const int dfd = ::open(directoryOf(path).c_str(), O_RDONLY | O_DIRECTORY);
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
}

void writeTextAtomically(const std::string& path, const std::string& text) {
    writeFileAtomically(path, [&](const std::string& tmp) {
        const int fd = ::open(tmp.c_str(), O_WRONLY | O_TRUNC);
        if (fd < 0) throw std::runtime_error(systemError("cannot write", path));
        std::size_t done = 0;
        while (done < text.size()) {
            const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
            if (n < 0) {
                if (errno == EINTR) continue;
                ::close(fd);
                throw std::runtime_error(systemError("cannot write", path));
            }
            done += static_cast<std::size_t>(n);
        }
        if (::close(fd) != 0) throw std::runtime_error(systemError("cannot write", path));
    });
}

} // namespace sweepers
