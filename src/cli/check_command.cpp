// SPDX-License-Identifier: Apache-2.0
#include "cli/check_command.h"

#include <iostream>
#include <map>

#include "cli/command.h"
#include "core/format.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "io/vdb_file.h"

namespace sweepers::cli {

using nlohmann::json;

namespace {

json vec(const Eigen::Vector3d& v) {
    return json::array({v.x(), v.y(), v.z()});
}

// The voxel size apply sculpts at: the option's, a VDB start's own (read, and refused where
// apply would refuse it), else the script's.
double plannedVoxelSize(const StrokeScript& script, const std::string& path, double voxelSize) {
    if (script.start.kind != StartShape::Kind::Vdb)
        return voxelSize > 0.0 ? voxelSize : script.grid.voxelSize;
    return makeStartGrid(script, directoryOf(path), voxelSize, &gStop)->voxelSize()[0];
}

// The human words of one stroke's rows.
void printStroke(std::size_t stroke, const json& rows) {
    const std::string head = "  stroke " + std::to_string(stroke);
    if (rows.empty()) {
        std::cout << head << ": deforms nothing (a keyed stroke back at rest at its last key)\n";
        return;
    }
    const json& first = rows.front();
    const std::string type = first["type"];
    if (first.contains("center")) {
        std::cout << head << ": smooth, " << rows.size()
                  << " dab(s) of curvature flow under the brush\n";
        return;
    }
    if (first.value("decided_on_shape", false) && !first.contains("steps")) {
        std::cout << head << ": " << type << " x" << rows.size()
                  << ", reaching the whole shape as it is when the stroke comes\n";
        return;
    }
    if (first.value("decided_on_shape", false)) {
        std::cout << head << ": " << type << ", " << first["steps"]
                  << " sub-steps, in as many segments as the shape's stretch needs (chosen "
                  << "when applied), affected box " << first["affected_box"].dump() << "\n";
        return;
    }
    for (const json& row : rows) {
        // A sweep's rows name their segment, as do those of any stroke of several steps.
        std::cout << head;
        if (type == "sweep" || rows.size() > 1) std::cout << " segment " << row["segment"];
        if (type == "sweep")
            std::cout << ": " << row["tools"] << " tool(s), " << row["steps"]
                      << " sub-steps (bound " << row["bound"].get<double>() << ")";
        else
            std::cout << ": " << row["type"].get<std::string>() << ", " << row["steps"]
                      << " sub-steps";
        if (row.contains("fluid_steps")) std::cout << ", " << row["fluid_steps"] << " flow steps";
        std::cout << ", affected box " << row["affected_box"].dump() << "\n";
    }
}

} // namespace

json stepJson(std::size_t stroke, const PlannedStep& step) {
    json j = {{"stroke", stroke}, {"segment", step.segment}, {"type", step.kind}};
    if (step.dab) {
        j["center"] = vec(step.dab->center);
        j["radius"] = step.dab->radius;
        j["time"] = step.dab->time;
        return j;
    }
    if (step.leftToShape) j["decided_on_shape"] = true;
    if (step.subSteps == 0) return j; // nothing but its kind is known ahead of the shape
    j["tools"] = step.tools;
    j["steps"] = step.subSteps;
    j["bound"] = step.bound;
    j["affected_box"] = {vec(step.affected.min), vec(step.affected.max)};
    if (step.fluidSteps > 0) j["fluid_steps"] = step.fluidSteps;
    return j;
}

int runCheck(const CheckArgs& a) {
    const StrokeScript script = readStrokeScript(a.script);
    requireBuildableStart(script, a.voxelSize); // the limits apply holds the script to
    const double h = plannedVoxelSize(script, a.script, a.voxelSize);
    json out = json::array();
    std::map<std::size_t, json> byStroke;
    for (std::size_t i = 0; i < script.strokes.size(); ++i) {
        byStroke[i] = json::array();
        for (const PlannedStep& step : planStrokeAhead(script.strokes[i], h)) {
            out.push_back(stepJson(i, step));
            byStroke[i].push_back(out.back());
        }
    }
    if (gOut.json) {
        printJson({{"script", a.script},
                   {"valid", true},
                   {"strokes", script.strokes.size()},
                   {"voxel_size", h},
                   {"half_width", script.grid.halfWidth},
                   {"deformations", out}});
        return kDone;
    }
    std::cout << a.script << ": valid, " << script.strokes.size() << " strokes, planned at voxel "
              << "size " << formatNumber(h) << "\n";
    for (const auto& [stroke, rows] : byStroke)
        printStroke(stroke, rows);
    return kDone;
}

} // namespace sweepers::cli
