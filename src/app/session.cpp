// SPDX-License-Identifier: Apache-2.0
#include "app/session.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include <unistd.h>

#include "core/format.h"
#include "io/vdb_file.h"

namespace sweepers {

namespace fs = std::filesystem;

Session::Session(SessionOptions options) : opt_(std::move(options)) {
    char stamp[32];
    const std::time_t now = std::time(nullptr);
    std::tm local{};
    localtime_r(&now, &local);
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);
    std::error_code ec;
    fs::create_directories(opt_.root, ec);
    // Named for when it began (the newest is offered first), unique whatever else runs.
    std::string name = opt_.root + "/" + stamp + "-XXXXXX";
    if (!::mkdtemp(name.data()))
        throw std::runtime_error(
            opt_.root + ": cannot make a session directory there: " + std::strerror(errno));
    dir_ = name;
    if (!lock_.acquire(dir_)) throw std::runtime_error(dir_ + ": the session is in use");
    lastCheckpoint_ = std::chrono::steady_clock::now();
    writer_ = std::thread([this] { run(); });
}

Session::~Session() {
    {
        std::lock_guard<std::mutex> hold(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    writer_.join();
}

void Session::post(std::function<void()> job) {
    {
        std::lock_guard<std::mutex> hold(mutex_);
        jobs_.push_back(std::move(job));
    }
    wake_.notify_all();
}

void Session::run() {
    std::unique_lock<std::mutex> hold(mutex_);
    for (;;) {
        wake_.wait(hold, [this] { return stopping_ || !jobs_.empty(); });
        if (jobs_.empty()) break; // stopping, and everything is written
        std::function<void()> job = std::move(jobs_.front());
        jobs_.pop_front();
        busy_ = true;
        hold.unlock();
        std::string failure;
        try {
            job();
        } catch (const std::exception& e) {
            failure = e.what();
        }
        hold.lock();
        busy_ = false;
        if (!failure.empty()) {
            failed_ = true;
            if (error_.empty())
                error_ = "the session journal cannot be written (" + failure +
                         "): strokes from now on are not protected against a crash";
        }
        idle_.notify_all();
    }
}

void Session::flush() {
    std::unique_lock<std::mutex> hold(mutex_);
    idle_.wait(hold, [this] { return jobs_.empty() && !busy_; });
}

std::string Session::takeError() {
    std::lock_guard<std::mutex> hold(mutex_);
    return std::exchange(error_, std::string());
}

std::size_t Session::checkpointsWritten() const {
    std::lock_guard<std::mutex> hold(mutex_);
    return written_;
}

void Session::follow(Document& doc, const Adoption& adopt) {
    // The document it followed before may be gone already: it is not touched.
    doc.setHistoryListener(this);
    closed_ = false;
    sinceCheckpoint_ = 0;
    lastCheckpoint_ = std::chrono::steady_clock::now();
    post([this, script = doc.script(), scriptDir = doc.scriptDir(), adopt] {
        failed_ = false;
        dropCheckpoints([](std::size_t) { return true; });
        journal_.start(dir_, script, scriptDir);
        if (!adopt.checkpoint.empty()) {
            // The checkpoint the document was rebuilt from is this session's first.
            const std::string name = "checkpoint-" + std::to_string(++sequence_) + ".vdb";
            std::error_code ec;
            fs::rename(adopt.checkpoint, dir_ + "/" + name, ec);
            if (!ec) {
                journal_.checkpointed(name, adopt.strokes);
                checkpoints_.push_back({name, adopt.strokes});
                publish();
            }
        }
        // The new session is on disk: the interrupted one has nothing more to give.
        if (!adopt.oldDir.empty()) {
            std::error_code ignored;
            fs::remove_all(adopt.oldDir, ignored);
        }
    });
}

void Session::appended(const Document& doc, const std::vector<Stroke>& strokes) {
    if (closed_) return;
    post([this, strokes] {
        if (!failed_) journal_.appended(strokes);
    });
    sinceCheckpoint_ += strokes.size();
    const double since =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - lastCheckpoint_).count();
    if (sinceCheckpoint_ >= opt_.checkpointStrokes || since >= opt_.checkpointSeconds) {
        // A copy, taken while no sculpting runs; the writer saves it while sculpting goes on.
        GridPtr copy = doc.grid().deepCopy();
        const std::size_t k = doc.script().strokes.size();
        post([this, copy, k] { writeCheckpoint(copy, k); });
        sinceCheckpoint_ = 0;
        lastCheckpoint_ = std::chrono::steady_clock::now();
    }
}

void Session::truncated(const Document& /*doc*/, std::size_t strokes) {
    if (closed_) return;
    post([this, strokes] {
        if (failed_) return;
        journal_.truncated(strokes);
        // Checkpoints past the undo no longer belong to the history.
        dropCheckpoints([strokes](std::size_t k) { return k > strokes; });
    });
}

void Session::writeCheckpoint(const GridPtr& grid, std::size_t strokes) {
    if (failed_) return;
    const std::string name = "checkpoint-" + std::to_string(++sequence_) + ".vdb";
    writeLevelSet(*grid, dir_ + "/" + name); // atomic: a crash leaves no half checkpoint
    journal_.checkpointed(name, strokes);
    checkpoints_.push_back({name, strokes});
    publish();
    {
        std::lock_guard<std::mutex> hold(mutex_);
        ++written_;
    }
    if (checkpoints_.size() > opt_.keepCheckpoints) {
        const std::size_t keepFrom =
            checkpoints_[checkpoints_.size() - opt_.keepCheckpoints].strokes;
        dropCheckpoints([keepFrom](std::size_t k) { return k < keepFrom; });
    }
}

void Session::dropCheckpoints(const std::function<bool(std::size_t)>& which) {
    auto gone = std::stable_partition(checkpoints_.begin(), checkpoints_.end(),
                                      [&](const Checkpoint& c) { return !which(c.strokes); });
    std::vector<std::string> files;
    for (auto c = gone; c != checkpoints_.end(); ++c)
        files.push_back(dir_ + "/" + c->file);
    checkpoints_.erase(gone, checkpoints_.end());
    publish();
    for (const std::string& f : files) {
        std::error_code ignored;
        fs::remove(f, ignored);
    }
}

void Session::publish() {
    std::lock_guard<std::mutex> hold(mutex_);
    published_ = checkpoints_;
}

GridPtr Session::checkpointAtOrBefore(std::size_t strokes, std::size_t& done) const {
    std::vector<Checkpoint> list;
    {
        std::lock_guard<std::mutex> hold(mutex_);
        list = published_;
    }
    for (auto c = list.rbegin(); c != list.rend(); ++c) {
        if (c->strokes > strokes) continue;
        try {
            // A file of ours, which the writer may be removing meanwhile: one that does not
            // read is passed over for an older one.
            GridPtr g = readLevelSetInProcess(dir_ + "/" + c->file).grid;
            done = c->strokes;
            return g;
        } catch (const std::exception&) {
        }
    }
    done = 0;
    return nullptr;
}

void Session::close() {
    closed_ = true; // the document may still be told of changes: they are not kept
    flush();
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
    lock_.release();
}

std::unique_ptr<Document> recoverDocument(const std::string& sessionDir, Adoption& adopt,
                                          const Progress& progress, Interrupter* interrupter) {
    auto lock = std::make_shared<SessionLock>();
    if (!lock->acquire(sessionDir))
        throw std::runtime_error(sessionDir + ": that session is still running");
    const JournalState state = readJournal(sessionDir);
    RecoveryStart start = recoveryStart(state, interrupter);
    auto doc = std::make_unique<Document>(Document::resume(
        state.script, state.scriptDir, start.grid, start.strokes, progress, interrupter));
    doc->markModified(); // nothing of it is saved anywhere but in the session
    adopt =
        Adoption{lock, sessionDir, start.checkpoint, start.strokes, describeRecovery(state, start)};
    return doc;
}

} // namespace sweepers
