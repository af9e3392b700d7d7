// SPDX-License-Identifier: Apache-2.0
#include "app/input_replay.h"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <stdexcept>

#define GLFW_INCLUDE_NONE // key codes only: no window here
#include <GLFW/glfw3.h>
#include <nlohmann/json.hpp>

namespace sweepers {

namespace {

// GLFW's code for a key named as in a replay file: a character (letters as capitals, as
// GLFW numbers them) or the name of a key without one.
int keyCode(const std::string& k) {
    static const std::map<std::string, int> named{
        {"space", GLFW_KEY_SPACE}, {"escape", GLFW_KEY_ESCAPE}, {"left", GLFW_KEY_LEFT},
        {"right", GLFW_KEY_RIGHT}, {"up", GLFW_KEY_UP},         {"down", GLFW_KEY_DOWN},
        {"home", GLFW_KEY_HOME},   {"end", GLFW_KEY_END}};
    if (k.size() == 1 && std::isgraph(static_cast<unsigned char>(k[0])))
        return std::toupper(static_cast<unsigned char>(k[0]));
    const auto it = named.find(k);
    if (it == named.end())
        throw std::runtime_error("key must be one character or one of space, escape, left, "
                                 "right, up, down, home, end");
    return it->second;
}

// One event of a replay file (its frame checked against the one before by the caller).
InputEvent readEvent(const nlohmann::json& e) {
    InputEvent ev;
    ev.frame = e.at("frame").get<int>();
    const std::string type = e.at("type").get<std::string>();
    auto number = [&](const char* k) {
        const double v = e.at(k).get<double>();
        if (!std::isfinite(v)) throw std::runtime_error(std::string(k) + " is not finite");
        return v;
    };
    if (type == "press" || type == "release") {
        ev.type = type == "press" ? InputEvent::Type::Press : InputEvent::Type::Release;
        const std::string b = e.value("button", "left");
        if (b == "left")
            ev.button = 0;
        else if (b == "right")
            ev.button = 1;
        else if (b == "middle")
            ev.button = 2;
        else
            throw std::runtime_error("unknown button \"" + b + "\"");
        ev.x = number("x");
        ev.y = number("y");
        ev.ctrl = e.value("ctrl", false);   // ctrl + left: the tool inverted
        ev.shift = e.value("shift", false); // shift + left: smooth
    } else if (type == "move") {
        ev.type = InputEvent::Type::Move;
        ev.x = number("x");
        ev.y = number("y");
    } else if (type == "key") {
        ev.type = InputEvent::Type::Key;
        ev.key = keyCode(e.at("key").get<std::string>());
        ev.ctrl = e.value("ctrl", false);
        ev.shift = e.value("shift", false);
    } else if (type == "scroll") {
        ev.type = InputEvent::Type::Scroll;
        ev.dy = number("dy");
        ev.ctrl = e.value("ctrl", false); // ctrl + wheel: tool radius
    } else if (type == "drop") {
        ev.type = InputEvent::Type::Drop;
        ev.path = e.at("path").get<std::string>();
    } else {
        throw std::runtime_error("unknown type \"" + type + "\"");
    }
    return ev;
}

} // namespace

InputReplay readInputReplay(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error(path + ": cannot open");
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(path + ": " + e.what());
    }
    if (!doc.is_object() || !doc.contains("events") || !doc["events"].is_array())
        throw std::runtime_error(path + ": expected {\"events\": [...]}");
    InputReplay out;
    if (doc.contains("window")) {
        const auto& w = doc["window"];
        const auto pixels = [](const nlohmann::json& v) {
            return v.is_number_integer() && v.get<std::int64_t>() >= kSmallestWindow &&
                   v.get<std::int64_t>() <= kLargestWindow;
        };
        if (!w.is_array() || w.size() != 2 || !pixels(w[0]) || !pixels(w[1]))
            throw std::runtime_error(path + ": /window: expected [width, height] in pixels, " +
                                     std::to_string(kSmallestWindow) + " to " +
                                     std::to_string(kLargestWindow) + " each, like [640, 480]");
        out.width = w[0].get<int>();
        out.height = w[1].get<int>();
    }
    int lastFrame = 0;
    for (std::size_t i = 0; i < doc["events"].size(); ++i) {
        const auto& e = doc["events"][i];
        const std::string where = path + ": /events/" + std::to_string(i) + ": ";
        try {
            const InputEvent ev = readEvent(e);
            if (ev.frame < lastFrame) throw std::runtime_error("frames must not go back");
            lastFrame = ev.frame;
            out.events.push_back(ev);
        } catch (const nlohmann::json::exception& x) {
            throw std::runtime_error(where + x.what());
        } catch (const std::runtime_error& x) {
            throw std::runtime_error(where + x.what());
        }
    }
    return out;
}

} // namespace sweepers
