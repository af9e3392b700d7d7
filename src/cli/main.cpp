// sweepers-cli: the command-line front end. Every failure prints one line on stderr and
// exits non-zero.
#include <cstdio>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "deform/sweep.h"
#include "io/stroke_script.h"

namespace {

using namespace sweepers;

std::string boxJson(const Box& b) {
    return nlohmann::json::array({nlohmann::json::array({b.min.x(), b.min.y(), b.min.z()}),
                                  nlohmann::json::array({b.max.x(), b.max.y(), b.max.z()})})
        .dump();
}

// `check`: validate a script and print how each sweep segment will be cut into sub-steps.
int runCheck(const std::string& path, bool asJson) {
    const StrokeScript script = readStrokeScript(path);
    nlohmann::json out = nlohmann::json::array();
    for (std::size_t i = 0; i < script.strokes.size(); ++i) {
        if (const auto* sweep = std::get_if<SweepStroke>(&script.strokes[i])) {
            const Sweep sw = toSweep(*sweep);
            for (std::size_t k = 0; k < sw.segmentCount(); ++k) {
                const SweepSegment seg(sw, k);
                out.push_back(
                    {{"stroke", i},
                     {"type", "sweep"},
                     {"segment", k},
                     {"tools", seg.toolCount()},
                     {"steps", seg.steps()},
                     {"bound", seg.stepBound()},
                     {"affected_box", nlohmann::json::parse(boxJson(seg.affectedBox()))}});
            }
        } else {
            out.push_back({{"stroke", i}, {"type", "swirl"}});
        }
    }
    if (asJson) {
        std::cout << out.dump(2) << "\n";
        return 0;
    }
    std::cout << path << ": valid, " << script.strokes.size() << " strokes\n";
    for (const auto& row : out) {
        if (row["type"] == "swirl") {
            std::cout << "  stroke " << row["stroke"] << ": swirl\n";
            continue;
        }
        std::cout << "  stroke " << row["stroke"] << " segment " << row["segment"] << ": "
                  << row["tools"] << " tool(s), " << row["steps"] << " sub-steps (bound "
                  << row["bound"].get<double>() << "), affected box " << row["affected_box"].dump()
                  << "\n";
    }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    CLI::App app{"sweepers-cli: sculpt narrow-band level sets with sweepers"};
    app.require_subcommand(1);

    std::string scriptPath;
    bool asJson = false;
    CLI::App* check = app.add_subcommand("check", "Validate a stroke script and show its plan");
    check->add_option("script", scriptPath, "Stroke script (JSON)")->required();
    check->add_flag("--json", asJson, "Print the plan as JSON");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }
    try {
        if (*check) return runCheck(scriptPath, asJson);
    } catch (const std::exception& e) {
        std::cerr << "sweepers-cli: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
