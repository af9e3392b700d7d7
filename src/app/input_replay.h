// SPDX-License-Identifier: Apache-2.0
// Recorded mouse and keyboard events, replayed frame by frame into the real window's
// handlers, so tests drive the modeler exactly as a user would.
//
//   { "events": [
//       { "frame": 3, "type": "press",   "button": "left", "x": 400, "y": 300 },
//                                          (and "shift": true to smooth, "ctrl": true to invert)
//       { "frame": 4, "type": "move",    "x": 420, "y": 290 },
//       { "frame": 5, "type": "release", "button": "left", "x": 420, "y": 290 },
//       { "frame": 7, "type": "key",     "key": "z", "ctrl": true, "shift": false },
//       { "frame": 8, "type": "key",     "key": "space" },  (or escape, left, right, up,
//                                                              down, home, end; or "." ...)
//       { "frame": 8, "type": "scroll",  "dy": -1 },
//       { "frame": 9, "type": "drop",    "path": "shape.vdb" } ] }   (a file dropped on it)
//
// Coordinates are window pixels (origin top left); frames count from 0; events of one
// frame are delivered in file order before that frame is drawn. A file may name the window
// its coordinates belong to, next to the events: "window": [640, 480] (width, height; each
// within kSmallestWindow and kLargestWindow, as --size takes them).
#pragma once

#include <string>
#include <vector>

namespace sweepers {

struct InputEvent {
    enum class Type { Press, Release, Move, Key, Scroll, Drop };
    int frame = 0;
    Type type = Type::Move;
    int button = 0; // 0 left, 1 right, 2 middle
    double x = 0, y = 0, dy = 0;
    int key = 0; // GLFW's key code: for a character key, its ASCII code (letters in capitals)
    bool ctrl = false, shift = false;
    std::string path; // Drop
};

// The window sizes the modeler opens (--size) and a replay file may name, in pixels a side.
constexpr int kSmallestWindow = 64, kLargestWindow = 8192;

struct InputReplay {
    std::vector<InputEvent> events;
    int width = 0, height = 0; // the window the coordinates belong to; 0 when not named
};

// Reads and checks a replay file; throws std::runtime_error naming the file, the event
// and the problem.
InputReplay readInputReplay(const std::string& path);

} // namespace sweepers
