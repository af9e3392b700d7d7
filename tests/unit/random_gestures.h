// SPDX-License-Identifier: Apache-2.0
// Seeded random input for the modeler: what a user's hands do that nobody scripted. Drags in
// every sculpt mode, on and off the shape, with Shift (smooth) and Ctrl (invert), the brush
// resized and mirrored between them, the view turned, strokes undone and redone, and drags
// cancelled with Escape half way. The events are the replay format (app/input_replay.h), so a
// failing case can be written out and replayed in the real window.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#define GLFW_INCLUDE_NONE // key codes only
#include <GLFW/glfw3.h>
#include <nlohmann/json.hpp>

#include "app/input_replay.h"
#include "app/sculpt_controller.h"
#include "random.h"

namespace sweepers::test {

struct GestureOptions {
    int width = 320, height = 240;
    int fewestGestures = 3, mostGestures = 6;
    int mostMoves = 8; // moves in one drag
    // Pinch and strangle take seconds each: drawn this often among the modes.
    double tearShare = 0.05;
};

class GestureGenerator {
  public:
    GestureGenerator(unsigned seed, GestureOptions options = {}) : rng_(seed), o_(options) {}

    InputReplay replay() {
        InputReplay r;
        r.width = o_.width;
        r.height = o_.height;
        const int n = integer(o_.fewestGestures, o_.mostGestures);
        for (int i = 0; i < n; ++i)
            gesture(r.events);
        return r;
    }

  private:
    bool chance(double p) { return rng_.uniform(0, 1) < p; }
    int integer(int lo, int hi) { return int(std::floor(rng_.uniform(lo, hi + 1 - 1e-9))); }

    void key(std::vector<InputEvent>& out, int code, bool ctrl = false, bool shift = false) {
        InputEvent e;
        e.frame = frame_++;
        e.type = InputEvent::Type::Key;
        e.key = code;
        e.ctrl = ctrl;
        e.shift = shift;
        out.push_back(e);
    }

    // A sculpt mode: any of them, the tearing ones (pinch, strangle) seldom.
    int modeKey() {
        std::vector<int> keys;
        for (const ModeInfo& m : kModes)
            if (m.mode != SculptMode::Pinch && m.mode != SculptMode::Strangle)
                keys.push_back(m.key);
        if (chance(o_.tearShare)) return chance(0.5) ? 'P' : 'K';
        return keys[std::size_t(integer(0, int(keys.size()) - 1))];
    }

    void gesture(std::vector<InputEvent>& out) {
        key(out, modeKey());
        if (chance(0.2)) key(out, 'M'); // the next mirror plane
        if (chance(0.3)) key(out, chance(0.5) ? '[' : ']', false, chance(0.4)); // shift: falloff
        if (chance(0.3)) key(out, chance(0.5) ? GLFW_KEY_LEFT : GLFW_KEY_UP);   // turn the view
        // A press mostly on the shape (the view frames it: about a third of the window's
        // height across), at times beside it.
        const double cx = 0.5 * o_.width, cy = 0.5 * o_.height;
        const double reach = (chance(0.85) ? 0.3 : 0.6) * std::min(o_.width, o_.height);
        const double a = rng_.uniform(0, 2 * M_PI), r = reach * std::sqrt(rng_.uniform(0, 1));
        double x = cx + r * std::cos(a), y = cy + r * std::sin(a);
        InputEvent press;
        press.frame = frame_++;
        press.type = InputEvent::Type::Press;
        press.x = x;
        press.y = y;
        press.shift = chance(0.15);                // smooth, whatever the tool
        press.ctrl = !press.shift && chance(0.15); // the tool inverted
        out.push_back(press);
        const int moves = integer(1, o_.mostMoves);
        const double heading = rng_.uniform(0, 2 * M_PI);
        for (int k = 0; k < moves; ++k) {
            const double turn = heading + rng_.uniform(-0.6, 0.6), step = rng_.uniform(2, 14);
            x += step * std::cos(turn);
            y += step * std::sin(turn);
            InputEvent move;
            move.frame = frame_++;
            move.type = InputEvent::Type::Move;
            move.x = x;
            move.y = y;
            out.push_back(move);
        }
        if (chance(0.08)) key(out, GLFW_KEY_ESCAPE); // let go of it half way
        InputEvent release = press;
        release.frame = frame_++;
        release.type = InputEvent::Type::Release;
        release.x = x;
        release.y = y;
        out.push_back(release);
        if (chance(0.15)) {
            key(out, 'Z', true);
            if (chance(0.5)) key(out, 'Z', true, true);
        }
    }

    Rng rng_;
    GestureOptions o_;
    int frame_ = 1;
};

// The events in the replay file format (app/input_replay.h), for a failing case to be
// replayed in the window.
inline nlohmann::json replayJson(const InputReplay& r) {
    using nlohmann::json;
    json events = json::array();
    for (const InputEvent& e : r.events) {
        json j = {{"frame", e.frame}};
        switch (e.type) {
        case InputEvent::Type::Press:
        case InputEvent::Type::Release:
            j["type"] = e.type == InputEvent::Type::Press ? "press" : "release";
            j["button"] = "left";
            j["x"] = e.x;
            j["y"] = e.y;
            break;
        case InputEvent::Type::Move:
            j["type"] = "move";
            j["x"] = e.x;
            j["y"] = e.y;
            break;
        case InputEvent::Type::Key:
            j["type"] = "key";
            j["key"] = e.key == GLFW_KEY_ESCAPE ? "escape"
                       : e.key == GLFW_KEY_LEFT ? "left"
                       : e.key == GLFW_KEY_UP   ? "up"
                                                : std::string(1, char(e.key));
            break;
        default:
            continue; // not drawn by the generator
        }
        if (e.ctrl) j["ctrl"] = true;
        if (e.shift) j["shift"] = true;
        events.push_back(j);
    }
    return {{"window", {r.width, r.height}}, {"events", events}};
}

} // namespace sweepers::test
