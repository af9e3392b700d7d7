// SPDX-License-Identifier: Apache-2.0
// The modeler's document without a window: strokes, undo / redo, the recorded script,
// picking the surface, and the timeline that plays its history as a film.
#include <gtest/gtest.h>

#include "app/document.h"
#include "app/timeline.h"
#include "grids.h"
#include "io/mesh_file.h"
#include "io/start_grid.h"
#include "levelset/raycast.h"
#include "replay.h"
#include "scratch_dir.h"

using namespace sweepers;
using sweepers::test::differingVoxels;

namespace {

ToolSpec ballAt(const Eigen::Vector3d& p) {
    ToolSpec t;
    t.size = Eigen::Vector3d::Constant(0.25);
    t.falloff = 0.3;
    Placement pl;
    pl.t = p;
    t.path = {pl};
    return t;
}

// A drag of `n` segments from p along d.
void drag(Document& doc, const Eigen::Vector3d& p, const Eigen::Vector3d& d, int n) {
    doc.beginStroke(ballAt(p), MirrorAxis::None);
    for (int i = 1; i <= n; ++i) {
        Placement pl;
        pl.t = p + d * (double(i) / n);
        doc.extendStroke(pl);
    }
    doc.endStroke();
}

} // namespace

TEST(Document, UndoRestoresTheGridExactlyAndRedoReappliesIt) {
    Document doc(Document::sphereScript(1.0 / 32), ".");
    const GridPtr start = doc.grid().deepCopy();
    drag(doc, {0, 0, 1}, {0, 0, 0.4}, 4);
    const GridPtr one = doc.grid().deepCopy();
    drag(doc, {1, 0, 0}, {0.3, 0.2, 0}, 3);
    drag(doc, {0, -1, 0}, {0, 0.5, 0}, 5); // pushes in
    const GridPtr three = doc.grid().deepCopy();
    ASSERT_GT(differingVoxels(*start, *three), 1000u); // the strokes did something
    EXPECT_EQ(doc.undoCount(), 3u);
    EXPECT_EQ(doc.script().strokes.size(), 3u);

    doc.undo();
    doc.undo();
    EXPECT_EQ(differingVoxels(doc.grid(), *one), 0u);
    EXPECT_EQ(doc.script().strokes.size(), 1u);
    doc.undo();
    EXPECT_EQ(differingVoxels(doc.grid(), *start), 0u);
    EXPECT_FALSE(doc.canUndo());

    doc.redo();
    EXPECT_EQ(differingVoxels(doc.grid(), *one), 0u);
    doc.redo();
    doc.redo();
    EXPECT_EQ(differingVoxels(doc.grid(), *three), 0u);
    EXPECT_EQ(doc.script().strokes.size(), 3u);
    EXPECT_FALSE(doc.canRedo());

    // The incrementally kept mesh is the mesh of the restored grid.
    doc.undo();
    SurfaceMesher fresh;
    fresh.rebuild(doc.grid());
    EXPECT_EQ(doc.mesher().triangleCount(), fresh.triangleCount());
    EXPECT_NEAR(doc.mesher().enclosedVolume(), fresh.enclosedVolume(), 1e-9);
}

TEST(Document, UndoKeepsWithinItsBudget) {
    Document doc(Document::sphereScript(1.0 / 32), ".");
    drag(doc, {0, 0, 1}, {0, 0, 0.3}, 3);
    const std::size_t oneStroke = doc.undoBytes();
    ASSERT_GT(oneStroke, 0u);
    doc.setUndoBudget(oneStroke * 2 + oneStroke / 2);
    for (int i = 0; i < 4; ++i)
        drag(doc, {std::cos(i * 1.5), std::sin(i * 1.5), 0}, {0, 0, 0.2}, 2);
    EXPECT_LE(doc.undoBytes(), doc.undoBudget());
    EXPECT_GE(doc.undoCount(), 1u);
    EXPECT_LT(doc.undoCount(), 5u);
    EXPECT_EQ(doc.script().strokes.size(), 5u); // the history is all in the script
}

TEST(Document, RecordedScriptReplaysToTheSameGrid) {
    Document doc(Document::sphereScript(1.0 / 32), ".");
    drag(doc, {0, 0, 1}, {0.2, 0, 0.4}, 6);
    drag(doc, {0.7, 0.7, 0}, {-0.2, -0.2, 0.1}, 3);
    doc.undo(); // an undone stroke is not in the script
    drag(doc, {0, 1, 0}, {0, 0.3, 0.1}, 2);
    // A volume-preserving drag (swirls, one per drag event) and a dab of clay: one undo
    // step each, replayed like the rest.
    const GridPtr beforeSwirls = doc.grid().deepCopy();
    doc.beginEdit();
    for (int i = 0; i < 3; ++i) {
        SwirlStroke sw;
        sw.at = {0.9 + 0.05 * i, 0.2, 0.3};
        sw.move = {0.05, 0.02, 0};
        sw.radius = 0.3;
        doc.applyStroke(sw);
    }
    doc.endEdit();
    ASSERT_GT(differingVoxels(*beforeSwirls, doc.grid()), 100u);
    doc.beginEdit();
    doc.applyStroke(InflateStroke{{0, 0, -1}, 0.15});
    doc.endEdit();
    doc.undo();
    doc.undo();
    EXPECT_EQ(differingVoxels(*beforeSwirls, doc.grid()), 0u);
    doc.redo();
    doc.redo();
    EXPECT_EQ(doc.script().strokes.size(), 6u);
    const StrokeScript replayed = parseStrokeScript(formatStrokeScript(doc.script()), "recorded");
    const GridPtr g = applyScript(replayed, ".");
    EXPECT_EQ(differingVoxels(*g, doc.grid()), 0u);
}

TEST(Raycast, HitsTheSphereWhereTheRayEntersIt) {
    Document doc(Document::sphereScript(1.0 / 32), ".");
    const auto hit = raycastLevelSet(doc.grid(), {0.3, 0.2, 5}, {0, 0, -1}, 100);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->norm(), 1.0, 0.01);
    EXPECT_GT(hit->z(), 0.0);
    EXPECT_FALSE(raycastLevelSet(doc.grid(), {3, 0, 5}, {0, 0, -1}, 100));
    EXPECT_FALSE(raycastLevelSet(doc.grid(), {0, 0, 5}, {0, 0, 1}, 100)); // facing away
}

TEST(Document, ImportsAMeshAndReplaysItsHistoryAtAnotherVoxelSize) {
    Document sphere(Document::sphereScript(1.0 / 32), ".");
    const test::ScratchDir dir;
    const std::string stl = dir / "sphere.stl";
    writeMesh(sphere.mesher().weld(), stl);
    Document imported = Document::open(stl, 1.0 / 32);
    EXPECT_EQ(imported.script().start.kind, StartShape::Kind::Mesh);
    EXPECT_NEAR(imported.mesher().enclosedVolume(), sphere.mesher().enclosedVolume(),
                0.01 * sphere.mesher().enclosedVolume());

    drag(sphere, {0, 0, 1}, {0, 0.2, 0.3}, 3);
    const Document fine = Document::replayAt(sphere.script(), ".", 1.0 / 48);
    EXPECT_DOUBLE_EQ(fine.grid().voxelSize()[0], 1.0 / 48);
    EXPECT_EQ(fine.script().strokes.size(), 1u);
    const GridPtr g = applyScript(sphere.script(), ".", 1.0 / 48);
    EXPECT_EQ(differingVoxels(*g, fine.grid()), 0u);
}

TEST(Document, AVdbStartIsNotReplayedAtAnotherVoxelSize) {
    Document sphere(Document::sphereScript(1.0 / 32), ".");
    const test::ScratchDir dir;
    const std::string vdb = dir / "start.vdb";
    sphere.saveVdb(vdb);
    const Document opened = Document::open(vdb);
    EXPECT_EQ(differingVoxels(opened.grid(), sphere.grid()), 0u);
    try {
        Document::replayAt(opened.script(), opened.scriptDir(), 1.0 / 40);
        FAIL() << "a VDB start was replayed at another voxel size";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("cannot be replayed at another voxel size"),
                  std::string::npos)
            << e.what();
    }
}

TEST(Timeline, ScrubsPlaysAndGoesBackOverTheHistory) {
    Document doc(Document::sphereScript(1.0 / 32), ".");
    drag(doc, {0, 0, 1}, {0, 0, 0.4}, 4); // 4 segments of a quarter second: 25 frames
    FilmTiming timing;
    std::vector<GridPtr> film(1);
    Sculptor reference(makeStartGrid(doc.script(), "."));
    playFilm(reference, doc.script(), timing, 1, 1000,
             [&](std::size_t, double, const Grid& g) { film.push_back(g.deepCopy()); });
    ASSERT_EQ(film.size(), 26u);

    Timeline tl(doc, timing);
    EXPECT_EQ(tl.frameCount(), 25u);
    Clock::time_point now = Clock::now();
    // Every frame asked for is made (no time passes meanwhile).
    auto settle = [&] {
        tl.step(now);
        while (tl.busy() || tl.shown() != tl.wanted()) {
            tl.wait();
            tl.step(now);
        }
        EXPECT_TRUE(tl.takeMessage().empty());
    };
    auto same = [&](std::size_t n) {
        ASSERT_EQ(tl.shown(), n);
        ASSERT_NE(tl.grid(), nullptr);
        EXPECT_EQ(differingVoxels(*tl.grid(), *film[n]), 0u) << "frame " << n;
    };
    settle();
    same(1);
    EXPECT_TRUE(tl.takeMeshChanges().all);
    const double start = tl.mesher()->enclosedVolume();
    tl.scrubTo(13); // the middle of the drag: half of the horn
    settle();
    same(13);
    EXPECT_FALSE(tl.takeMeshChanges().all); // on from frame 1: only what changed
    const double middle = tl.mesher()->enclosedVolume(), end = doc.mesher().enclosedVolume();
    EXPECT_GT(middle, start + 0.1 * (end - start));
    EXPECT_LT(middle, end - 0.1 * (end - start));
    tl.scrubTo(5); // back: the film is played again from the start shape
    settle();
    same(5);
    EXPECT_TRUE(tl.takeMeshChanges().all);
    // Half a second of play at twice the speed is 24 frames on: the end, where play stops.
    tl.setSpeed(2.0);
    tl.play(now);
    now += std::chrono::milliseconds(250);
    settle();
    same(17);
    EXPECT_TRUE(tl.playing());
    now += std::chrono::milliseconds(250);
    settle();
    same(25);
    EXPECT_FALSE(tl.playing());
    EXPECT_EQ(differingVoxels(*tl.grid(), doc.grid()), 0u);
    tl.scrubTo(1000);
    EXPECT_EQ(tl.wanted(), 25u);
    tl.play(now); // from the end: from the start again
    EXPECT_EQ(tl.wanted(), 1u);
    tl.pause();
    // Asked back while a later frame is being made: that work stops, the frame asked for
    // comes from the start shape.
    settle();
    tl.scrubTo(25);
    tl.step(now);
    EXPECT_TRUE(tl.busy());
    tl.scrubTo(2);
    settle();
    same(2);
}
