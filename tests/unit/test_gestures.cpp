// SPDX-License-Identifier: Apache-2.0
// The gestures of the sculpt controller (app/gestures.h), driven directly: each tool family
// sculpts by its own rule between the press and the release (a dab waits for the cursor to
// move its spacing, a topology tool applies once at the release), and F's sizing puts back
// what Esc asks.
#include <gtest/gtest.h>

#include "app/gestures.h"
#include "app/glm_eigen.h"
#include "levelset/raycast.h"

using namespace sweepers;

namespace {

constexpr int kWidth = 640, kHeight = 480;

// A sphere looked at whole, and the tools a gesture gets, its pieces run at once and
// counted.
struct Stage {
    Document doc{Document::sphereScript(1.0 / 16), "."};
    OrbitCamera camera;
    ToolSettings settings;
    int pieces = 0;
    Stage() { camera.frame(glm::dvec3(-1.0), glm::dvec3(1.0)); }

    GestureTools at(double x, double y) {
        GestureTools t{doc, camera, settings, RadialSymmetry{}, x, y, kWidth, kHeight, {}, {}};
        t.launch = [this](const std::function<SegmentReport()>& task) {
            task();
            ++pieces;
        };
        t.pick = [this](double px, double py) -> std::optional<glm::dvec3> {
            const Ray r = camera.rayThrough(px, py, kWidth, kHeight);
            const auto hit =
                raycastLevelSet(doc.grid(), toEigen3(r.origin), toEigen3(r.direction), 100.0);
            if (!hit) return std::nullopt;
            return toGlm(*hit);
        };
        return t;
    }
    // The press at the centre of the view, on the sphere.
    Press centre() {
        const double x = kWidth / 2.0, y = kHeight / 2.0;
        return Press{*at(x, y).pick(x, y), x, y, false};
    }
};

} // namespace

TEST(Gesture, EachToolFamilyShowsWhatItHolds) {
    for (const ModeInfo& m : kModes) {
        SCOPED_TRACE(m.label);
        Stage s;
        const Press p = s.centre();
        auto g = makeGesture(m.mode, p);
        ASSERT_TRUE(g);
        ASSERT_FALSE(g->press(s.at(p.x, p.y)));
        // The dabs and the topology tools draw no tool during the drag; the others draw it
        // where it is, which at the press is the point pressed.
        const bool dab = m.mode == SculptMode::Clay || m.mode == SculptMode::Smooth;
        const bool topology = m.mode == SculptMode::Pinch || m.mode == SculptMode::Strangle;
        EXPECT_EQ(bool(g->toolCentre()), !dab && !topology);
        if (g->toolCentre()) EXPECT_LT(glm::length(*g->toolCentre() - p.at), 1e-12);
        // Only a dab sculpts at the press; only a topology tool previews a stroke.
        EXPECT_EQ(s.pieces, dab ? 1 : 0);
        EXPECT_EQ(bool(g->stroke(s.at(p.x + 60, p.y))), topology);
    }
}

TEST(Gesture, ADabWaitsForTheCursorToMoveItsSpacing) {
    // A move of three eighths of the radius: past smoothing's spacing (a quarter radius), short
    // of clay's (a half).
    Stage probe;
    const Press p = probe.centre();
    const double perPixel = glm::length(probe.at(p.x + 100, p.y).dragFrom(p.at, p.x, p.y)) / 100;
    const double pixels = 0.375 * probe.settings.radius / perPixel;
    for (const SculptMode mode : {SculptMode::Clay, SculptMode::Smooth}) {
        Stage s;
        auto g = makeGesture(mode, p);
        ASSERT_FALSE(g->press(s.at(p.x, p.y)));
        EXPECT_EQ(s.pieces, 1);
        EXPECT_FALSE(g->move(s.at(p.x + 1, p.y)));
        EXPECT_EQ(g->move(s.at(p.x + pixels, p.y)), mode == SculptMode::Smooth);
        EXPECT_EQ(s.pieces, mode == SculptMode::Smooth ? 2 : 1);
        std::string message;
        EXPECT_EQ(g->release(s.at(p.x + pixels, p.y), message), Gesture::Release::Done);
    }
}

TEST(Gesture, ATopologyToolAppliesOnceAtTheRelease) {
    Stage s;
    const Press p = s.centre();
    auto pinch = makeGesture(SculptMode::Pinch, p);
    ASSERT_FALSE(pinch->press(s.at(p.x, p.y)));
    EXPECT_FALSE(pinch->move(s.at(p.x + 40, p.y)));
    std::string message;
    EXPECT_EQ(pinch->release(s.at(p.x + 40, p.y), message), Gesture::Release::Launched);
    EXPECT_EQ(s.pieces, 1);
    EXPECT_EQ(pinch->release(s.at(p.x + 40, p.y), message), Gesture::Release::Done);
    EXPECT_EQ(s.pieces, 1);
    // A strangle needs a drag across the limb: released where it was pressed, it is refused.
    Stage t;
    auto strangle = makeGesture(SculptMode::Strangle, p);
    ASSERT_FALSE(strangle->press(t.at(p.x, p.y)));
    EXPECT_EQ(strangle->release(t.at(p.x, p.y), message), Gesture::Release::Refused);
    EXPECT_NE(message.find("drag across the limb"), std::string::npos) << message;
    EXPECT_EQ(t.pieces, 0);
    // Past the shape's far side the view ray comes out of nothing: the press is refused.
    Stage u;
    const glm::dvec3 beyond = p.at + 3.0 * glm::normalize(p.at - u.camera.eye());
    auto lost = makeGesture(SculptMode::Pinch, Press{beyond, p.x, p.y, false});
    EXPECT_TRUE(lost->press(u.at(p.x, p.y)));
}

TEST(ToolSizing, FSetsTheRadiusShiftFTheToolsOwnStrengthAndEscPutsThemBack) {
    Stage s;
    const glm::dvec3 at(0.0, 0.0, 1.0);
    const ToolSizing radius(Sizing::Radius, 320, 240, at, s.settings);
    radius.move(420, 240, s.camera, kWidth, kHeight, s.settings);
    EXPECT_NEAR(s.settings.radius,
                glm::length(s.camera.dragInViewPlane(at, 320, 240, 420, 240, kWidth, kHeight)),
                1e-12);
    radius.putBack(s.settings);
    EXPECT_EQ(s.settings.radius, ToolSettings().radius);
    // Shift-F with the smooth tool sets smoothing's strength, up to its own most.
    s.settings.mode = SculptMode::Smooth;
    const ToolSizing strength(Sizing::Strength, 320, 240, at, s.settings);
    strength.move(320, 240 + 0.2 * kHeight, s.camera, kWidth, kHeight, s.settings);
    EXPECT_DOUBLE_EQ(s.settings.smoothStrength, kMostSmoothStrength);
    EXPECT_EQ(s.settings.strength, ToolSettings().strength);
    strength.putBack(s.settings);
    EXPECT_EQ(s.settings.smoothStrength, ToolSettings().smoothStrength);
}
