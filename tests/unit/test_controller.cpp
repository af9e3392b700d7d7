// SPDX-License-Identifier: Apache-2.0
// The modeler's input logic without a window: drags become placements and strokes, fast
// twists keep the hand's direction, and long work can be cancelled, leaving the document
// and the mesh as they were.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#define GLFW_INCLUDE_NONE // key codes only
#include <GLFW/glfw3.h>
#include <openvdb/tools/Interpolation.h>

#include "app/sculpt_controller.h"
#include "grids.h"
#include "io/stroke_script.h"
#include "io/vdb_file.h"
#include "levelset/band.h"
#include "levelset/create.h"
#include "levelset/measure.h"
#include "levelset/raycast.h"
#include "levelset/renormalize.h"
#include "replay.h"
#include "scratch_dir.h"

using namespace sweepers;
using sweepers::test::differingVoxels;

namespace {

constexpr int kWidth = 640, kHeight = 480;

// Says stop at its n-th poll (counting from 1), and at every poll after.
class StopAfter : public Interrupter {
  public:
    explicit StopAfter(int n) : left_(n) {}
    bool wasInterrupted(int = -1) override { return --left_ <= 0; }

  private:
    std::atomic<int> left_;
};

// A document on a sculpt controller, looked at whole (not the crash-safety Session).
struct Bench {
    Document doc{Document::sphereScript(1.0 / 32), "."};
    SculptController ctl{/*waitEachPiece=*/true};
    Bench() {
        ctl.setViewport(kWidth, kHeight);
        ctl.setDocument(&doc);
        ctl.frameView();
    }
    // A twist drag from the centre of the view `pixels` to the right, in moves of `step`
    // pixels (one move when step >= pixels), one frame each.
    void twist(double pixels, double step) {
        ctl.onKey('T', false, false);
        const double x0 = kWidth / 2.0, y0 = kHeight / 2.0;
        ctl.onButton(0, true, x0, y0, false);
        ASSERT_EQ(ctl.drag(), DragKind::Sculpt) << "the press missed the sphere";
        for (double d = std::min(step, pixels);; d = std::min(d + step, pixels)) {
            ctl.onMove(x0 + d, y0);
            ctl.step();
            if (d >= pixels) break;
        }
        ctl.onButton(0, false, x0 + pixels, y0, false);
        ctl.wait();
        ctl.step();
        ASSERT_EQ(ctl.drag(), DragKind::None);
        ASSERT_EQ(ctl.takeMessage(), "");
    }
    const ToolSpec& tool() const {
        return std::get<SweepStroke>(doc.script().strokes.back()).tools[0];
    }
};

// How far (degrees, signed, unwrapped) a point of the tool's coating turns about the twist
// axis through all the segments of the recorded stroke.
double coatingTurn(const ToolSpec& tool) {
    const Sweep sweep = toSweep(SweepStroke{MirrorAxis::None, {tool}});
    const Eigen::Vector3d c = tool.path[0].t, axis = tool.path[1].axis.normalized();
    const Eigen::Vector3d u = axis.unitOrthogonal(), v = axis.cross(u);
    // Half-way through the falloff: the coating turns by part of the tool's angle.
    Eigen::Vector3d p = c + (tool.size.x() + 0.5 * tool.falloff) * u;
    double turned = 0.0;
    auto angle = [&](const Eigen::Vector3d& q) {
        const Eigen::Vector3d d = q - c;
        return std::atan2(d.dot(v), d.dot(u)) * 180.0 / M_PI;
    };
    for (std::size_t k = 0; k < sweep.segmentCount(); ++k) {
        const double before = angle(p);
        p = SweepSegment(sweep, k).forwardMap(p).p;
        double d = angle(p) - before;
        d -= 360.0 * std::round(d / 360.0); // one segment turns less than half a turn
        turned += d;
    }
    return turned;
}

} // namespace

TEST(SculptController, AFastTwistTurnsTheWayTheHandWent) {
    // 2000 pixels right in one move (the angle saturates at 720 degrees) against the same
    // drag in 20-pixel moves, and 400 pixels (200 degrees) both ways.
    for (const double pixels : {400.0, 2000.0}) {
        Bench slow, flick;
        slow.twist(pixels, 20);
        flick.twist(pixels, pixels);
        for (const Bench* s : {&slow, &flick}) {
            const auto& path = s->tool().path;
            for (std::size_t i = 1; i < path.size(); ++i)
                ASSERT_LT(std::abs(path[i].angleDegrees - path[i - 1].angleDegrees),
                          kMaxTwistStepDegrees + 1e-9)
                    << "placements " << i - 1 << " and " << i;
            EXPECT_DOUBLE_EQ(path.back().angleDegrees, std::min(0.5 * pixels, 720.0));
        }
        const double a = coatingTurn(slow.tool()), b = coatingTurn(flick.tool());
        std::printf("[ twist ] %g pixels: the coating turns %.2f degrees (slow drag, %zu "
                    "placements) and %.2f (one move, %zu placements)\n",
                    pixels, a, slow.tool().path.size(), b, flick.tool().path.size());
        EXPECT_GT(a, 10.0);
        EXPECT_NEAR(b, a, 0.02 * a);
    }
}

TEST(SculptController, EveryReplayFileSculptsAndRecordsAScriptThatReplaysExactly) {
    // The modeler's own test input, without a window: every file sculpts something, and
    // the recorded script, applied as sweepers-cli applies it, gives the same grid.
    std::size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(SWEEPERS_APP_TEST_DIR)) {
        if (entry.path().extension() != ".json") continue;
        InputReplay replay;
        try {
            replay = readInputReplay(entry.path().string());
        } catch (const std::exception&) {
            continue; // a stroke script, not events
        }
        ++files;
        const std::string name = entry.path().filename().string();
        Document doc(Document::sphereScript(1.0 / 32), ".");
        SculptController ctl(/*waitEachPiece=*/true);
        // The window the file's clicks belong to (every one of them names it).
        EXPECT_GT(replay.width, 0) << name << " names no window";
        ctl.setViewport(replay.width > 0 ? replay.width : kWidth,
                        replay.height > 0 ? replay.height : kHeight);
        ctl.setDocument(&doc);
        ctl.frameView();
        const GridPtr before = doc.grid().deepCopy();
        replayEvents(ctl, replay.events);
        doc.endEdit();
        EXPECT_EQ(ctl.takeMessage(), "") << name;
        ASSERT_FALSE(doc.script().strokes.empty()) << name;
        EXPECT_GT(differingVoxels(*before, doc.grid()), 100u) << name;
        const StrokeScript recorded =
            loadStrokeScript(formatStrokeScript(doc.script()), "recorded " + name);
        EXPECT_EQ(differingVoxels(*applyScript(recorded, "."), doc.grid()), 0u) << name;
        std::printf("[ replay ] %s: %zu strokes\n", name.c_str(), doc.script().strokes.size());
    }
    EXPECT_GE(files, 4u);
}

TEST(SculptController, EscapeCancelsTheDragAndPutsTheShapeBack) {
    Bench s;
    const GridPtr before = s.doc.grid().deepCopy();
    const double volume = s.doc.mesher().enclosedVolume();
    s.ctl.onKey('G', false, false);
    s.ctl.onButton(0, true, kWidth / 2.0, kHeight / 2.0, false);
    s.ctl.onMove(kWidth / 2.0 + 30, kHeight / 2.0);
    s.ctl.step();
    s.ctl.wait();
    s.ctl.step();
    ASSERT_GT(differingVoxels(*before, s.doc.grid()), 100u);
    // The next segment is cancelled (Esc while it runs is the same flag, set earlier).
    s.ctl.onMove(kWidth / 2.0 + 60, kHeight / 2.0);
    s.ctl.cancel();
    s.ctl.step();
    s.ctl.wait();
    s.ctl.step();
    EXPECT_EQ(s.ctl.drag(), DragKind::None);
    EXPECT_NE(s.ctl.takeMessage().find("cancelled"), std::string::npos);
    EXPECT_EQ(differingVoxels(*before, s.doc.grid()), 0u);
    EXPECT_DOUBLE_EQ(s.doc.mesher().enclosedVolume(), volume);
    EXPECT_TRUE(s.doc.script().strokes.empty());
    EXPECT_FALSE(s.doc.canUndo());
    // And sculpting goes on afterwards.
    s.ctl.onButton(0, true, kWidth / 2.0, kHeight / 2.0, false);
    s.ctl.onMove(kWidth / 2.0 + 30, kHeight / 2.0);
    s.ctl.step();
    s.ctl.onButton(0, false, kWidth / 2.0 + 30, kHeight / 2.0, false);
    s.ctl.wait();
    s.ctl.step();
    EXPECT_EQ(s.doc.script().strokes.size(), 1u);
}

// A hand that keeps moving: each piece of the drag starts as soon as the one before ends,
// and in between (the controller's idle call) the window takes the mesh of the piece that
// ended, so every piece is seen on screen, not only the last one after the hand stops. A
// release that starts the last piece takes the one before it the same way.
TEST(SculptController, BetweenPiecesOfADragTheWindowTakesEachPiecesMesh) {
    Document doc{Document::sphereScript(1.0 / 32), "."};
    SculptController ctl; // pieces run while events come in, as in the window
    ctl.setViewport(kWidth, kHeight);
    ctl.setDocument(&doc);
    ctl.frameView();
    doc.takeMeshChanges(); // the sphere's
    int meshesTaken = 0;
    ctl.setIdle([&] { meshesTaken += doc.takeMeshChanges().any(); });
    constexpr int kMoves = 5;
    const double x0 = kWidth / 2.0, y0 = kHeight / 2.0;
    ctl.onKey('G', false, false);
    ctl.onButton(0, true, x0, y0, false);
    ASSERT_EQ(ctl.drag(), DragKind::Sculpt) << "the press missed the sphere";
    for (int k = 1; k <= kMoves; ++k) {
        ctl.onMove(x0 + 10.0 * k, y0);
        ctl.step(); // takes the piece before, and starts this one
        ASSERT_TRUE(ctl.busy());
        EXPECT_EQ(meshesTaken, k - 1);
        ctl.wait();
    }
    // Released farther on: one piece more, started by the release.
    ctl.onButton(0, false, x0 + 10.0 * (kMoves + 1), y0, false);
    ASSERT_TRUE(ctl.busy());
    EXPECT_EQ(meshesTaken, kMoves);
    ctl.wait();
    ctl.step();
    EXPECT_EQ(ctl.drag(), DragKind::None);
    EXPECT_EQ(meshesTaken, kMoves + 1);
    ASSERT_EQ(doc.script().strokes.size(), 1u);
    EXPECT_EQ(std::get<SweepStroke>(doc.script().strokes[0]).tools[0].path.size(),
              std::size_t(kMoves + 2));
}

TEST(Cancel, EveryLongOperationStopsAndLeavesItsInputAsItWas) {
    const GridPtr sphere = makeSphere({0, 0, 0}, 1.0, 1.0 / 48, 3.0);
    // Renormalization: nothing written back.
    {
        GridPtr g = sphere->deepCopy();
        for (auto it = g->tree().beginValueOn(); it; ++it)
            it.setValue(1.5f * *it); // no longer a distance
        const GridPtr stretched = g->deepCopy();
        StopAfter stop(2);
        RenormalizeOptions o;
        o.interrupter = &stop;
        EXPECT_THROW(renormalize(*g, o), Cancelled);
        EXPECT_EQ(differingVoxels(*stretched, *g), 0u);
    }
    // Whole-grid meshing: the mesher keeps its mesh.
    {
        SurfaceMesher mesher;
        mesher.rebuild(*makeSphere({0, 0, 0}, 0.5, 1.0 / 48, 3.0));
        const std::size_t triangles = mesher.triangleCount();
        StopAfter stop(3);
        EXPECT_THROW(mesher.rebuild(*sphere, &stop), Cancelled);
        EXPECT_EQ(mesher.triangleCount(), triangles);
    }
    // Mesh import.
    {
        const TriangleMesh m = meshLevelSet(*sphere);
        StopAfter stop(1);
        EXPECT_THROW(levelSetFromMesh(m.positions, m.triangles, 1.0 / 48, 3.0, &stop), Cancelled);
    }
    // A resample (a history replayed): no document is made.
    {
        StrokeScript script = Document::sphereScript(1.0 / 32);
        script.strokes.push_back(InflateStroke{{0, 0, 0.9}, 0.2});
        StopAfter stop(5);
        EXPECT_THROW(Document::replayAt(script, ".", 1.0 / 48, {}, &stop), Cancelled);
    }
}

TEST(SculptController, PinchModeGoesThroughTheShapeAlongTheView) {
    // P, a press on the middle of the sphere and a drag: the pinch's needles lie on the view
    // ray through the press, on either side of the sphere, the drag sets the hole's radius,
    // and the preview shows it all before the release applies it: a torus.
    Bench s;
    s.ctl.onKey('P', false, false);
    const double x0 = kWidth / 2.0, y0 = kHeight / 2.0;
    s.ctl.onButton(0, true, x0, y0, false);
    ASSERT_EQ(s.ctl.drag(), DragKind::Sculpt);
    double x = x0, firstOpen = 0.0;
    std::optional<Stroke> stroke;
    for (; x < kWidth; x += 2) {
        s.ctl.onMove(x, y0);
        s.ctl.step();
        stroke = s.ctl.topologyStroke();
        ASSERT_TRUE(stroke);
        if (x == x0) firstOpen = std::get<PinchStroke>(*stroke).open;
        if (std::get<PinchStroke>(*stroke).open >= 0.3) break;
    }
    EXPECT_LT(firstOpen, 0.1); // the drag opens the hole
    EXPECT_LT(x, kWidth);
    const PinchStroke& pinch = std::get<PinchStroke>(*stroke);
    const Eigen::Vector3d eye(s.ctl.camera().eye().x, s.ctl.camera().eye().y,
                              s.ctl.camera().eye().z);
    // The view ray through the middle of the window goes through the sphere's centre.
    const double h = s.doc.grid().voxelSize()[0];
    EXPECT_LT(pinch.at.norm(), h);
    EXPECT_LT((pinch.axis.normalized() + eye.normalized()).norm(), 1e-6);
    // At this coarse voxel size the falloff is raised to 16 voxels (0.25 asked).
    EXPECT_EQ(pinch.falloff, kMinPinchFalloffVoxels * h);
    EXPECT_NEAR(pinch.size, 1.0 + 0.5 * pinch.falloff, h);
    EXPECT_GE(strokePreview(*stroke).size(), 4u);
    EXPECT_TRUE(s.doc.script().strokes.empty()); // nothing applied before the release
    s.ctl.onButton(0, false, x, y0, false);
    s.ctl.wait();
    s.ctl.step();
    EXPECT_EQ(s.ctl.drag(), DragKind::None);
    EXPECT_EQ(s.ctl.takeMessage(), "");
    ASSERT_EQ(s.doc.script().strokes.size(), 1u);
    EXPECT_TRUE(std::holds_alternative<PinchStroke>(s.doc.script().strokes[0]));
    EXPECT_EQ(topologicalEulerCharacteristic(s.doc.grid()), 0);
    // One undo step.
    s.doc.undo();
    EXPECT_EQ(topologicalEulerCharacteristic(s.doc.grid()), 2);
}

TEST(SculptController, StrangleModeCutsAroundTheLimbUnderTheCursor) {
    // K, a press on the middle of the sphere and a drag across it, past its outline: the
    // circle lies in the plane of the drag and the view, around the sphere's centre, and the
    // release cuts the sphere in two. A release without a drag says what to do instead.
    Bench s;
    s.ctl.onKey('K', false, false);
    const double x0 = kWidth / 2.0, y0 = kHeight / 2.0;
    s.ctl.onButton(0, true, x0, y0, false);
    s.ctl.onButton(0, false, x0, y0, false);
    s.ctl.step();
    EXPECT_NE(s.ctl.takeMessage().find("drag across the limb"), std::string::npos);
    EXPECT_EQ(s.ctl.drag(), DragKind::None);
    EXPECT_TRUE(s.doc.script().strokes.empty());

    s.ctl.onButton(0, true, x0, y0, false);
    double x = x0;
    std::optional<Stroke> stroke;
    for (; x < kWidth; x += 2) {
        s.ctl.onMove(x, y0);
        s.ctl.step();
        stroke = s.ctl.topologyStroke();
        if (stroke && std::get<StrangleStroke>(*stroke).size >= 1.15) break;
    }
    ASSERT_TRUE(stroke);
    const StrangleStroke& strangle = std::get<StrangleStroke>(*stroke);
    const double h = s.doc.grid().voxelSize()[0];
    EXPECT_LT(strangle.at.norm(), h);
    // A horizontal drag seen from the front: the circle is upright, its axis vertical in
    // the view.
    const Eigen::Vector3d eye(s.ctl.camera().eye().x, s.ctl.camera().eye().y,
                              s.ctl.camera().eye().z);
    EXPECT_LT(std::abs(strangle.axis.normalized().dot(eye.normalized())), 1e-6);
    s.ctl.onButton(0, false, x, y0, false);
    s.ctl.wait();
    s.ctl.step();
    EXPECT_EQ(s.ctl.takeMessage(), "");
    ASSERT_EQ(s.doc.script().strokes.size(), 1u);
    EXPECT_EQ(measureLevelSet(s.doc.grid()).components, 2u);
}

TEST(SculptController, AToolFromAFileGrabsAndIsRecordedByItsFile) {
    // "Tool from file": grab drags move the file's shape; the recorded script names the
    // file and replays to the same grid. A file that cannot be a tool is refused with its
    // reason; "Ball" goes back to the ball.
    sweepers::test::ScratchDir dir;
    writeLevelSet(*makeSphere(Eigen::Vector3d::Zero(), 1.0, 1.0 / 16, 3.0), dir / "tool.vdb");
    std::ofstream(dir / "broken.vdb") << "not a vdb";
    Bench s;
    try {
        s.ctl.useToolFile(dir / "broken.vdb");
        ADD_FAILURE() << "a broken file was taken as a tool";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("broken.vdb"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(s.ctl.settings().bakedTool);
    s.ctl.useToolFile(dir / "tool.vdb");
    ASSERT_TRUE(s.ctl.settings().bakedTool);
    const GridPtr before = s.doc.grid().deepCopy();
    auto drag = [&] {
        s.ctl.onButton(0, true, kWidth / 2.0, kHeight / 2.0, false);
        for (int k = 1; k <= 3; ++k) {
            s.ctl.onMove(kWidth / 2.0 + 10 * k, kHeight / 2.0 - 10 * k);
            s.ctl.step();
        }
        s.ctl.onButton(0, false, kWidth / 2.0 + 30, kHeight / 2.0 - 30, false);
        s.ctl.wait();
        s.ctl.step();
        ASSERT_EQ(s.ctl.takeMessage(), "");
    };
    drag();
    EXPECT_GT(differingVoxels(*before, s.doc.grid()), 100u);
    EXPECT_EQ(s.tool().shape, ToolShapeKind::Baked);
    EXPECT_EQ(s.tool().source.file, std::filesystem::absolute(dir / "tool.vdb").string());
    // Half the tool's extent is the radius.
    const Box b = s.tool().baked->place(Eigen::Affine3d::Identity())->bounds();
    EXPECT_NEAR(0.5 * b.extent().maxCoeff(), s.ctl.settings().radius, 1e-9);
    s.ctl.useBall();
    drag();
    EXPECT_EQ(s.tool().shape, ToolShapeKind::Ball);
    const StrokeScript recorded = loadStrokeScript(formatStrokeScript(s.doc.script()), "recorded");
    EXPECT_EQ(differingVoxels(*applyScript(recorded, "."), s.doc.grid()), 0u);
}

TEST(SculptController, FluidModePushesTheClayAsAFluidAndKeepsItsVolume) {
    // U, then a drag of two moves from the sphere's silhouette outward: each move becomes a
    // fluid stroke of the tool's radius from the last position to this one (the swept fluid,
    // 4.2).
    Bench b;
    b.ctl.onKey('U', false, false);
    EXPECT_EQ(b.ctl.settings().mode, SculptMode::Fluid);
    const double before = b.doc.mesher().enclosedVolume();
    const double x0 = kWidth / 2.0, y0 = kHeight / 2.0;
    // From a little inside the right of the silhouette.
    double x = x0;
    while (b.ctl.pick(x + 4, y0))
        x += 4;
    x -= 12;
    b.ctl.onButton(0, true, x, y0, false);
    ASSERT_EQ(b.ctl.drag(), DragKind::Sculpt);
    for (int k = 1; k <= 2; ++k) {
        b.ctl.onMove(x + 20 * k, y0);
        b.ctl.step();
    }
    b.ctl.onButton(0, false, x + 40, y0, false);
    b.ctl.wait();
    b.ctl.step();
    ASSERT_EQ(b.ctl.takeMessage(), "");
    const auto& strokes = b.doc.script().strokes;
    ASSERT_EQ(strokes.size(), 2u);
    for (const Stroke& s : strokes) {
        const auto* f = std::get_if<FluidStroke>(&s);
        ASSERT_TRUE(f);
        EXPECT_EQ(f->radius, b.ctl.settings().radius);
        EXPECT_GT(f->path[1].x() - f->path[0].x(), 0.0);
    }
    const double after = b.doc.mesher().enclosedVolume();
    std::printf("fluid drag: volume %.5f -> %.5f (%+.3f%%)\n", before, after,
                100.0 * (after - before) / before);
    EXPECT_LT(std::abs(after - before), 0.01 * before);
    EXPECT_GT(activeWorldBox(b.doc.grid()).max.x(), 1.1); // pulled out to the right
    const StrokeScript recorded = loadStrokeScript(formatStrokeScript(b.doc.script()), "fluid");
    EXPECT_EQ(differingVoxels(*applyScript(recorded, "."), b.doc.grid()), 0u);
}

namespace {

Eigen::Vector3d toEigen3(const glm::dvec3& v) {
    return {v.x, v.y, v.z};
}

// A left drag from (x0, y0) to (x1, y1) in `moves` moves, one frame each, with the keys held.
void dragOn(SculptController& ctl, double x0, double y0, double x1, double y1, int moves,
            bool shift = false, bool ctrl = false) {
    ctl.onMove(x0, y0);
    ctl.onButton(0, true, x0, y0, shift, ctrl);
    ASSERT_EQ(ctl.drag(), DragKind::Sculpt) << "the press missed the shape";
    for (int k = 1; k <= moves; ++k) {
        ctl.onMove(x0 + (x1 - x0) * k / moves, y0 + (y1 - y0) * k / moves);
        ctl.step();
    }
    ctl.onButton(0, false, x1, y1, shift, ctrl);
    ctl.wait();
    ctl.step();
    ASSERT_EQ(ctl.drag(), DragKind::None);
    ASSERT_EQ(ctl.takeMessage(), "");
}

} // namespace

TEST(SculptController, CtrlInvertsTheTool) {
    const double x = kWidth / 2.0, y = kHeight / 2.0;
    // Inflate: a drag up blows the clay up; with Ctrl the same drag lets it down.
    for (const bool ctrl : {false, true}) {
        Bench s;
        const double volume = s.ctl.volume();
        s.ctl.onKey('I', false, false);
        dragOn(s.ctl, x, y, x, y - 60, 6, false, ctrl);
        std::printf("[ invert ] inflate%s: volume %.4f -> %.4f\n", ctrl ? " with Ctrl" : "", volume,
                    s.ctl.volume());
        if (ctrl)
            EXPECT_LT(s.ctl.volume(), volume - 0.002);
        else
            EXPECT_GT(s.ctl.volume(), volume + 0.002);
    }
    // Twist: Ctrl turns the other way.
    {
        Bench s;
        s.ctl.onKey('T', false, false);
        dragOn(s.ctl, x, y, x + 100, y, 5, false, true);
        EXPECT_DOUBLE_EQ(s.tool().path.back().angleDegrees, -50.0);
    }
    // Clay: a dab adds a ball; Ctrl at the same pixel takes a ball away (from the surface
    // the first one raised).
    {
        Bench s;
        const double volume = s.ctl.volume();
        s.ctl.onKey('C', false, false);
        dragOn(s.ctl, x + 40, y + 30, x + 40, y + 30, 0);
        const double added = s.ctl.volume();
        dragOn(s.ctl, x + 40, y + 30, x + 40, y + 30, 0, false, true);
        std::printf("[ invert ] clay: volume %.5f, %.5f with a dab, %.5f after Ctrl\n", volume,
                    added, s.ctl.volume());
        EXPECT_GT(added, volume + 0.02);
        EXPECT_NEAR(s.ctl.volume(), volume, 0.005 * volume);
        const auto& strokes = s.doc.script().strokes;
        ASSERT_EQ(strokes.size(), 2u);
        EXPECT_FALSE(std::get<InflateStroke>(strokes[0]).remove);
        EXPECT_TRUE(std::get<InflateStroke>(strokes[1]).remove);
    }
}

TEST(SculptController, ShiftDragSmoothsWhateverTheTool) {
    Bench s;
    s.ctl.onKey('G', false, false);
    const GridPtr before = s.doc.grid().deepCopy();
    const double volume = s.ctl.volume();
    dragOn(s.ctl, kWidth / 2.0, kHeight / 2.0, kWidth / 2.0 + 60, kHeight / 2.0, 6, true);
    const auto& strokes = s.doc.script().strokes;
    ASSERT_GE(strokes.size(), 2u); // a dab at the press and one every quarter radius
    for (const Stroke& st : strokes)
        ASSERT_TRUE(std::holds_alternative<SmoothStroke>(st));
    EXPECT_EQ(s.ctl.settings().mode, SculptMode::Grab);
    // A sphere smoothed shrinks a little (mean-curvature flow), and nothing else happens.
    EXPECT_GT(differingVoxels(*before, s.doc.grid()), 100u);
    EXPECT_LT(s.ctl.volume(), volume);
    EXPECT_GT(s.ctl.volume(), 0.99 * volume);
    EXPECT_TRUE(s.doc.canUndo());
}

TEST(SculptController, FSizesTheBrushInTheViewAndShiftFItsStrength) {
    Bench s;
    const double x = kWidth / 2.0, y = kHeight / 2.0;
    s.ctl.onMove(x, y);
    const double radius = s.ctl.settings().radius;
    // F, a move of 80 pixels, Esc: the radius is put back.
    s.ctl.onKey('F', false, false);
    ASSERT_EQ(s.ctl.sizing(), Sizing::Radius);
    s.ctl.onMove(x + 80, y);
    EXPECT_NE(s.ctl.settings().radius, radius);
    s.ctl.onKey(GLFW_KEY_ESCAPE, false, false);
    EXPECT_EQ(s.ctl.sizing(), Sizing::None);
    EXPECT_EQ(s.ctl.settings().radius, radius);
    // F, a move, a click: the radius is the move's length in the view plane at the surface
    // point under the cursor, twice as long for twice the pixels; the click sculpts nothing.
    const std::optional<glm::dvec3> at = s.ctl.pick(x, y);
    ASSERT_TRUE(at);
    double sized[2];
    for (int k = 0; k < 2; ++k) {
        s.ctl.onMove(x, y);
        s.ctl.onKey('F', false, false);
        s.ctl.onMove(x + 40 * (k + 1), y);
        s.ctl.onButton(0, true, x + 40 * (k + 1), y, false);
        s.ctl.onButton(0, false, x + 40 * (k + 1), y, false);
        EXPECT_EQ(s.ctl.sizing(), Sizing::None);
        sized[k] = s.ctl.settings().radius;
        EXPECT_NEAR(sized[k],
                    glm::length(s.ctl.camera().dragInViewPlane(*at, x, y, x + 40 * (k + 1), y,
                                                               kWidth, kHeight)),
                    1e-12);
    }
    EXPECT_NEAR(sized[1], 2.0 * sized[0], 1e-9);
    EXPECT_TRUE(s.doc.script().strokes.empty());
    // Shift-F: a fifth of the window's height is full strength.
    s.ctl.onMove(x, y);
    s.ctl.onKey('F', false, true);
    ASSERT_EQ(s.ctl.sizing(), Sizing::Strength);
    s.ctl.onMove(x, y + 0.1 * kHeight);
    s.ctl.onButton(0, true, x, y + 0.1 * kHeight, false);
    EXPECT_NEAR(s.ctl.settings().strength, 0.5, 1e-12);
    EXPECT_TRUE(s.doc.script().strokes.empty());
    // With the smooth tool, Shift-F sets smoothing's own strength, up to 10; then Shift-drag
    // smooths with it whatever the tool.
    s.ctl.onButton(0, false, x, y + 0.1 * kHeight, false);
    s.ctl.onKey('O', false, false);
    ASSERT_EQ(s.ctl.settings().mode, SculptMode::Smooth);
    s.ctl.onMove(x, y);
    s.ctl.onKey('F', false, true);
    s.ctl.onMove(x, y + 0.1 * kHeight);
    s.ctl.onButton(0, true, x, y + 0.1 * kHeight, false);
    s.ctl.onButton(0, false, x, y + 0.1 * kHeight, false);
    EXPECT_NEAR(s.ctl.settings().smoothStrength, 5.0, 1e-12);
    EXPECT_NEAR(s.ctl.settings().strength, 0.5, 1e-12);
    s.ctl.onKey('G', false, false);
    dragOn(s.ctl, x, y, x + 30, y, 2, true);
    ASSERT_FALSE(s.doc.script().strokes.empty());
    const auto* smooth = std::get_if<SmoothStroke>(&s.doc.script().strokes.back());
    ASSERT_NE(smooth, nullptr);
    EXPECT_EQ(smooth->strength, 5.0);
}

TEST(SculptController, AGrabAtHalfStrengthMovesThePointUnderTheBrushHalfAsFar) {
    // Grabbed at the top of the sphere's outline (where the surface faces up, in the view
    // plane) and pulled up: the point under the brush, which moves with the ball, is the tip
    // of what the grab pulls out. It is found on the grid: the first surface on the way down
    // from well above it.
    const double x = kWidth / 2.0;
    double moved[2];
    for (int k = 0; k < 2; ++k) {
        Bench s;
        s.ctl.settings().strength = k == 0 ? 1.0 : 0.5;
        double y = kHeight / 2.0;
        while (s.ctl.pick(x, y - 1))
            --y; // the outline's top pixel
        y += 2;
        const glm::dvec3 p0 = *s.ctl.pick(x, y);
        const glm::dvec3 hand =
            s.ctl.camera().dragInViewPlane(p0, x, y, x, y - 40, kWidth, kHeight);
        dragOn(s.ctl, x, y, x, y - 40, 4);
        const glm::dvec3 expected = p0 + s.ctl.settings().strength * hand;
        const auto hit = raycastLevelSet(s.doc.grid(), toEigen3(p0 + 2.0 * hand),
                                         toEigen3(-glm::normalize(hand)), 100.0);
        ASSERT_TRUE(hit);
        const glm::dvec3 found(hit->x(), hit->y(), hit->z());
        const double h = s.doc.grid().voxelSize()[0];
        EXPECT_LT(glm::length(found - expected), h) << "strength " << s.ctl.settings().strength;
        moved[k] = glm::length(found - p0);
    }
    std::printf("[ strength ] the point under the brush moved %.4f at strength 1, %.4f at 0.5\n",
                moved[0], moved[1]);
    EXPECT_NEAR(moved[1], 0.5 * moved[0], 1.0 / 32);
}

TEST(SculptController, RadialCopiesOfAGrabAreSymmetric) {
    // Five copies about y: the grid at the surface and the same points turned by 72 degrees
    // agree (trilinear), and the view shows a circle at each copy.
    Bench s;
    s.ctl.settings().radialCount = 5;
    s.ctl.settings().radialAxis = 1;
    const double x = kWidth / 2.0 + 60, y = kHeight / 2.0;
    dragOn(s.ctl, x, y, x + 30, y - 30, 3);
    const auto& sweep = std::get<SweepStroke>(s.doc.script().strokes.back());
    EXPECT_EQ(sweep.radial.count, 5);
    const Grid& g = s.doc.grid();
    const double h = g.voxelSize()[0];
    const Eigen::AngleAxisd turn(2.0 * M_PI / 5, Eigen::Vector3d::UnitY());
    const Grid::ConstAccessor acc = g.getConstAccessor(); // the sampler keeps a reference
    openvdb::tools::GridSampler<Grid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
        acc, g.transform());
    double sum = 0.0;
    std::size_t n = 0;
    for (auto it = g.cbeginValueOn(); it; ++it) {
        if (std::abs(*it) > h) continue;
        const Eigen::Vector3d p = toEigen(g.indexToWorld(it.getCoord())), q = turn * p;
        const double d = (double(*it) - sampler.wsSample(openvdb::Vec3d(q.x(), q.y(), q.z()))) / h;
        sum += d * d;
        ++n;
    }
    const double rms = std::sqrt(sum / double(n));
    std::printf("[ radial ] 5 copies: %.4f voxel RMS between the surface and itself turned\n", rms);
    EXPECT_LT(rms, 0.05);
    EXPECT_EQ(s.ctl.symmetryPreview(glm::dvec3(0.5, 0.2, 0.3)).size(), 4u * 2 * 48);
    // Swirls, clay and smoothing record the symmetry as theirs.
    for (const int key : {'S', 'C', 'O'}) {
        s.ctl.onKey(key, false, false);
        dragOn(s.ctl, x, y, x + 20, y - 20, 2);
        const Stroke& last = s.doc.script().strokes.back();
        const int count = std::visit(
            [](const auto& st) {
                if constexpr (std::is_same_v<std::decay_t<decltype(st)>, SwirlStroke> ||
                              std::is_same_v<std::decay_t<decltype(st)>, InflateStroke> ||
                              std::is_same_v<std::decay_t<decltype(st)>, SmoothStroke>)
                    return st.radial.count;
                return 0;
            },
            last);
        EXPECT_EQ(count, 5) << char(key);
    }
}
