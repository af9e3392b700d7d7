// SPDX-License-Identifier: Apache-2.0
// The modeler's window-free parts: the orbit camera, the input replay files and the
// timeline.
#include <cstdio>
#include <fstream>

#define GLFW_INCLUDE_NONE // key codes only
#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include "app/camera.h"
#include "app/input_replay.h"
#include "scratch_dir.h"

using namespace sweepers;

TEST(OrbitCamera, CentrePixelLooksAtTheTargetAndDragsFollowTheCursor) {
    OrbitCamera c;
    c.target = {0.2, -0.1, 0.3};
    c.yaw = 1.1;
    c.pitch = -0.4;
    const Ray r = c.rayThrough(400, 300, 800, 600);
    const glm::dvec3 toTarget = glm::normalize(c.target - r.origin);
    EXPECT_NEAR(glm::dot(r.direction, toTarget), 1.0, 1e-9);
    // A drag across the whole width moves a point at the target by the view's width there.
    const glm::dvec3 d = c.dragInViewPlane(c.target, 0, 300, 800, 300, 800, 600);
    const double height = 2.0 * c.distance * std::tan(0.5 * c.fovY);
    EXPECT_NEAR(glm::length(d), height * 800.0 / 600.0, 1e-6);
    EXPECT_NEAR(glm::dot(d, c.eye() - c.target), 0.0, 1e-9); // in the view plane
    c.frame({-1, -1, -1}, {1, 1, 1});
    EXPECT_NEAR(glm::length(c.target), 0.0, 1e-12);
}

namespace {
std::string refused(const std::string& text) {
    const test::ScratchDir dir;
    const std::string path = dir / "events.json";
    std::ofstream(path) << text;
    try {
        readInputReplay(path);
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "";
}
} // namespace

TEST(InputReplay, ReadsEventsAndRefusesBadOnesWithTheirPlace) {
    const test::ScratchDir dir;
    const std::string path = dir / "ok.json";
    std::ofstream(path) << R"({"events": [
        {"frame": 1, "type": "press", "button": "right", "x": 10, "y": 20},
        {"frame": 1, "type": "move", "x": 11, "y": 21},
        {"frame": 3, "type": "key", "key": "z", "ctrl": true, "shift": true},
        {"frame": 4, "type": "drop", "path": "a.vdb"},
        {"frame": 5, "type": "key", "key": "."},
        {"frame": 5, "type": "key", "key": "home"}]})";
    const auto ev = readInputReplay(path).events;
    ASSERT_EQ(ev.size(), 6u);
    EXPECT_EQ(ev[4].key, GLFW_KEY_PERIOD);
    EXPECT_EQ(ev[5].key, GLFW_KEY_HOME);
    EXPECT_EQ(ev[0].button, 1);
    EXPECT_EQ(ev[2].key, 'Z');
    EXPECT_TRUE(ev[2].ctrl && ev[2].shift);
    EXPECT_EQ(ev[3].path, "a.vdb");

    EXPECT_NE(refused("{\"events\": 3}").find("expected"), std::string::npos);
    EXPECT_NE(refused("not json").find("parse error"), std::string::npos);
    EXPECT_NE(
        refused(R"({"events": [{"frame": 1, "type": "wiggle"}]})").find("/events/0: unknown type"),
        std::string::npos);
    EXPECT_NE(refused(R"({"events": [{"frame": 2, "type": "move", "x": 1, "y": 1},
                                     {"frame": 1, "type": "move", "x": 1, "y": 1}]})")
                  .find("/events/1: frames must not go back"),
              std::string::npos);
    EXPECT_NE(refused(R"({"events": [{"frame": 1, "type": "move", "x": 1}]})").find("/events/0"),
              std::string::npos);
    EXPECT_NE(refused(R"({"events": [{"frame": 1, "type": "key", "key": "hyper"}]})")
                  .find("/events/0: key must be one character or one of space"),
              std::string::npos);
}

// The window a file's clicks belong to: read when named, refused with its place when it is
// not two pixel sizes within what --size takes; 0 by 0 when the file does not name one.
TEST(InputReplay, ReadsTheWindowTheEventsBelongTo) {
    const test::ScratchDir dir;
    const std::string path = dir / "window.json";
    std::ofstream(path) << R"({"window": [640, 480], "events": []})";
    const InputReplay named = readInputReplay(path);
    EXPECT_EQ(named.width, 640);
    EXPECT_EQ(named.height, 480);
    std::ofstream(path) << R"({"events": [{"frame": 1, "type": "move", "x": 1, "y": 1}]})";
    const InputReplay unnamed = readInputReplay(path);
    EXPECT_EQ(unnamed.width, 0);
    EXPECT_EQ(unnamed.height, 0);
    EXPECT_EQ(unnamed.events.size(), 1u);
    for (const char* bad :
         {R"({"window": [640], "events": []})", R"({"window": [640, 480.5], "events": []})",
          R"({"window": [640, 63], "events": []})", R"({"window": [8193, 480], "events": []})",
          R"({"window": "640x480", "events": []})", R"({"window": [640, -480], "events": []})"})
        EXPECT_NE(refused(bad).find("/window: expected [width, height] in pixels"),
                  std::string::npos)
            << bad;
}
