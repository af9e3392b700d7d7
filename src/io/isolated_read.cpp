// SPDX-License-Identifier: Apache-2.0
#include "io/isolated_read.h"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <new>
#include <string>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/iostreams/device/array.hpp>
#include <boost/iostreams/device/file_descriptor.hpp>
#include <boost/iostreams/stream.hpp>
#include <openvdb/io/Stream.h>
#include <tbb/global_control.h>

#include "core/format.h"
#include "core/memory.h"
#include "core/stopwatch.h"
#include "io/vdb_file.h"

namespace sweepers {

namespace {

constexpr const char* kMarker = "--sweepers-read-grid-for-parent";
// Under AddressSanitizer (kAddressSanitizer, core/memory.h) the child's memory limit cannot
// be a limit on its address space, which the sanitizer reserves by terabytes: the
// sanitizer's own limit on the resident memory stands in for it.
// Child exit codes besides 0 (the grid was sent). Not 1 for a refusal: a sanitizer that
// catches the reader overrunning a buffer ends the child with 1, and that is damage.
constexpr int kRefused = 65, kOutOfMemory = 3, kCannotStart = 127;
// The child's descriptors for the grid and for a refusal (its stdout and stderr go nowhere).
constexpr int kGridFd = 3, kMessageFd = 4;

void writeAll(int fd, const std::string& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) ::_exit(kCannotStart);
        done += std::size_t(n);
    }
}

// The child's side: runs when the executable was started with the marker.
bool serveReadIfAsked() {
    std::ifstream cmdline("/proc/self/cmdline", std::ios::binary);
    std::vector<std::string> args;
    for (std::string arg; std::getline(cmdline, arg, '\0');)
        args.push_back(arg);
    // The marker and its three arguments end the command line (a reader started through an
    // interpreter has the interpreter's own arguments before them).
    if (args.size() < 5 || args[args.size() - 4] != kMarker) return false;
    args.erase(args.begin(), args.end() - 5);
    // One thread: its memory limit holds the reader's work, not a stack and a malloc arena
    // (tens of megabytes of address space each) for each of the machine's cores.
    const tbb::global_control oneThread(tbb::global_control::max_allowed_parallelism, 1);
    try {
        openvdb::GridBase::ConstPtr grid;
        std::string about; // what else the file holds: fields ended by NULs (a grid's name
                           // may hold any other character)
        std::vector<std::string> grids;
        if (args[2] == "velocity") {
            const VelocityFile file = readVelocityInProcess(args[3], args[4]);
            grid = file.grid;
            about = file.name + '\0' + "0" + '\0';
            grids = file.grids;
        } else {
            const LevelSetFile file = readLevelSetInProcess(args[3], args[4]);
            grid = file.grid;
            about = file.name + '\0' + std::to_string(file.levelSets) + '\0';
            grids = file.grids;
        }
        // Straight into the pipe, and not compressed: the parent reads it at once, so
        // compressing it here only to decompress it there would be pure cost. Nor is it held
        // here in a string first.
        namespace bio = boost::iostreams;
        bio::stream<bio::file_descriptor_sink> out(kGridFd, bio::never_close_handle);
        openvdb::io::Stream stream(out);
        stream.setCompression(openvdb::io::COMPRESS_ACTIVE_MASK);
        stream.write(openvdb::GridCPtrVec{grid});
        out.flush();
        if (!out) ::_exit(kCannotStart);
        for (const std::string& g : grids)
            about += g + '\0';
        writeAll(kMessageFd, about);
        ::_exit(0);
    } catch (const std::bad_alloc&) {
        ::_exit(kOutOfMemory);
    } catch (const std::exception& e) {
        writeAll(kMessageFd, e.what());
        ::_exit(kRefused);
    }
}

const bool gServed = serveReadIfAsked();

// What the reader may use: a file expands when it is decompressed, but not without bound;
// a damaged size field can ask for gigabytes. Generous for real files (64 times the file,
// 512 MB at least, counting the process's own mappings), never more than is available.
// The floor is what a damaged small file can make the reader fill before it is stopped: a
// floor of gigabytes would let each damaged file cost seconds of filling memory, while a
// real level set needs far less than 64 times its size.
double readerMemory(const std::string& path) {
    struct stat st {};
    const double file = ::stat(path.c_str(), &st) == 0 ? double(st.st_size) : 0.0;
    const double available = availableMemoryBytes();
    const double wanted = std::max(512e6, 64.0 * file);
    return available > 0 ? std::min(wanted, available) : wanted;
}

std::string selfPath() {
    std::vector<char> buf(4096);
    const ssize_t n = ::readlink("/proc/self/exe", buf.data(), buf.size() - 1);
    if (n <= 0) throw FileError("cannot start the file reader (no /proc/self/exe)");
    return std::string(buf.data(), std::size_t(n));
}

std::vector<std::string>& readerCommand() {
    static std::vector<std::string> command;
    return command;
}

} // namespace

void setReaderCommand(std::vector<std::string> command) {
    readerCommand() = std::move(command);
}

namespace {

// What the child sent: its grid, its name in the file, how many level sets the file holds and
// what grids.
struct ChildRead {
    openvdb::GridBase::Ptr grid;
    std::string name;
    std::size_t levelSets = 0;
    std::vector<std::string> grids;
};

// Runs the child reader of `kind` ("level-set" or "velocity") on the file.
ChildRead readInChild(const char* kind, const std::string& path, const std::string& gridName,
                      const ReadLimits& limits) {
    (void)gServed;
    initVdb();
    std::vector<std::string> command = readerCommand();
    if (command.empty()) command.push_back(selfPath());
    const std::string self = command.front();
    int out[2], err[2];
    if (::pipe2(out, O_CLOEXEC) != 0) throw FileError("cannot start the file reader (pipe)");
    if (::pipe2(err, O_CLOEXEC) != 0) {
        ::close(out[0]);
        ::close(out[1]);
        throw FileError("cannot start the file reader (pipe)");
    }
    const double bytes = limits.bytes > 0 ? limits.bytes : readerMemory(path);
    std::vector<const char*> argv;
    argv.reserve(command.size() + 5);
    for (const std::string& a : command)
        argv.push_back(a.c_str());
    for (const char* a : {kMarker, kind, path.c_str(), gridName.c_str()})
        argv.push_back(a);
    argv.push_back(nullptr);
    // The child's environment: the parent's, and under AddressSanitizer a resident-memory
    // limit in its options (AddressSanitizer cannot run under an address-space limit, and
    // without a limit a damaged file could make the reader allocate gigabytes).
    // Threads the libraries start themselves still get an arena each unless glibc is told.
    std::vector<std::string> env{"MALLOC_ARENA_MAX=1"};
    for (char** e = environ; *e; ++e)
        if ((!kAddressSanitizer || std::strncmp(*e, "ASAN_OPTIONS=", 13) != 0) &&
            std::strncmp(*e, "MALLOC_ARENA_MAX=", 17) != 0)
            env.emplace_back(*e);
    if (kAddressSanitizer && bytes > 0) {
        const char* options = std::getenv("ASAN_OPTIONS");
        env.push_back(std::string("ASAN_OPTIONS=") + (options ? options : "") +
                      (options && *options ? ":" : "") +
                      "hard_rss_limit_mb=" + std::to_string(std::size_t(bytes / (1 << 20))));
    }
    std::vector<char*> envp;
    envp.reserve(env.size() + 1);
    for (std::string& e : env)
        envp.push_back(e.data());
    envp.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        // Only async-signal-safe calls until exec.
        // Moved above the targets first, so that neither dup2 overwrites the other's source.
        const int grid = ::fcntl(out[1], F_DUPFD_CLOEXEC, 10);
        const int message = ::fcntl(err[1], F_DUPFD_CLOEXEC, 10);
        // What the libraries print (OpenVDB's warnings, glibc's last words) is not for the
        // user: the parent says in one line what happened.
        const int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, STDOUT_FILENO);
        ::dup2(null, STDERR_FILENO);
        ::dup2(grid, kGridFd);
        ::dup2(message, kMessageFd);
        if (bytes > 0 && !kAddressSanitizer) {
            const rlimit as{rlim_t(bytes), rlim_t(bytes)};
            ::setrlimit(RLIMIT_AS, &as);
        }
        ::execve(self.c_str(), const_cast<char* const*>(argv.data()), envp.data());
        ::_exit(kCannotStart);
    }
    ::close(out[1]);
    ::close(err[1]);
    if (pid < 0) {
        ::close(out[0]);
        ::close(err[0]);
        throw FileError("cannot start the file reader (fork)");
    }
    // Collect both pipes until they close or the time is up.
    std::string grid, message;
    pollfd fds[2] = {{out[0], POLLIN, 0}, {err[0], POLLIN, 0}};
    std::string* sinks[2] = {&grid, &message};
    const auto start = Clock::now();
    bool timedOut = false;
    int open = 2;
    std::vector<char> chunk(1 << 16);
    while (open > 0) {
        const double left = limits.seconds - secondsSince(start);
        if (left <= 0) {
            timedOut = true;
            break;
        }
        const int ready = ::poll(fds, 2, int(std::min(left, 1.0) * 1000) + 1);
        if (ready < 0 && errno != EINTR) break;
        for (int k = 0; k < 2; ++k) {
            if (fds[k].fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
            const ssize_t n = ::read(fds[k].fd, chunk.data(), chunk.size());
            if (n > 0) {
                sinks[k]->append(chunk.data(), std::size_t(n));
            } else if (n == 0 || errno != EINTR) {
                ::close(fds[k].fd);
                fds[k].fd = -1;
                --open;
            }
        }
    }
    for (const pollfd& f : fds)
        if (f.fd >= 0) ::close(f.fd);
    if (timedOut) ::kill(pid, SIGKILL);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (timedOut)
        throw FileError(path + ": the file seems damaged: reading it did not finish in " +
                        formatNumber(limits.seconds) + " s");
    if (WIFSIGNALED(status))
        throw FileError(path + ": the file is damaged: the VDB reader crashed on it (" +
                        std::string(::strsignal(WTERMSIG(status))) + ")");
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : kCannotStart;
    if (code == kOutOfMemory)
        throw FileError(path + ": the file seems damaged: reading it would take more than " +
                        formatBytes(bytes) + " of memory");
    if (code == kRefused && !message.empty()) throw FileError(message);
    if (code == kCannotStart) throw FileError(path + ": cannot start the file reader");
    if (code != 0)
        throw FileError(path + ": the file is damaged: the VDB reader failed on it (exit code " +
                        std::to_string(code) + ")");
    try {
        // Read where it lies (an istringstream would copy it first).
        boost::iostreams::stream<boost::iostreams::array_source> in(grid.data(), grid.size());
        openvdb::io::Stream stream(in, /*delayLoad=*/false);
        const openvdb::GridPtrVecPtr grids = stream.getGrids();
        std::vector<std::string> fields;
        for (std::size_t at = 0, end; (end = message.find('\0', at)) != std::string::npos;
             at = end + 1)
            fields.push_back(message.substr(at, end - at));
        if (grids && !grids->empty() && fields.size() >= 2) {
            ChildRead read;
            read.grid = grids->front();
            read.name = fields[0];
            read.levelSets = std::stoul(fields[1]);
            read.grids.assign(fields.begin() + 2, fields.end());
            return read;
        }
    } catch (const std::exception& e) {
    }
    throw FileError(path + ": the file reader returned no grid");
}

} // namespace

LevelSetFile readLevelSetInChild(const std::string& path, const std::string& gridName,
                                 const ReadLimits& limits) {
    ChildRead read = readInChild("level-set", path, gridName, limits);
    LevelSetFile file;
    file.grid = openvdb::gridPtrCast<Grid>(read.grid);
    if (!file.grid) throw FileError(path + ": the file reader returned no level set");
    file.name = std::move(read.name);
    file.levelSets = read.levelSets;
    file.grids = std::move(read.grids);
    return file;
}

VelocityFile readVelocityInChild(const std::string& path, const std::string& gridName,
                                 const ReadLimits& limits) {
    ChildRead read = readInChild("velocity", path, gridName, limits);
    VelocityFile file;
    file.grid = openvdb::gridPtrCast<openvdb::Vec3SGrid>(read.grid);
    if (!file.grid) throw FileError(path + ": the file reader returned no velocity grid");
    file.name = std::move(read.name);
    file.grids = std::move(read.grids);
    return file;
}

} // namespace sweepers
