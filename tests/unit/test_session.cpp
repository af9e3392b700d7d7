// SPDX-License-Identifier: Apache-2.0
// Crash-safe sessions: the journal's records, what reading makes of a journal cut short or
// damaged, and a document rebuilt from a session that was never closed (as after a crash),
// which must hold the very grid the document held.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "app/session.h"
#include "grids.h"
#include "scratch_dir.h"

using namespace sweepers;
using sweepers::test::differingVoxels;
using sweepers::test::ScratchDir;

namespace {

SweepStroke dragStroke(const Eigen::Vector3d& p, const Eigen::Vector3d& d) {
    ToolSpec t;
    t.size = Eigen::Vector3d::Constant(0.3);
    t.falloff = 0.3;
    Placement a, b;
    a.t = p;
    b.t = p + d;
    t.path = {a, b};
    return SweepStroke{MirrorAxis::None, {t}};
}

void edit(Document& doc, const Stroke& s) {
    doc.beginEdit();
    doc.applyStroke(s);
    doc.endEdit();
}

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void spit(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

// Sessions kept in `root`, a checkpoint every `every` strokes.
SessionOptions sessionsIn(const ScratchDir& root, std::size_t every) {
    SessionOptions so;
    so.root = root.path.string();
    so.checkpointStrokes = every;
    return so;
}

// The only session directory under `root`.
std::string onlySession(const std::string& root) {
    std::vector<std::string> dirs;
    for (const auto& e : std::filesystem::directory_iterator(root))
        dirs.push_back(e.path().string());
    EXPECT_EQ(dirs.size(), 1u);
    return dirs.empty() ? "" : dirs.front();
}

} // namespace

TEST(SessionJournal, ReadsBackTheHistoryWithUndoAndCheckpoints) {
    ScratchDir dir;
    StrokeScript script = Document::sphereScript(1.0 / 16);
    script.strokes = {dragStroke({0, 0, 1}, {0, 0, 0.2})};
    {
        JournalWriter w;
        w.start(dir.path.string(), script, "/somewhere");
        w.appended({dragStroke({1, 0, 0}, {0.2, 0, 0}), InflateStroke{{0, 1, 0}, 0.1}});
        w.checkpointed("checkpoint-1.vdb", 3);
        w.truncated(2); // the checkpoint after 3 strokes no longer belongs to the history
        w.checkpointed("checkpoint-2.vdb", 2);
        w.appended({SwirlStroke{{0, -1, 0}, {0.1, 0, 0}, 0.3}});
    }
    const JournalState st = readJournal(dir.path.string());
    EXPECT_EQ(st.records, 6u);
    EXPECT_EQ(st.scriptDir, "/somewhere");
    EXPECT_TRUE(st.ignored.empty());
    ASSERT_EQ(st.script.strokes.size(), 3u);
    EXPECT_TRUE(std::holds_alternative<SweepStroke>(st.script.strokes[1]));
    EXPECT_TRUE(std::holds_alternative<SwirlStroke>(st.script.strokes[2]));
    ASSERT_EQ(st.checkpoints.size(), 1u);
    EXPECT_EQ(st.checkpoints[0].strokes, 2u);
    EXPECT_EQ(st.checkpoints[0].file, dir / "checkpoint-2.vdb");
    EXPECT_EQ(formatStrokeScript(st.script), [&] {
        StrokeScript s = script;
        s.strokes.push_back(dragStroke({1, 0, 0}, {0.2, 0, 0}));
        s.strokes.push_back(SwirlStroke{{0, -1, 0}, {0.1, 0, 0}, 0.3});
        return formatStrokeScript(s);
    }());
}

TEST(SessionJournal, ARecordCutShortOrDamagedEndsTheHistoryThere) {
    ScratchDir dir;
    StrokeScript script = Document::sphereScript(1.0 / 16);
    {
        JournalWriter w;
        w.start(dir.path.string(), script, ".");
        w.appended({InflateStroke{{0, 1, 0}, 0.1}});
        w.appended({InflateStroke{{0, -1, 0}, 0.1}});
    }
    const std::string journal = dir / "journal", whole = slurp(journal);

    // The crash came while the last record was being written.
    spit(journal, whole.substr(0, whole.size() - 7));
    JournalState st = readJournal(dir.path.string());
    EXPECT_EQ(st.script.strokes.size(), 1u);
    EXPECT_EQ(st.ignored, "the last record was cut short by the crash (ignored)");

    // Damage in the middle: what follows cannot be trusted.
    const std::size_t second = whole.find('\n') + 1;
    std::string damaged = whole;
    damaged[second + 3] = '#';
    spit(journal, damaged);
    st = readJournal(dir.path.string());
    EXPECT_EQ(st.script.strokes.size(), 0u);
    EXPECT_EQ(st.ignored, "the journal is damaged at line 2; what follows was left out");

    // A record that is JSON but not a stroke is damage too.
    spit(journal,
         whole.substr(0, second) + "{\"append\":[{\"type\":\"pinch\"}]}\n" + whole.substr(second));
    st = readJournal(dir.path.string());
    EXPECT_EQ(st.script.strokes.size(), 0u);
    EXPECT_EQ(st.ignored, "the journal is damaged at line 2; what follows was left out");

    // Nothing to recover from.
    spit(journal, "{\"session\":1}\n");
    EXPECT_THROW(readJournal(dir.path.string()), std::runtime_error);
    std::filesystem::remove(journal);
    try {
        readJournal(dir.path.string());
        ADD_FAILURE() << "a missing journal was read";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), journal + ": there is no session journal here");
    }
}

TEST(Session, ACrashedSessionRebuildsTheSameGrid) {
    ScratchDir root;
    const SessionOptions so = sessionsIn(root, 2);
    GridPtr expected;
    std::size_t strokes = 0;
    {
        Session session(so);
        Document doc(Document::sphereScript(1.0 / 24), ".");
        session.follow(doc);
        edit(doc, dragStroke({0, 0, 1}, {0, 0, 0.3}));
        edit(doc, dragStroke({1, 0, 0}, {0.25, 0.1, 0}));
        edit(doc, InflateStroke{{0, 1, 0}, 0.15}); // checkpoints after 2, 3 and 4 strokes
        doc.undo();                                // back to 2: the first still holds
        edit(doc, SwirlStroke{{0, -1, 0}, {0.1, 0, 0}, 0.3});
        edit(doc, dragStroke({0, 0, -1}, {0, 0, -0.2}));
        doc.undo();
        doc.redo();
        edit(doc, dragStroke({-1, 0, 0}, {-0.2, 0, 0}));
        session.flush();
        EXPECT_TRUE(session.takeError().empty());
        EXPECT_EQ(session.checkpointsWritten(), 3u);
        expected = doc.grid().deepCopy();
        strokes = doc.script().strokes.size();
        // No close(): the session stays on disk as a crash leaves it.
    }
    const std::string dir = onlySession(root.path.string());
    ASSERT_EQ(interruptedSessions(root.path.string()), std::vector<std::string>{dir});

    Adoption adopt;
    std::unique_ptr<Document> doc = recoverDocument(dir, adopt);
    EXPECT_EQ(doc->script().strokes.size(), strokes);
    EXPECT_EQ(differingVoxels(doc->grid(), *expected), 0u);
    EXPECT_EQ(doc->grid().activeVoxelCount(), expected->activeVoxelCount());
    EXPECT_TRUE(doc->modified());
    EXPECT_EQ(adopt.report, "recovered 5 strokes (from the checkpoint after stroke 4, 1 replayed)");

    // Without its checkpoints the history is replayed from the start, to the same grid.
    for (const auto& e : std::filesystem::directory_iterator(dir))
        if (e.path().extension() == ".vdb") std::filesystem::remove(e.path());
    adopt = {}; // lets go of the session's lock
    doc = recoverDocument(dir, adopt);
    EXPECT_EQ(differingVoxels(doc->grid(), *expected), 0u);
    // Only the newest one missing is named (the modeler removes old ones itself).
    const std::string newest = readJournal(dir).checkpoints.back().file;
    EXPECT_EQ(adopt.report, "recovered 5 strokes (replayed from the start); a checkpoint was "
                            "skipped: " +
                                newest + ": cannot open the file");

    // The new session takes the old one over, and a clean close leaves nothing behind.
    {
        Session next(so);
        next.follow(*doc, adopt);
        next.flush();
        EXPECT_FALSE(std::filesystem::exists(dir));
        EXPECT_EQ(readJournal(next.dir()).script.strokes.size(), strokes);
        EXPECT_TRUE(interruptedSessions(root.path.string()).empty()); // it is running
        next.close();
    }
    EXPECT_EQ(root.count(), 0u);
}

TEST(Session, RecoveryStartsFromTheNewestCheckpointThatCanBeRead) {
    ScratchDir root;
    const SessionOptions so = sessionsIn(root, 1);
    GridPtr expected;
    {
        Session session(so);
        Document doc(Document::sphereScript(1.0 / 24), ".");
        session.follow(doc);
        edit(doc, dragStroke({0, 0, 1}, {0, 0, 0.3}));
        edit(doc, InflateStroke{{0, 1, 0}, 0.15});
        edit(doc, dragStroke({1, 0, 0}, {0.2, 0, 0}));
        session.flush();
        expected = doc.grid().deepCopy();
    }
    const std::string dir = onlySession(root.path.string());
    const JournalState st = readJournal(dir);
    ASSERT_EQ(st.checkpoints.size(), 3u);
    spit(st.checkpoints[2].file, "not a vdb"); // the newest is damaged
    Adoption adopt;
    std::unique_ptr<Document> doc = recoverDocument(dir, adopt);
    EXPECT_EQ(differingVoxels(doc->grid(), *expected), 0u);
    const std::string said = "recovered 3 strokes (from the checkpoint after stroke 2, 1 "
                             "replayed); a checkpoint was skipped: " +
                             st.checkpoints[2].file + ": ";
    EXPECT_EQ(adopt.report.rfind(said, 0), 0u) << adopt.report;
    EXPECT_EQ(adopt.checkpoint, st.checkpoints[1].file);
}

TEST(Session, AJournalThatCannotBeWrittenSaysSoOnce) {
    ScratchDir root;
    const SessionOptions so = sessionsIn(root, 1);
    Session session(so);
    Document doc(Document::sphereScript(1.0 / 16), ".");
    session.follow(doc);
    session.flush();
    // The directory disappears under the session: the next checkpoint cannot be written.
    std::filesystem::remove_all(session.dir());
    edit(doc, InflateStroke{{0, 1, 0}, 0.15});
    session.flush();
    const std::string error = session.takeError();
    EXPECT_EQ(error.rfind("the session journal cannot be written (" + session.dir() +
                              "/checkpoint-1.vdb: ",
                          0),
              0u)
        << error;
    EXPECT_NE(error.find("): strokes from now on are not protected against a crash"),
              std::string::npos);
    edit(doc, InflateStroke{{0, -1, 0}, 0.15});
    session.flush();
    EXPECT_EQ(session.takeError(), ""); // said once; nothing more is written
}

TEST(Document, UndoBeyondTheBudgetReplaysTheHistoryAndRedoAppliesTheEditAgain) {
    Document doc(Document::sphereScript(1.0 / 24), ".");
    std::vector<GridPtr> after{doc.grid().deepCopy()};
    const std::vector<Stroke> strokes = {
        dragStroke({0, 0, 1}, {0, 0, 0.3}), InflateStroke{{0, 1, 0}, 0.15},
        SwirlStroke{{0, -1, 0}, {0.1, 0, 0}, 0.3}, dragStroke({1, 0, 0}, {0.25, 0.1, 0})};
    for (const Stroke& s : strokes) {
        edit(doc, s);
        after.push_back(doc.grid().deepCopy());
    }
    // Only the newest edit keeps its blocks.
    doc.setUndoBudget(doc.undoBytes() / 4);
    ASSERT_EQ(doc.undoCount(), 1u);
    EXPECT_FALSE(doc.undoNeedsReplay());
    doc.undo(); // from its blocks
    EXPECT_EQ(differingVoxels(doc.grid(), *after[3]), 0u);
    for (std::size_t k = 3; k-- > 0;) {
        ASSERT_TRUE(doc.undoNeedsReplay());
        EXPECT_EQ(doc.replayTarget(), k);
        doc.undo(); // by replay from the start
        EXPECT_EQ(doc.script().strokes.size(), k);
        EXPECT_EQ(differingVoxels(doc.grid(), *after[k]), 0u) << k;
    }
    EXPECT_FALSE(doc.canUndo());
    // The mesh kept with the grid is the grid's.
    SurfaceMesher fresh;
    fresh.rebuild(doc.grid());
    EXPECT_EQ(doc.mesher().triangleCount(), fresh.triangleCount());
    for (std::size_t k = 1; k <= 4; ++k) {
        ASSERT_TRUE(doc.canRedo());
        doc.redo();
        EXPECT_EQ(differingVoxels(doc.grid(), *after[k]), 0u) << k;
    }
    EXPECT_FALSE(doc.canRedo());
    EXPECT_EQ(formatStrokeScript(doc.script()), [&] {
        StrokeScript s = Document::sphereScript(1.0 / 24);
        s.strokes = strokes;
        return formatStrokeScript(s);
    }());
}

TEST(Session, UndoBeyondTheBudgetStartsFromACheckpointAndIsJournaled) {
    ScratchDir root;
    const SessionOptions so = sessionsIn(root, 2);
    Session session(so);
    Document doc(Document::sphereScript(1.0 / 24), ".");
    session.follow(doc);
    std::vector<GridPtr> after{doc.grid().deepCopy()};
    for (int k = 0; k < 5; ++k) {
        edit(doc, InflateStroke{{std::cos(k * 1.2), std::sin(k * 1.2), 0.2}, 0.15});
        after.push_back(doc.grid().deepCopy());
    }
    session.flush();
    doc.setUndoBudget(0); // every undo replays
    // The edit after stroke 4: from the checkpoint after stroke 4, nothing to replay.
    std::size_t done = 99;
    GridPtr from = session.checkpointAtOrBefore(doc.replayTarget(), done);
    ASSERT_TRUE(from);
    EXPECT_EQ(done, 4u);
    doc.undoByReplay(doc.replayTo(from, done));
    EXPECT_EQ(differingVoxels(doc.grid(), *after[4]), 0u);
    // After stroke 3: the checkpoint after stroke 2, and one stroke replayed.
    session.flush();
    from = session.checkpointAtOrBefore(doc.replayTarget(), done);
    EXPECT_EQ(done, 2u);
    doc.undoByReplay(doc.replayTo(from, done));
    EXPECT_EQ(differingVoxels(doc.grid(), *after[3]), 0u);
    // The journal knows: a crash now recovers the document as it is.
    session.flush();
    const JournalState st = readJournal(session.dir());
    EXPECT_EQ(st.script.strokes.size(), 3u);
    ScratchDir crashed; // the session as a crash would leave it (this one is still running)
    std::filesystem::copy(session.dir(), crashed.path / "s",
                          std::filesystem::copy_options::recursive);
    Adoption adopt;
    const std::unique_ptr<Document> back = recoverDocument(crashed / "s", adopt);
    EXPECT_EQ(differingVoxels(back->grid(), *after[3]), 0u) << adopt.report;
}
