// SPDX-License-Identifier: Apache-2.0
// The modeler's document without a window: strokes, undo / redo, the recorded script,
// picking the surface.
#include <gtest/gtest.h>

#include "document/document.h"
#include "document_strokes.h"
#include "grids.h"
#include "io/mesh_file.h"
#include "io/start_grid.h"
#include "levelset/raycast.h"
#include "replay.h"
#include "scratch_dir.h"

using namespace sweepers;
using sweepers::test::differingVoxels;
using sweepers::test::drag;

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
    const StrokeScript replayed = loadStrokeScript(formatStrokeScript(doc.script()), "recorded");
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
