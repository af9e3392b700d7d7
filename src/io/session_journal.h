// SPDX-License-Identifier: Apache-2.0
// A modeler session on disk, so that a crash loses no completed stroke. A session is a
// directory holding
//   lock                 held (flock) by the running modeler: a free lock means its owner died
//   journal              the history, one JSON record per line (below)
//   checkpoint-N.vdb     the grid after the first K strokes of the history, now and then
//
// Journal records, in the order things happened:
//   {"session": 1, "dir": D, "script": {stroke script}}    the document as it was opened: its
//                                                         start, voxel size and history
//   {"append": [strokes]}                                 an edit ended (one undo step)
//   {"truncate": N}                                       undo: the history keeps N strokes
//   {"checkpoint": "checkpoint-3.vdb", "strokes": K}       the grid after the first K strokes
// A record is one write() of one line, fsync'd before the call returns: a crash can only
// cut the record being written, which reading ignores. Undo below a checkpoint's K makes it
// useless (later strokes may differ): reading drops it.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "io/stroke_script.h"
#include "levelset/interrupt.h"
#include "vdb/vdb.h"

namespace sweepers {

class JournalWriter {
  public:
    JournalWriter() = default;
    JournalWriter(const JournalWriter&) = delete;
    JournalWriter& operator=(const JournalWriter&) = delete;
    ~JournalWriter();

    // A new journal in `dir` for a document (its script, history included, and the
    // directory its relative file names are taken from); it replaces the journal there
    // atomically. Throws std::runtime_error saying why it cannot be written.
    void start(const std::string& dir, const StrokeScript& script, const std::string& scriptDir);
    void appended(const std::vector<Stroke>& strokes);
    void truncated(std::size_t strokes);
    void checkpointed(const std::string& file, std::size_t strokes);

  private:
    void append(const std::string& line);
    int fd_ = -1;
    std::string path_;
};

// What a journal says: the history as of its last complete record, and the checkpoints
// still valid for it.
struct JournalState {
    StrokeScript script;
    std::string scriptDir;
    struct Checkpoint {
        std::string file; // path
        std::size_t strokes = 0;
    };
    std::vector<Checkpoint> checkpoints; // oldest first
    std::size_t records = 0;
    // Empty, or what was left out at the end, in the user's words (a record cut short by
    // the crash is normal; anything else means damage).
    std::string ignored;
};

// Reads DIR/journal. Throws std::runtime_error when there is nothing to recover from (no
// journal, or a first record that cannot be read).
JournalState readJournal(const std::string& dir);

// The grid a recovery starts from: the newest checkpoint that can be read, or the script's
// start shape (strokes = 0, no checkpoint).
struct RecoveryStart {
    GridPtr grid;
    std::size_t strokes = 0; // of the history, already in the grid
    std::string checkpoint;  // the file it came from, empty for the start shape
    std::string skipped;     // why checkpoints newer than it could not be read
};
RecoveryStart recoveryStart(const JournalState& state, Interrupter* interrupter = nullptr);

// What a recovery rebuilt, in the user's words: "recovered 12 strokes (from the checkpoint
// after stroke 10, 2 replayed)", with what was skipped or ignored.
std::string describeRecovery(const JournalState& state, const RecoveryStart& start);

// The session a recovery reads: `path` itself when it holds a journal, else the newest
// interrupted session under it. Throws std::runtime_error when there is none.
std::string sessionToRecover(const std::string& path);

// Where sessions live: $XDG_STATE_HOME/sweepers/sessions, or ~/.local/state/sweepers/sessions.
std::string defaultSessionRoot();

// The lock a running session holds on its directory for as long as it lives (released by
// the kernel when the process dies, however it dies).
class SessionLock {
  public:
    SessionLock() = default;
    // Takes the lock of the directory `dir`; false when another process holds it.
    bool acquire(const std::string& dir);
    void release();
    ~SessionLock() { release(); }
    SessionLock(SessionLock&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
    SessionLock& operator=(SessionLock&& o) noexcept;
    SessionLock(const SessionLock&) = delete;
    SessionLock& operator=(const SessionLock&) = delete;

  private:
    int fd_ = -1;
};

// Removes an interrupted session (false when its modeler is running after all).
bool discardSession(const std::string& dir);

// Sessions under `root` whose modeler died with a journal in them (nobody holds their
// lock), newest journal first. Dead sessions whose journal holds nothing but its opening
// record are removed on the way: there is nothing in them to recover.
std::vector<std::string> interruptedSessions(const std::string& root);

} // namespace sweepers
