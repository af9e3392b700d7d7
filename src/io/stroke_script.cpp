// SPDX-License-Identifier: Apache-2.0
#include "io/stroke_script.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/format.h"
#include "core/limits.h"
#include "io/baked_tool.h"
#include "io/fluid_cache.h"
#include "io/input_file.h"
#include "io/velocity_file.h"

namespace sweepers {

using nlohmann::json;

namespace {

// Walks the JSON tree and knows where it is, so every complaint carries its location.
// The fields each kind of object in a script may hold. Any other is refused: in a
// hand-written script it is a typo. `duration` (on any stroke) and `time` (on a key) are
// taken off their objects before the rest is read. docs/stroke-scripts.md names every one
// (a test reads it against strokeScriptFields()).
const std::pair<const char*, std::vector<const char*>> kScriptFields[] = {
    {"script", {"sweepers", "grid", "start", "strokes"}},
    {"grid", {"voxel_size", "half_width"}},
    {"start", {"sphere", "vdb", "mesh", "grid"}},
    {"sphere", {"center", "radius"}},
    {"any stroke", {"duration"}},
    {"sweep", {"type", "mirror", "tools", "strength", "radial"}},
    {"radial", {"axis", "center", "count"}},
    {"tool", {"shape", "size", "falloff", "path"}},
    {"keyed tool", {"shape", "size", "falloff"}},
    {"placement", {"t", "r", "s"}},
    {"keyed placement", {"time"}},
    {"baked shape", {"vdb", "mesh", "grid", "voxel_size"}},
    {"swirl", {"type", "at", "move", "radius", "ring", "swirls", "ball", "strength", "radial"}},
    {"inflate", {"type", "at", "radius", "strength", "remove", "radial"}},
    {"smooth", {"type", "tool", "strength", "radial"}},
    {"pinch or strangle", {"type", "at", "axis", "size", "falloff", "open"}},
    {"keyframed", {"type", "tool", "keys"}},
    {"slide", {"type", "mirror", "tools", "keys"}},
    {"flow", {"type", "field", "from", "to", "segments"}},
    {"rotation field", {"rotation"}},
    {"rotation", {"center", "axis", "degrees_per_second", "radius", "falloff"}},
    {"file field", {"vdb", "grid"}},
    {"fluid", {"type", "radius", "path", "strength"}},
};

const std::vector<const char*>& fieldsOf(std::string_view object) {
    for (const auto& [name, fields] : kScriptFields)
        if (name == object) return fields;
    throw std::logic_error("no field list for " + std::string(object));
}

class Reader {
  public:
    explicit Reader(const std::string& name) : name_(name) {}
    // The script's voxel size, once /grid is read (a mesh tool's default sampling).
    double voxelSize = GridSpec().voxelSize;

    [[noreturn]] void fail(const std::string& where, const std::string& why) const {
        throw ScriptError(name_ + ": " + (where.empty() ? "/" : where) + ": " + why);
    }

    // Refuses any field the kind of object (a name in kScriptFields) may not hold.
    void onlyKeys(const json& obj, const std::string& where, std::string_view object) const {
        if (!obj.is_object()) fail(where, "expected an object");
        const std::vector<const char*>& allowed = fieldsOf(object);
        for (auto it = obj.begin(); it != obj.end(); ++it) {
            bool known = false;
            for (const char* a : allowed)
                known = known || it.key() == a;
            if (!known) fail(where + "/" + it.key(), "unknown field");
        }
    }

    const json& require(const json& obj, const std::string& where, const char* key) const {
        auto it = obj.find(key);
        if (it == obj.end()) fail(where + "/" + key, "missing field");
        return *it;
    }

    // Within core/limits.h's range (a size of 1e30 once made strokes that silently did
    // nothing).
    double number(const json& v, const std::string& where) const {
        if (!v.is_number()) fail(where, "expected a number, got " + describe(v));
        const double d = v.get<double>();
        if (!std::isfinite(d)) fail(where, "the number is not finite");
        if (std::abs(d) > kLargestNumber)
            fail(where, v.dump() + " is beyond the largest number a script takes, 1e5");
        return d;
    }

    double positive(const json& v, const std::string& where) const {
        const double d = number(v, where);
        if (!(d > 0.0)) fail(where, "must be positive (got " + v.dump() + ")");
        if (d < kSmallestPositive)
            fail(where, v.dump() + " is below the smallest positive number a script takes, 1e-9");
        return d;
    }

    Eigen::Vector3d vec3(const json& v, const std::string& where) const {
        if (!v.is_array() || v.size() != 3) fail(where, "expected an array of 3 numbers");
        Eigen::Vector3d r;
        for (int i = 0; i < 3; ++i)
            r[i] = number(v[i], where + "/" + std::to_string(i));
        return r;
    }

    std::string string(const json& v, const std::string& where) const {
        if (!v.is_string()) fail(where, "expected a string, got " + describe(v));
        return v.get<std::string>();
    }

    static std::string describe(const json& v) {
        const std::string s = v.dump();
        return s.size() > 40 ? s.substr(0, 37) + "..." : s;
    }

  private:
    const std::string& name_;
};

Placement readPlacement(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "placement");
    Placement p;
    p.t = r.vec3(r.require(v, at, "t"), at + "/t");
    if (auto it = v.find("r"); it != v.end()) {
        if (!it->is_array() || it->size() != 4)
            r.fail(at + "/r", "expected [axis x, axis y, axis z, angle in degrees]");
        for (int i = 0; i < 3; ++i)
            p.axis[i] = r.number((*it)[i], at + "/r/" + std::to_string(i));
        p.angleDegrees = r.number((*it)[3], at + "/r/3");
        if (p.axis.norm() == 0.0 && p.angleDegrees != 0.0)
            r.fail(at + "/r", "the rotation axis is zero");
        if (std::abs(p.angleDegrees) >= 360.0)
            r.fail(at + "/r/3", "the angle must lie strictly between -360 and 360 degrees");
    }
    if (auto it = v.find("s"); it != v.end()) {
        if (it->is_array()) {
            p.scale = r.vec3(*it, at + "/s");
            for (int i = 0; i < 3; ++i)
                if (!(p.scale[i] > 0.0)) r.fail(at + "/s/" + std::to_string(i), "must be positive");
        } else {
            p.scale = Eigen::Vector3d::Constant(r.positive(*it, at + "/s"));
        }
    }
    return p;
}

// {"vdb": file, "grid": name} or {"mesh": file, "voxel_size": h}.
BakedToolSource readBakedSource(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "baked shape");
    BakedToolSource b;
    const bool vdb = v.contains("vdb");
    if (vdb == v.contains("mesh")) r.fail(at, "expected exactly one of vdb, mesh");
    b.kind = vdb ? BakedToolSource::Kind::Vdb : BakedToolSource::Kind::Mesh;
    const std::string key = vdb ? "vdb" : "mesh";
    b.file = r.string(v[key], at + "/" + key);
    if (b.file.empty()) r.fail(at + "/" + key, "empty file name");
    if (auto it = v.find("grid"); it != v.end()) {
        if (!vdb) r.fail(at + "/grid", "names a grid of a VDB tool; this tool is a mesh");
        b.gridName = r.string(*it, at + "/grid");
        if (b.gridName.empty()) r.fail(at + "/grid", "empty grid name");
    }
    if (auto it = v.find("voxel_size"); it != v.end()) {
        if (vdb) r.fail(at + "/voxel_size", "a VDB tool keeps its own voxel size");
        b.voxelSize = r.positive(*it, at + "/voxel_size");
    }
    return b;
}

// A baked tool's path, checked when read: the tool can only be scaled uniformly, and a mesh
// is sampled at least as finely as the sculpt, wherever the tool is largest.
void checkBakedPath(const Reader& r, ToolSpec& t, const std::string& at) {
    double largest = t.size.x();
    for (std::size_t i = 0; i < t.path.size(); ++i) {
        const Placement& p = t.path[i];
        if (!p.uniformScale())
            r.fail(at + "/path/" + std::to_string(i) + "/s",
                   "a baked tool can only be scaled uniformly");
        largest = std::max(largest, t.size.x() * p.scale.x());
    }
    if (t.source.kind == BakedToolSource::Kind::Mesh && t.source.voxelSize == 0.0)
        t.source.voxelSize = r.voxelSize / largest;
}

// A tool with its path, or (`keyed`) with the placements keyed elsewhere as its path.
ToolSpec readTool(const Reader& r, const json& v, const std::string& at,
                  const std::vector<Placement>* keyed = nullptr, std::size_t fewest = 2) {
    if (keyed)
        r.onlyKeys(v, at, "keyed tool");
    else
        r.onlyKeys(v, at, "tool");
    ToolSpec t;
    const json& shapeValue = r.require(v, at, "shape");
    const std::string shape =
        shapeValue.is_object() ? "baked" : r.string(shapeValue, at + "/shape");
    const json& size = r.require(v, at, "size");
    if (shape == "baked") {
        t.shape = ToolShapeKind::Baked;
        t.source = readBakedSource(r, shapeValue, at + "/shape");
        t.size = Eigen::Vector3d::Constant(r.positive(size, at + "/size"));
    } else if (shape == "ball") {
        t.shape = ToolShapeKind::Ball;
        t.size = Eigen::Vector3d::Constant(r.positive(size, at + "/size"));
    } else if (shape == "ellipsoid") {
        t.shape = ToolShapeKind::Ellipsoid;
        t.size = r.vec3(size, at + "/size");
        for (int i = 0; i < 3; ++i)
            if (!(t.size[i] > 0.0)) r.fail(at + "/size/" + std::to_string(i), "must be positive");
    } else {
        r.fail(at + "/shape", "unknown shape \"" + shape +
                                  "\" (expected ball, ellipsoid, {\"vdb\": file} or "
                                  "{\"mesh\": file})");
    }
    t.falloff = r.positive(r.require(v, at, "falloff"), at + "/falloff");
    if (keyed) {
        t.path = *keyed;
    } else {
        const json& path = r.require(v, at, "path");
        if (!path.is_array()) r.fail(at + "/path", "expected an array of placements");
        if (path.size() < fewest)
            r.fail(at + "/path", fewest == 1 ? "a path needs at least one placement"
                                             : "a path needs at least two placements");
        for (std::size_t i = 0; i < path.size(); ++i)
            t.path.push_back(readPlacement(r, path[i], at + "/path/" + std::to_string(i)));
    }
    if (t.shape == ToolShapeKind::Baked) checkBakedPath(r, t, at);
    return t;
}

// A stroke's "strength": in (0, most] (a fraction, but for smoothing), 1 when not given.
double readStrength(const Reader& r, const json& v, const std::string& at, double most = 1.0) {
    const auto it = v.find("strength");
    if (it == v.end()) return 1.0;
    const double s = r.positive(*it, at + "/strength");
    if (s > most)
        r.fail(at + "/strength", most == 1.0
                                     ? "expected a fraction, greater than 0 and at most 1"
                                     : "expected greater than 0 and at most " + formatNumber(most));
    return s;
}

// A stroke's "radial" symmetry: the stroke alone when not given.
RadialSymmetry readRadial(const Reader& r, const json& v, const std::string& at) {
    RadialSymmetry radial;
    const auto it = v.find("radial");
    if (it == v.end()) return radial;
    const std::string where = at + "/radial";
    r.onlyKeys(*it, where, "radial");
    radial.axis = r.vec3(r.require(*it, where, "axis"), where + "/axis");
    if (!(radial.axis.norm() > 0.0)) r.fail(where + "/axis", "an axis needs a length");
    radial.center = r.vec3(r.require(*it, where, "center"), where + "/center");
    const json& count = r.require(*it, where, "count");
    if (!count.is_number_integer() || count.get<long long>() < 1 || count.get<long long>() > 64)
        r.fail(where + "/count", "expected a whole number from 1 to 64");
    radial.count = count.get<int>();
    return radial;
}

bool hasBakedTool(const SweepStroke& s) {
    return std::any_of(s.tools.begin(), s.tools.end(),
                       [](const ToolSpec& t) { return t.shape == ToolShapeKind::Baked; });
}

// Every segment's motion must have a logarithm and a sane number of sub-steps; the count
// depends on the tools' shapes, so a sweep with a baked tool is checked once its file is
// read (loadScriptInputs).
void checkSweepSegments(const Reader& r, const SweepStroke& s, const std::string& at) {
    const Sweep sweep = toSweep(s);
    for (std::size_t k = 0; k < sweep.segmentCount(); ++k) {
        try {
            SweepSegment segment(sweep, k);
        } catch (const std::exception& e) {
            r.fail(at + "/tools/0/path/" + std::to_string(k + 1),
                   std::string("segment ") + std::to_string(k) + ": " + e.what());
        }
    }
}

// Every keyed placement must be reachable from the rest by one motion with a logarithm
// (checked as a sweep's segments are, and when they are).
void checkKeyedMotions(const Reader& r, const KeyframedStroke& s, const std::string& at) {
    for (std::size_t i = 1; i < s.keys.placements.size(); ++i) {
        SweepStroke grab;
        grab.tools = {s.tool};
        grab.tools[0].path = {s.keys.placements[0], s.keys.placements[i]};
        try {
            SweepSegment segment(toSweep(grab), 0);
        } catch (const std::exception& e) {
            r.fail(at + "/keys/" + std::to_string(i), std::string("from the rest: ") + e.what());
        }
    }
}

SweepStroke readSweep(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "sweep");
    SweepStroke s;
    s.strength = readStrength(r, v, at);
    if (auto it = v.find("mirror"); it != v.end()) {
        const std::string m = r.string(*it, at + "/mirror");
        if (m == "x")
            s.mirror = MirrorAxis::X;
        else if (m == "y")
            s.mirror = MirrorAxis::Y;
        else if (m == "z")
            s.mirror = MirrorAxis::Z;
        else
            r.fail(at + "/mirror", "expected \"x\", \"y\" or \"z\"");
    }
    s.radial = readRadial(r, v, at);
    const json& tools = r.require(v, at, "tools");
    if (!tools.is_array() || tools.empty())
        r.fail(at + "/tools", "expected a non-empty array of tools");
    for (std::size_t i = 0; i < tools.size(); ++i)
        s.tools.push_back(readTool(r, tools[i], at + "/tools/" + std::to_string(i)));
    for (std::size_t i = 1; i < s.tools.size(); ++i)
        if (s.tools[i].path.size() != s.tools[0].path.size())
            r.fail(at + "/tools/" + std::to_string(i) + "/path",
                   "tools swept together need the same number of placements");

    if (!hasBakedTool(s)) checkSweepSegments(r, s, at);
    return s;
}

// "keys": [{"time": 0, "t": .., "r": .., "s": ..}, ...], from time 0, in increasing time.
Keyframes readKeys(const Reader& r, const json& v, const std::string& at, bool uniformScale) {
    const json& keys = r.require(v, at, "keys");
    if (!keys.is_array() || keys.size() < 2)
        r.fail(at + "/keys", "expected an array of at least two keys");
    Keyframes k;
    for (std::size_t i = 0; i < keys.size(); ++i) {
        const std::string key = at + "/keys/" + std::to_string(i);
        if (!keys[i].is_object()) r.fail(key, "expected an object");
        json placement = keys[i];
        const double time = r.number(r.require(placement, key, "time"), key + "/time");
        placement.erase("time");
        if (i == 0 && time != 0.0) r.fail(key + "/time", "the first key is at time 0");
        if (i > 0 && !(time > k.times.back()))
            r.fail(key + "/time", "keys must come in increasing time (this one is at " +
                                      keys[i]["time"].dump() + ", the one before at " +
                                      keys[i - 1]["time"].dump() + ")");
        k.times.push_back(time);
        k.placements.push_back(readPlacement(r, placement, key));
        if (uniformScale && !k.placements.back().uniformScale())
            r.fail(key + "/s", "a slide's frame can only be scaled uniformly");
    }
    return k;
}

KeyframedStroke readKeyframed(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "keyframed");
    KeyframedStroke s;
    s.keys = readKeys(r, v, at, false);
    s.tool = readTool(r, r.require(v, at, "tool"), at + "/tool", &s.keys.placements);
    if (s.tool.shape != ToolShapeKind::Baked) checkKeyedMotions(r, s, at);
    return s;
}

SlideStroke readSlide(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "slide");
    SlideStroke s;
    json local = v;
    local.erase("keys");
    s.local = readSweep(r, local, at);
    s.frame = readKeys(r, v, at, true);
    return s;
}

FluidStroke readFluid(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "fluid");
    FluidStroke s;
    s.strength = readStrength(r, v, at);
    s.radius = r.positive(r.require(v, at, "radius"), at + "/radius");
    const json& path = r.require(v, at, "path");
    if (!path.is_array() || path.size() < 2)
        r.fail(at + "/path", "expected two points or more, got " + Reader::describe(path));
    for (std::size_t i = 0; i < path.size(); ++i) {
        s.path.push_back(r.vec3(path[i], at + "/path/" + std::to_string(i)));
        if (i > 0 && s.path[i] == s.path[i - 1])
            r.fail(at + "/path/" + std::to_string(i),
                   "the tool does not move from the point before");
    }
    return s;
}

SwirlStroke readSwirl(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "swirl");
    SwirlStroke s;
    s.strength = readStrength(r, v, at);
    s.radial = readRadial(r, v, at);
    s.at = r.vec3(r.require(v, at, "at"), at + "/at");
    s.move = r.vec3(r.require(v, at, "move"), at + "/move");
    s.radius = r.positive(r.require(v, at, "radius"), at + "/radius");
    if (auto it = v.find("ring"); it != v.end()) {
        const std::string ring = r.string(*it, at + "/ring");
        if (ring == "discrete")
            s.ring = SwirlRing::Discrete;
        else if (ring == "convolution")
            s.ring = SwirlRing::Convolution;
        else
            r.fail(at + "/ring", "expected \"discrete\" or \"convolution\"");
    }
    if (auto it = v.find("swirls"); it != v.end()) {
        if (!it->is_number_integer() || it->get<long long>() < 1 || it->get<long long>() > 1024)
            r.fail(at + "/swirls", "expected a whole number from 1 to 1024");
        s.swirls = it->get<int>();
    }
    if (auto it = v.find("ball"); it != v.end()) s.ball = r.positive(*it, at + "/ball");
    if (s.move.norm() == 0.0) r.fail(at + "/move", "a swirl needs a non-zero move");
    try {
        SwirlSegment check(toSwirl(s));
    } catch (const std::exception& e) {
        r.fail(at, e.what());
    }
    return s;
}

InflateStroke readInflate(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "inflate");
    InflateStroke s;
    s.strength = readStrength(r, v, at);
    s.radial = readRadial(r, v, at);
    s.at = r.vec3(r.require(v, at, "at"), at + "/at");
    s.radius = r.positive(r.require(v, at, "radius"), at + "/radius");
    if (auto it = v.find("remove"); it != v.end()) {
        if (!it->is_boolean()) r.fail(at + "/remove", "expected true or false");
        s.remove = it->get<bool>();
    }
    return s;
}

// A smooth stroke: a ball and the placements of its dabs.
SmoothStroke readSmooth(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "smooth");
    SmoothStroke s;
    s.strength = readStrength(r, v, at, kMostSmoothStrength);
    s.radial = readRadial(r, v, at);
    s.tool = readTool(r, r.require(v, at, "tool"), at + "/tool", nullptr, 1);
    if (s.tool.shape != ToolShapeKind::Ball) r.fail(at + "/tool/shape", "smoothing takes a ball");
    return s;
}

// Sub-steps last at most 1 / (2 L) (deform/flow.h): a span that needs more than a hundred
// thousand of them is refused before any work.
void checkFlowSpan(const Reader& r, const FlowStroke& s, const std::string& at) {
    const double subSteps = 2.0 * makeField(s.field)->lipschitz() * (s.to - s.from);
    if (subSteps > 1e5)
        r.fail(at, "the flow would take " + formatNumber(std::ceil(subSteps)) +
                       " sub-steps (more than 100000): shorten its time or slow its field");
}

FlowStroke readFlow(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "flow");
    FlowStroke s;
    const json& f = r.require(v, at, "field");
    const std::string fat = at + "/field";
    if (f.is_string() && f.get<std::string>() == "enright") {
        s.field.kind = FieldSpec::Kind::Enright;
    } else if (f.is_string() && f.get<std::string>() == "vortex") {
        s.field.kind = FieldSpec::Kind::Vortex;
    } else if (f.is_object() && f.contains("rotation")) {
        r.onlyKeys(f, fat, "rotation field");
        const json& rot = f["rotation"];
        const std::string rat = fat + "/rotation";
        r.onlyKeys(rot, rat, "rotation");
        s.field.kind = FieldSpec::Kind::Rotation;
        s.field.center = r.vec3(r.require(rot, rat, "center"), rat + "/center");
        s.field.axis = r.vec3(r.require(rot, rat, "axis"), rat + "/axis");
        if (!(s.field.axis.norm() > 0.0)) r.fail(rat + "/axis", "needs a direction (not zero)");
        s.field.degreesPerSecond =
            r.number(r.require(rot, rat, "degrees_per_second"), rat + "/degrees_per_second");
        s.field.radius = r.positive(r.require(rot, rat, "radius"), rat + "/radius");
        s.field.falloff = r.positive(r.require(rot, rat, "falloff"), rat + "/falloff");
    } else if (f.is_object() && f.contains("vdb")) {
        r.onlyKeys(f, fat, "file field");
        s.field.kind = FieldSpec::Kind::Sampled;
        s.field.file = r.string(f["vdb"], fat + "/vdb");
        if (f.contains("grid")) s.field.gridName = r.string(f["grid"], fat + "/grid");
    } else {
        r.fail(fat, "expected \"enright\", \"vortex\", {\"rotation\": {...}} or {\"vdb\": file}, "
                    "got " +
                        Reader::describe(f));
    }
    s.from = r.number(r.require(v, at, "from"), at + "/from");
    s.to = r.number(r.require(v, at, "to"), at + "/to");
    if (!(s.to > s.from))
        r.fail(at + "/to", "a flow runs forward in time: to (" + formatNumber(s.to) +
                               ") must come after from (" + formatNumber(s.from) + ")");
    if (auto it = v.find("segments"); it != v.end()) {
        if (!it->is_number_integer() || it->get<long long>() < 1 || it->get<long long>() > 4096)
            r.fail(at + "/segments",
                   "expected a whole number from 1 to 4096, got " + Reader::describe(*it));
        s.segments = it->get<int>();
    }
    // A sampled field's speed is known once its file is read (loadScriptInputs).
    if (s.field.kind != FieldSpec::Kind::Sampled) checkFlowSpan(r, s, at);
    return s;
}

// A pinch or a strangle: the same fields, checked by the tool's own rules.
template <typename StrokeT, typename Check>
StrokeT readTopologyTool(const Reader& r, const json& v, const std::string& at, Check check) {
    r.onlyKeys(v, at, "pinch or strangle");
    StrokeT s;
    s.at = r.vec3(r.require(v, at, "at"), at + "/at");
    s.axis = r.vec3(r.require(v, at, "axis"), at + "/axis");
    if (!(s.axis.norm() > 0.0)) r.fail(at + "/axis", "needs a direction (not zero)");
    s.size = r.positive(r.require(v, at, "size"), at + "/size");
    s.falloff = r.positive(r.require(v, at, "falloff"), at + "/falloff");
    s.open = r.positive(r.require(v, at, "open"), at + "/open");
    try {
        check(s);
    } catch (const std::exception& e) {
        // The message starts with the field it is about.
        const std::string why = e.what();
        const auto colon = why.find(": ");
        if (colon == std::string::npos) r.fail(at, why);
        r.fail(at + "/" + why.substr(0, colon), why.substr(colon + 2));
    }
    return s;
}

StartShape readStart(const Reader& r, const json& v, const std::string& at) {
    r.onlyKeys(v, at, "start");
    if (v.size() - v.contains("grid") != 1) r.fail(at, "expected exactly one of sphere, vdb, mesh");
    if (v.contains("grid") && !v.contains("vdb"))
        r.fail(at + "/grid", "names a grid of a VDB start; this start is not a VDB file");
    StartShape s;
    if (auto it = v.find("sphere"); it != v.end()) {
        r.onlyKeys(*it, at + "/sphere", "sphere");
        s.kind = StartShape::Kind::Sphere;
        s.center = r.vec3(r.require(*it, at + "/sphere", "center"), at + "/sphere/center");
        s.radius = r.positive(r.require(*it, at + "/sphere", "radius"), at + "/sphere/radius");
    } else {
        const bool vdb = v.contains("vdb");
        s.kind = vdb ? StartShape::Kind::Vdb : StartShape::Kind::Mesh;
        const std::string key = vdb ? "vdb" : "mesh";
        s.file = r.string(v[key], at + "/" + key);
        if (s.file.empty()) r.fail(at + "/" + key, "empty file name");
        if (v.contains("grid")) {
            s.gridName = r.string(v["grid"], at + "/grid");
            if (s.gridName.empty()) r.fail(at + "/grid", "empty grid name");
        }
    }
    return s;
}

std::pair<int, int> lineAndColumn(const std::string& text, std::size_t byte) {
    int line = 1, col = 1;
    for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            col = 1;
        } else {
            ++col;
        }
    }
    return {line, col};
}

} // namespace

namespace {

// A parser callback that finds the first key an object holds twice (JSON allows it; the
// parser would keep the last silently, and a script meant something by the first too).
// `first` is its path, "/grid/voxel_size".
struct DuplicateKeys {
    struct Frame {
        bool object = false;
        std::set<std::string> keys;
        std::string key; // the object's current key
        long index = -1; // the array's current element
    };
    std::vector<Frame> frames;
    std::string first;

    bool operator()(int /*depth*/, json::parse_event_t event, json& parsed) {
        using E = json::parse_event_t;
        switch (event) {
        case E::object_start:
        case E::array_start:
            nextElement();
            frames.push_back({event == E::object_start, {}, {}, -1});
            break;
        case E::object_end:
        case E::array_end:
            if (!frames.empty()) frames.pop_back();
            break;
        case E::key:
            if (!frames.empty()) {
                Frame& top = frames.back();
                top.key = parsed.get<std::string>();
                if (!top.keys.insert(top.key).second && first.empty()) first = path();
            }
            break;
        case E::value:
            nextElement();
            break;
        }
        return true;
    }
    void nextElement() {
        if (!frames.empty() && !frames.back().object) ++frames.back().index;
    }
    std::string path() const {
        std::string p;
        for (const Frame& f : frames)
            p += "/" + (f.object ? f.key : std::to_string(f.index));
        return p;
    }
};

} // namespace

StrokeScript parseStrokeScript(const std::string& text, const std::string& name) {
    Reader r(name);
    json root;
    DuplicateKeys duplicates;
    try {
        root = json::parse(text, std::ref(duplicates));
    } catch (const json::parse_error& e) {
        const auto [line, col] = lineAndColumn(text, e.byte == 0 ? 0 : e.byte - 1);
        std::string why = e.what();
        if (auto p = why.find("syntax error"); p != std::string::npos) why = why.substr(p);
        throw ScriptError(name + ": line " + std::to_string(line) + ", column " +
                          std::to_string(col) + ": invalid JSON (" + why + ")");
    } catch (const json::out_of_range& e) {
        // A number too large for a double (1e999): the parser names the token, not its
        // position, so find the token to report where it stands.
        const std::string why = e.what();
        const auto q0 = why.find('\''), q1 = why.rfind('\'');
        const std::string token = q0 < q1 ? why.substr(q0 + 1, q1 - q0 - 1) : "";
        const auto [line, col] = lineAndColumn(text, token.empty() ? 0 : text.find(token));
        throw ScriptError(name + ": line " + std::to_string(line) + ", column " +
                          std::to_string(col) + ": the number " + token + " is not finite");
    }
    if (!duplicates.first.empty())
        throw ScriptError(name + ": " + duplicates.first +
                          " appears twice in the same object (which one is meant?)");
    r.onlyKeys(root, "", "script");
    StrokeScript s;
    const json& version = r.require(root, "", "sweepers");
    if (!version.is_number_integer() || version.get<long long>() != 1)
        r.fail("/sweepers", "unsupported format version " + Reader::describe(version) +
                                " (this build reads version 1)");
    if (auto it = root.find("grid"); it != root.end()) {
        r.onlyKeys(*it, "/grid", "grid");
        s.grid.voxelSizeGiven = it->contains("voxel_size");
        s.grid.halfWidthGiven = it->contains("half_width");
        if (s.grid.voxelSizeGiven)
            s.grid.voxelSize = r.positive((*it)["voxel_size"], "/grid/voxel_size");
        r.voxelSize = s.grid.voxelSize;
        if (s.grid.halfWidthGiven) {
            s.grid.halfWidth = r.number((*it)["half_width"], "/grid/half_width");
            if (s.grid.halfWidth < 1.0 || s.grid.halfWidth > 64.0)
                r.fail("/grid/half_width", "must lie between 1 and 64 voxels");
        }
    }
    if (auto it = root.find("start"); it != root.end()) s.start = readStart(r, *it, "/start");
    const json& strokes = r.require(root, "", "strokes");
    if (!strokes.is_array()) r.fail("/strokes", "expected an array of strokes");
    for (std::size_t i = 0; i < strokes.size(); ++i) {
        const std::string at = "/strokes/" + std::to_string(i);
        json v = strokes[i];
        if (!v.is_object()) r.fail(at, "expected an object");
        // Any stroke may say how long it lasts in a film.
        if (auto d = v.find("duration"); d != v.end()) {
            s.durations.resize(i + 1, 0.0);
            s.durations[i] = r.positive(*d, at + "/duration");
            v.erase(d);
        }
        const std::string type = r.string(r.require(v, at, "type"), at + "/type");
        if (type == "sweep")
            s.strokes.emplace_back(readSweep(r, v, at));
        else if (type == "swirl")
            s.strokes.emplace_back(readSwirl(r, v, at));
        else if (type == "inflate")
            s.strokes.emplace_back(readInflate(r, v, at));
        else if (type == "pinch")
            s.strokes.emplace_back(readTopologyTool<PinchStroke>(r, v, at, checkPinch));
        else if (type == "strangle")
            s.strokes.emplace_back(readTopologyTool<StrangleStroke>(r, v, at, checkStrangle));
        else if (type == "keyframed")
            s.strokes.emplace_back(readKeyframed(r, v, at));
        else if (type == "slide")
            s.strokes.emplace_back(readSlide(r, v, at));
        else if (type == "flow")
            s.strokes.emplace_back(readFlow(r, v, at));
        else if (type == "fluid")
            s.strokes.emplace_back(readFluid(r, v, at));
        else if (type == "smooth")
            s.strokes.emplace_back(readSmooth(r, v, at));
        else
            r.fail(at + "/type", "unknown stroke type \"" + type +
                                     "\" (expected sweep, swirl, inflate, pinch, strangle, "
                                     "keyframed, slide, flow, fluid or smooth)");
        if (keyedDuration(s.strokes.back()) > 0.0 && i < s.durations.size() && s.durations[i] > 0.0)
            r.fail(at + "/duration", "a " + type + " stroke lasts until its last key");
    }
    return s;
}

StrokeScript readStrokeScript(const std::string& path, std::string* text) {
    std::string all;
    try {
        all = readWholeFile(path, kMostTextBytes, "a stroke script");
    } catch (const FileError& e) {
        throw ScriptError(e.what());
    }
    if (text) *text = all;
    return loadStrokeScript(all, path, directoryOf(path));
}

void loadScriptInputs(StrokeScript& script, const std::string& name, const std::string& baseDir) {
    const Reader r(name);
    // A baked tool's file: the band it needs reaches its falloff at the smallest scale it is
    // placed with.
    const auto load = [&](ToolSpec& t, const std::string& at) {
        if (t.shape != ToolShapeKind::Baked || t.baked) return;
        double smallest = t.size.x();
        for (const Placement& p : t.path)
            smallest = std::min(smallest, t.size.x() * p.scale.x());
        try {
            t.baked = loadBakedTool(t.source, baseDir, t.size.x(), t.falloff / smallest);
        } catch (const std::exception& e) {
            r.fail(at + "/shape", e.what());
        }
    };
    const auto loadTools = [&](SweepStroke& s, const std::string& at) {
        for (std::size_t j = 0; j < s.tools.size(); ++j)
            load(s.tools[j], at + "/tools/" + std::to_string(j));
        if (hasBakedTool(s)) checkSweepSegments(r, s, at);
    };
    for (std::size_t i = 0; i < script.strokes.size(); ++i) {
        const std::string at = "/strokes/" + std::to_string(i);
        Stroke& stroke = script.strokes[i];
        if (auto* sweep = std::get_if<SweepStroke>(&stroke)) {
            loadTools(*sweep, at);
        } else if (auto* slide = std::get_if<SlideStroke>(&stroke)) {
            loadTools(slide->local, at);
        } else if (auto* keyed = std::get_if<KeyframedStroke>(&stroke)) {
            load(keyed->tool, at + "/tool");
            if (keyed->tool.shape == ToolShapeKind::Baked) checkKeyedMotions(r, *keyed, at);
        } else if (auto* smooth = std::get_if<SmoothStroke>(&stroke)) {
            load(smooth->tool, at + "/tool");
        } else if (auto* flow = std::get_if<FlowStroke>(&stroke)) {
            FieldSpec& field = flow->field;
            if (field.kind != FieldSpec::Kind::Sampled || field.sampled) continue;
            try {
                field.sampled = std::make_shared<SampledField>(
                    readVelocitySamples(resolveAgainst(field.file, baseDir), field.gridName));
            } catch (const std::exception& e) {
                r.fail(at + "/field/vdb", e.what());
            }
            checkFlowSpan(r, *flow, at);
        } else if (auto* fluid = std::get_if<FluidStroke>(&stroke)) {
            if (fluid->fluid) continue;
            try {
                fluid->fluid = sweptFluid();
            } catch (const std::exception& e) {
                r.fail(at, std::string("cannot solve the swept fluid: ") + e.what());
            }
        }
    }
}

StrokeScript loadStrokeScript(const std::string& text, const std::string& name,
                              const std::string& baseDir) {
    StrokeScript script = parseStrokeScript(text, name);
    loadScriptInputs(script, name, baseDir);
    return script;
}

std::vector<std::string> strokeScriptFields() {
    std::vector<std::string> out;
    for (const auto& entry : kScriptFields)
        for (const char* f : entry.second)
            if (std::find(out.begin(), out.end(), f) == out.end()) out.emplace_back(f);
    return out;
}

} // namespace sweepers
