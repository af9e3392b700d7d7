// SPDX-License-Identifier: Apache-2.0
// Keeps the modeler's work safe against a crash (io/session_journal.h has the files): every
// completed edit is appended to the session's journal, and every few strokes a checkpoint of
// the grid is saved beside it. A thread of the session's own does all the writing, in
// order, so that neither the render thread nor the sculpting waits for a disk. After a
// crash, the next start finds the session (its lock is free) and rebuilds the document from
// the last checkpoint and the strokes after it, to the same grid.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "document/document.h"
#include "io/session_journal.h"

namespace sweepers {

struct SessionOptions {
    std::string root;                   // where session directories are made
    std::size_t checkpointStrokes = 20; // a checkpoint after this many new strokes,
    double checkpointSeconds = 60.0;    // or at the first stroke this long after the last one
    std::size_t keepCheckpoints = 4;    // older ones are removed
};

// What a new session takes over from the interrupted one a document was recovered from:
// the checkpoint the document started from moves into the new session, and the old
// session is removed once the new one is on disk.
struct Adoption {
    std::shared_ptr<SessionLock> lock; // on oldDir, so that no other modeler recovers it too
    std::string oldDir;
    std::string checkpoint; // empty: none
    std::size_t strokes = 0;
    std::string report; // what was recovered, in the user's words
};

class Session : public HistoryListener {
  public:
    // Makes its directory under options.root and takes its lock. Throws std::runtime_error
    // when the directory cannot be made.
    explicit Session(SessionOptions options);
    // Writes what is queued; the directory stays (as after a crash) unless close() was called.
    ~Session() override;
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    const std::string& dir() const { return dir_; }

    // A new journal for this document (its history so far), then every change to it. The
    // session must outlive the document, or the document be told of another listener.
    void follow(Document& doc, const Adoption& adopt = {});
    // The modeler ends and the user has decided about the document: the session goes.
    void close();
    // Waits until everything queued is on disk.
    void flush();
    // Why the journal stopped, once (empty when it did not). After a failure nothing more is
    // written until the next follow(): a hole in the journal would make the rest unusable.
    std::string takeError();
    std::size_t checkpointsWritten() const;
    // The newest checkpoint of the history's first `strokes` or fewer that can be read, and
    // how many strokes it holds (`done`); null when there is none.
    GridPtr checkpointAtOrBefore(std::size_t strokes, std::size_t& done) const;

    void appended(const Document& doc, const std::vector<Stroke>& strokes) override;
    void truncated(const Document& doc, std::size_t strokes) override;

  private:
    void post(std::function<void()> job);
    void run();
    void writeCheckpoint(const GridPtr& grid, std::size_t strokes);
    void dropCheckpoints(const std::function<bool(std::size_t strokes)>& which);
    void publish();

    SessionOptions opt_;
    std::string dir_;
    SessionLock lock_;
    // Render thread only.
    bool closed_ = false;
    std::size_t sinceCheckpoint_ = 0;
    std::chrono::steady_clock::time_point lastCheckpoint_;
    // Writer thread only.
    JournalWriter journal_;
    struct Checkpoint {
        std::string file;
        std::size_t strokes;
    };
    std::vector<Checkpoint> checkpoints_;
    std::size_t sequence_ = 0;
    bool failed_ = false;
    // Shared.
    mutable std::mutex mutex_;
    std::condition_variable wake_, idle_;
    std::deque<std::function<void()>> jobs_;
    bool stopping_ = false, busy_ = false;
    std::string error_;
    std::size_t written_ = 0;
    std::vector<Checkpoint> published_; // checkpoints_, for other threads
    std::thread writer_;
};

// The document of an interrupted session: its last readable checkpoint and the strokes
// after it; `adopt` is what the new session takes over, and the report.
std::unique_ptr<Document> recoverDocument(const std::string& sessionDir, Adoption& adopt,
                                          const Progress& progress = {},
                                          Interrupter* interrupter = nullptr);

} // namespace sweepers
