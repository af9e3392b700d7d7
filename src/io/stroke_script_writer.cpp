// SPDX-License-Identifier: Apache-2.0
// Writing stroke scripts (io/stroke_script.h): the script as JSON that reads back to the same
// script (numbers round-trip exactly), the files it names, the atomic write.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "io/atomic_file.h"
#include "io/baked_tool.h"
#include "io/stroke_script.h"

namespace sweepers {

using nlohmann::json;

namespace {

json vecJson(const Eigen::Vector3d& v) {
    return json::array({v.x(), v.y(), v.z()});
}

json placementJson(const Placement& p) {
    json j;
    j["t"] = vecJson(p.t);
    if (p.hasRotation()) j["r"] = json::array({p.axis.x(), p.axis.y(), p.axis.z(), p.angleDegrees});
    if (p.scale != Eigen::Vector3d::Ones()) {
        if (p.uniformScale())
            j["s"] = p.scale.x();
        else
            j["s"] = vecJson(p.scale);
    }
    return j;
}

json bakedSourceJson(const BakedToolSource& b) {
    if (b.kind == BakedToolSource::Kind::Mesh)
        return {{"mesh", b.file}, {"voxel_size", b.voxelSize}};
    json j = {{"vdb", b.file}};
    if (!b.gridName.empty()) j["grid"] = b.gridName;
    return j;
}

template <typename Spec> json topologyToolJson(const char* type, const Spec& s) {
    return {{"type", type},   {"at", vecJson(s.at)},  {"axis", vecJson(s.axis)},
            {"size", s.size}, {"falloff", s.falloff}, {"open", s.open}};
}

const char* mirrorName(MirrorAxis m) {
    switch (m) {
    case MirrorAxis::X:
        return "x";
    case MirrorAxis::Y:
        return "y";
    case MirrorAxis::Z:
        return "z";
    case MirrorAxis::None:
        break;
    }
    return "";
}

json toolJson(const ToolSpec& t, bool withPath) {
    json tj;
    switch (t.shape) {
    case ToolShapeKind::Ball:
        tj["shape"] = "ball";
        tj["size"] = t.size.x();
        break;
    case ToolShapeKind::Ellipsoid:
        tj["shape"] = "ellipsoid";
        tj["size"] = vecJson(t.size);
        break;
    case ToolShapeKind::Baked:
        tj["shape"] = bakedSourceJson(t.source);
        tj["size"] = t.size.x();
        break;
    }
    tj["falloff"] = t.falloff;
    if (withPath) {
        json path = json::array();
        for (const Placement& p : t.path)
            path.push_back(placementJson(p));
        tj["path"] = path;
    }
    return tj;
}

// A stroke's radial symmetry, where it has copies.
void radialJson(json& j, const RadialSymmetry& radial) {
    if (radial.count > 1)
        j["radial"] = {{"axis", vecJson(radial.axis)},
                       {"center", vecJson(radial.center)},
                       {"count", radial.count}};
}

json toolsJson(const SweepStroke& sweep) {
    json tools = json::array();
    for (const ToolSpec& t : sweep.tools)
        tools.push_back(toolJson(t, true));
    return tools;
}

json keysJson(const Keyframes& keys) {
    json out = json::array();
    for (std::size_t i = 0; i < keys.times.size(); ++i) {
        json k = placementJson(keys.placements[i]);
        k["time"] = keys.times[i];
        out.push_back(k);
    }
    return out;
}

} // namespace

std::string formatStrokeScript(const StrokeScript& s, int indent) {
    json root;
    root["sweepers"] = s.version;
    root["grid"] = {{"voxel_size", s.grid.voxelSize}, {"half_width", s.grid.halfWidth}};
    switch (s.start.kind) {
    case StartShape::Kind::Sphere:
        root["start"] = {
            {"sphere", {{"center", vecJson(s.start.center)}, {"radius", s.start.radius}}}};
        break;
    case StartShape::Kind::Vdb:
        root["start"] = {{"vdb", s.start.file}};
        if (!s.start.gridName.empty()) root["start"]["grid"] = s.start.gridName;
        break;
    case StartShape::Kind::Mesh:
        root["start"] = {{"mesh", s.start.file}};
        break;
    }
    json strokes = json::array();
    for (const Stroke& stroke : s.strokes) {
        json j;
        if (const auto* sw = std::get_if<SweepStroke>(&stroke)) {
            j["type"] = "sweep";
            if (sw->mirror != MirrorAxis::None) j["mirror"] = mirrorName(sw->mirror);
            j["tools"] = toolsJson(*sw);
            if (sw->strength != 1.0) j["strength"] = sw->strength;
            radialJson(j, sw->radial);
        } else if (const auto* sr = std::get_if<SwirlStroke>(&stroke)) {
            j["type"] = "swirl";
            j["at"] = vecJson(sr->at);
            j["move"] = vecJson(sr->move);
            j["radius"] = sr->radius;
            j["ring"] = sr->ring == SwirlRing::Convolution ? "convolution" : "discrete";
            j["swirls"] = sr->swirls;
            if (sr->ball > 0.0) j["ball"] = sr->ball;
            if (sr->strength != 1.0) j["strength"] = sr->strength;
            radialJson(j, sr->radial);
        } else if (const auto* in = std::get_if<InflateStroke>(&stroke)) {
            j["type"] = "inflate";
            j["at"] = vecJson(in->at);
            j["radius"] = in->radius;
            if (in->strength != 1.0) j["strength"] = in->strength;
            if (in->remove) j["remove"] = true;
            radialJson(j, in->radial);
        } else if (const auto* sm = std::get_if<SmoothStroke>(&stroke)) {
            j["type"] = "smooth";
            j["tool"] = toolJson(sm->tool, true);
            if (sm->strength != 1.0) j["strength"] = sm->strength;
            radialJson(j, sm->radial);
        } else if (const auto* pinch = std::get_if<PinchStroke>(&stroke)) {
            j = topologyToolJson("pinch", *pinch);
        } else if (const auto* strangle = std::get_if<StrangleStroke>(&stroke)) {
            j = topologyToolJson("strangle", *strangle);
        } else if (const auto* keyed = std::get_if<KeyframedStroke>(&stroke)) {
            j["type"] = "keyframed";
            j["tool"] = toolJson(keyed->tool, false);
            j["keys"] = keysJson(keyed->keys);
        } else if (const auto* fluid = std::get_if<FluidStroke>(&stroke)) {
            j["type"] = "fluid";
            j["radius"] = fluid->radius;
            j["path"] = json::array();
            for (const Eigen::Vector3d& p : fluid->path)
                j["path"].push_back(vecJson(p));
            if (fluid->strength != 1.0) j["strength"] = fluid->strength;
        } else if (const auto* flow = std::get_if<FlowStroke>(&stroke)) {
            j["type"] = "flow";
            const FieldSpec& f = flow->field;
            if (f.kind == FieldSpec::Kind::Rotation)
                j["field"] = {{"rotation",
                               {{"center", vecJson(f.center)},
                                {"axis", vecJson(f.axis)},
                                {"degrees_per_second", f.degreesPerSecond},
                                {"radius", f.radius},
                                {"falloff", f.falloff}}}};
            else if (f.kind == FieldSpec::Kind::Sampled)
                j["field"] = f.gridName.empty() ? json{{"vdb", f.file}}
                                                : json{{"vdb", f.file}, {"grid", f.gridName}};
            else
                j["field"] = fieldName(f.kind);
            j["from"] = flow->from;
            j["to"] = flow->to;
            if (flow->segments > 0) j["segments"] = flow->segments;
        } else {
            const SlideStroke& slide = std::get<SlideStroke>(stroke);
            j["type"] = "slide";
            if (slide.local.mirror != MirrorAxis::None)
                j["mirror"] = mirrorName(slide.local.mirror);
            j["tools"] = toolsJson(slide.local);
            j["keys"] = keysJson(slide.frame);
        }
        const std::size_t i = strokes.size();
        if (i < s.durations.size() && s.durations[i] > 0.0) j["duration"] = s.durations[i];
        strokes.push_back(j);
    }
    root["strokes"] = strokes;
    return indent < 0 ? root.dump() : root.dump(indent) + "\n";
}

void forEachScriptFile(StrokeScript& s, const std::function<void(std::string& file)>& visit) {
    if (s.start.kind != StartShape::Kind::Sphere) visit(s.start.file);
    for (Stroke& stroke : s.strokes) {
        std::vector<ToolSpec*> tools;
        if (auto* sweep = std::get_if<SweepStroke>(&stroke))
            for (ToolSpec& t : sweep->tools)
                tools.push_back(&t);
        if (auto* slide = std::get_if<SlideStroke>(&stroke))
            for (ToolSpec& t : slide->local.tools)
                tools.push_back(&t);
        if (auto* keyed = std::get_if<KeyframedStroke>(&stroke)) tools.push_back(&keyed->tool);
        if (auto* flow = std::get_if<FlowStroke>(&stroke);
            flow && flow->field.kind == FieldSpec::Kind::Sampled)
            visit(flow->field.file);
        for (ToolSpec* t : tools)
            if (t->shape == ToolShapeKind::Baked) visit(t->source.file);
    }
}

StrokeScript withAbsoluteFiles(StrokeScript s, const std::string& scriptDir) {
    forEachScriptFile(s, [&](std::string& file) {
        if (!file.empty() && file.front() != '/')
            file = std::filesystem::absolute(resolveAgainst(file, scriptDir)).string();
    });
    return s;
}

void writeStrokeScript(const StrokeScript& script, const std::string& path) {
    writeTextAtomically(path, formatStrokeScript(script));
}

} // namespace sweepers
