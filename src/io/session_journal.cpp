// SPDX-License-Identifier: Apache-2.0
#include "io/session_journal.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "core/format.h"
#include "io/atomic_file.h"
#include "io/start_grid.h"
#include "io/vdb_file.h"

namespace sweepers {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

std::string journalPath(const std::string& dir) {
    return dir + "/journal";
}

[[noreturn]] void systemFailure(const std::string& path, const std::string& what, int error) {
    throw std::runtime_error(path + ": " + what + ": " + std::strerror(error));
}

// The strokes of a record as the stroke script format writes them (one validated reader
// for both).
json strokesJson(const std::vector<Stroke>& strokes) {
    StrokeScript s;
    s.strokes = strokes;
    return json::parse(formatStrokeScript(s, -1))["strokes"];
}

std::vector<Stroke> readStrokes(const json& strokes, const std::string& name,
                                const std::string& scriptDir) {
    return loadStrokeScript(json{{"sweepers", 1}, {"strokes", strokes}}.dump(), name, scriptDir)
        .strokes;
}

} // namespace

JournalWriter::~JournalWriter() {
    if (fd_ >= 0) ::close(fd_);
}

void JournalWriter::start(const std::string& dir, const StrokeScript& script,
                          const std::string& scriptDir) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    path_ = journalPath(dir);
    // (A document made in code may name no directory: its files are named absolutely, or
    // relative to where the program runs.)
    const fs::path base = scriptDir.empty() ? fs::current_path() : fs::absolute(scriptDir);
    const json header = {{"session", 1},
                         {"dir", base.lexically_normal().string()},
                         {"script", json::parse(formatStrokeScript(script, -1))}};
    writeTextAtomically(path_, header.dump() + "\n");
    fd_ = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
    if (fd_ < 0) systemFailure(path_, "cannot open", errno);
}

void JournalWriter::append(const std::string& line) {
    if (fd_ < 0) throw std::logic_error("the journal was not started");
    const std::string text = line + "\n";
    // One write for the whole record (a short write is continued, and reading ignores a
    // record cut short), then fsync: the record is on disk when this returns.
    std::size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            systemFailure(path_, "cannot write", errno);
        }
        done += std::size_t(n);
    }
    if (::fsync(fd_) != 0) systemFailure(path_, "cannot write", errno);
}

void JournalWriter::appended(const std::vector<Stroke>& strokes) {
    append(json{{"append", strokesJson(strokes)}}.dump());
}

void JournalWriter::truncated(std::size_t strokes) {
    append(json{{"truncate", strokes}}.dump());
}

void JournalWriter::checkpointed(const std::string& file, std::size_t strokes) {
    append(json{{"checkpoint", file}, {"strokes", strokes}}.dump());
}

JournalState readJournal(const std::string& dir) {
    const std::string path = journalPath(dir);
    requireRegularFile(path);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path + ": there is no session journal here");
    std::ostringstream all;
    all << in.rdbuf();
    if (in.bad()) throw std::runtime_error(path + ": cannot read the session journal");
    const std::string text = all.str();

    JournalState st;
    std::size_t at = 0, line = 0;
    while (at < text.size()) {
        const std::size_t end = text.find('\n', at);
        ++line;
        const std::string where = path + ", line " + std::to_string(line);
        if (end == std::string::npos) {
            // Written up to the crash and no further.
            st.ignored = "the last record was cut short by the crash (ignored)";
            break;
        }
        const std::string record = text.substr(at, end - at);
        at = end + 1;
        try {
            const json j = json::parse(record);
            if (line == 1) {
                if (!j.is_object() || j.value("session", 0) != 1 || !j.contains("script"))
                    throw std::runtime_error("not a session journal");
                st.scriptDir = j.at("dir").get<std::string>();
                st.script = loadStrokeScript(j.at("script").dump(), where, st.scriptDir);
            } else if (j.contains("append")) {
                const std::vector<Stroke> strokes =
                    readStrokes(j.at("append"), where, st.scriptDir);
                st.script.strokes.insert(st.script.strokes.end(), strokes.begin(), strokes.end());
            } else if (j.contains("truncate")) {
                const std::size_t n = j.at("truncate").get<std::size_t>();
                if (n > st.script.strokes.size())
                    throw std::runtime_error("an undo past the start of the history");
                st.script.strokes.resize(n);
                // A checkpoint after the undone strokes no longer belongs to the history.
                st.checkpoints.erase(std::remove_if(st.checkpoints.begin(), st.checkpoints.end(),
                                                    [n](const JournalState::Checkpoint& c) {
                                                        return c.strokes > n;
                                                    }),
                                     st.checkpoints.end());
            } else if (j.contains("checkpoint")) {
                const std::string file = j.at("checkpoint").get<std::string>();
                const std::size_t k = j.at("strokes").get<std::size_t>();
                if (file.empty() || file.find('/') != std::string::npos ||
                    k > st.script.strokes.size())
                    throw std::runtime_error("a checkpoint that does not fit the history");
                st.checkpoints.push_back({(fs::path(dir) / file).string(), k});
            } else {
                throw std::runtime_error("an unknown record");
            }
        } catch (const std::exception& e) {
            if (line == 1)
                throw std::runtime_error(path + ": cannot recover from this journal (" +
                                         std::string(e.what()) + ")");
            st.ignored = "the journal is damaged at line " + std::to_string(line) +
                         "; what follows was left out";
            break;
        }
        st.records = line;
    }
    if (st.records == 0) throw std::runtime_error(path + ": the session journal is empty");
    return st;
}

RecoveryStart recoveryStart(const JournalState& state, Interrupter* interrupter) {
    RecoveryStart start;
    std::size_t unreadable = 0;
    for (auto c = state.checkpoints.rbegin(); c != state.checkpoints.rend(); ++c) {
        // The modeler keeps its newest few checkpoints and removes older ones: only the
        // newest one missing is worth a word.
        std::error_code ec;
        if (c != state.checkpoints.rbegin() && !fs::exists(c->file, ec)) continue;
        try {
            GridPtr g = readLevelSet(c->file);
            const double h = g->voxelSize()[0];
            if (std::abs(h - state.script.grid.voxelSize) > 1e-9 * state.script.grid.voxelSize)
                throw std::runtime_error(c->file + ": a checkpoint at voxel size " +
                                         formatNumber(h) + ", not the session's");
            start.grid = std::move(g);
            start.strokes = c->strokes;
            start.checkpoint = c->file;
            break;
        } catch (const std::runtime_error& e) {
            // The newest failure says why; older ones are counted.
            if (++unreadable == 1) start.skipped = e.what();
        }
    }
    if (unreadable > 1)
        start.skipped = std::to_string(unreadable) +
                        " checkpoints could not be read, the newest: " + start.skipped;
    if (!start.grid) start.grid = makeStartGrid(state.script, state.scriptDir, 0.0, interrupter);
    return start;
}

std::string describeRecovery(const JournalState& state, const RecoveryStart& start) {
    const std::size_t n = state.script.strokes.size(), done = start.strokes;
    std::string report = "recovered " + std::to_string(n) + (n == 1 ? " stroke" : " strokes") +
                         (done > 0 ? " (from the checkpoint after stroke " + std::to_string(done) +
                                         ", " + std::to_string(n - done) + " replayed)"
                                   : " (replayed from the start)");
    if (!start.skipped.empty()) report += "; a checkpoint was skipped: " + start.skipped;
    if (!state.ignored.empty()) report += "; " + state.ignored;
    return report;
}

std::string sessionToRecover(const std::string& path) {
    std::error_code ec;
    if (fs::exists(journalPath(path), ec)) return path;
    if (!fs::is_directory(path, ec)) throw std::runtime_error(path + ": no such session directory");
    const std::vector<std::string> found = interruptedSessions(path);
    if (found.empty())
        throw std::runtime_error(path + ": there is no interrupted session to recover");
    return found.front();
}

std::string defaultSessionRoot() {
    if (const char* state = std::getenv("XDG_STATE_HOME"); state && *state == '/')
        return std::string(state) + "/sweepers/sessions";
    const char* home = std::getenv("HOME");
    return std::string(home && *home ? home : "/tmp") + "/.local/state/sweepers/sessions";
}

bool SessionLock::acquire(const std::string& dir) {
    release();
    const std::string path = dir + "/lock";
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) systemFailure(path, "cannot open", errno);
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        ::close(fd);
        return false;
    }
    fd_ = fd;
    return true;
}

void SessionLock::release() {
    if (fd_ >= 0) ::close(fd_); // closing the descriptor releases the lock
    fd_ = -1;
}

SessionLock& SessionLock::operator=(SessionLock&& o) noexcept {
    if (this != &o) {
        release();
        fd_ = o.fd_;
        o.fd_ = -1;
    }
    return *this;
}

bool discardSession(const std::string& dir) {
    SessionLock lock;
    if (!lock.acquire(dir)) return false;
    std::error_code ignored;
    fs::remove_all(dir, ignored);
    return true;
}

std::vector<std::string> interruptedSessions(const std::string& root) {
    std::vector<std::pair<fs::file_time_type, std::string>> found;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(root, ec)) {
        const std::string dir = entry.path().string();
        std::error_code e2;
        const auto written = fs::last_write_time(journalPath(dir), e2);
        if (e2) continue;
        SessionLock probe;
        if (!probe.acquire(dir)) continue; // its modeler is running
        // A journal of its opening record alone holds nothing that was not on disk already.
        std::ifstream in(journalPath(dir), std::ios::binary);
        std::string first, second;
        if (!std::getline(in, first) || !std::getline(in, second) || in.eof()) {
            probe.release();
            discardSession(dir);
            continue;
        }
        found.emplace_back(written, dir);
    }
    std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a > b; });
    std::vector<std::string> dirs;
    dirs.reserve(found.size());
    for (auto& f : found)
        dirs.push_back(std::move(f.second));
    return dirs;
}

} // namespace sweepers
