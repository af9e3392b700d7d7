// SPDX-License-Identifier: Apache-2.0
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "io/stroke_script.h"
#include "io/vdb_file.h"
#include "levelset/create.h"
#include "scratch_dir.h"

using namespace sweepers;
namespace fs = std::filesystem;

namespace {

const char* kFull = R"({
  "sweepers": 1,
  "grid": { "voxel_size": 0.015625, "half_width": 3.5 },
  "start": { "sphere": { "center": [0.1, -0.2, 0.3], "radius": 0.9 } },
  "strokes": [
    { "type": "sweep", "mirror": "x",
      "tools": [ { "shape": "ball", "size": 0.3, "falloff": 0.25,
                   "path": [ { "t": [0.2, 1, 0] },
                             { "t": [0.2, 1.6, 0], "r": [0, 0, 1, 30], "s": 1.2 },
                             { "t": [0.3, 1.7, 0.1], "r": [0, 0, 1, 45], "s": [1.2, 1.3, 1.1] } ] },
                 { "shape": "ellipsoid", "size": [0.1, 0.2, 0.3], "falloff": 0.125,
                   "path": [ { "t": [0.5, 0, 0] }, { "t": [0.5, 0.1, 0] },
                             { "t": [0.5, 0.2, 0], "r": [1, 0, 0, -20] } ] } ] },
    { "type": "swirl", "at": [0, 0, 1], "move": [0, 0, 0.5], "radius": 0.3,
      "ring": "convolution", "swirls": 12 }
  ]
})";

std::string errorOf(const std::string& text) {
    try {
        loadStrokeScript(text, "bad.json");
    } catch (const ScriptError& e) {
        return e.what();
    }
    return "";
}

// A minimal valid script with one field replaced by `stroke`.
std::string withStroke(const std::string& stroke) {
    return R"({"sweepers": 1, "strokes": [)" + stroke + "]}";
}

const std::string kGoodTool =
    R"("shape": "ball", "size": 0.3, "falloff": 0.3, "path": [{"t": [0,0,0]}, {"t": [0,0.5,0]}])";

} // namespace

TEST(StrokeScript, EveryFieldRoundTrips) {
    const StrokeScript a = parseStrokeScript(kFull, "full.json");
    EXPECT_EQ(a.grid.voxelSize, 0.015625);
    EXPECT_EQ(a.grid.halfWidth, 3.5);
    EXPECT_EQ(a.start.kind, StartShape::Kind::Sphere);
    EXPECT_EQ(a.start.center, Eigen::Vector3d(0.1, -0.2, 0.3));
    EXPECT_EQ(a.start.radius, 0.9);
    ASSERT_EQ(a.strokes.size(), 2u);
    const auto& sweep = std::get<SweepStroke>(a.strokes[0]);
    EXPECT_EQ(sweep.mirror, MirrorAxis::X);
    ASSERT_EQ(sweep.tools.size(), 2u);
    EXPECT_EQ(sweep.tools[0].shape, ToolShapeKind::Ball);
    EXPECT_EQ(sweep.tools[0].size, Eigen::Vector3d::Constant(0.3));
    EXPECT_EQ(sweep.tools[0].falloff, 0.25);
    EXPECT_EQ(sweep.tools[0].path[1].angleDegrees, 30.0);
    EXPECT_EQ(sweep.tools[0].path[1].scale, Eigen::Vector3d::Constant(1.2));
    EXPECT_EQ(sweep.tools[0].path[2].scale, Eigen::Vector3d(1.2, 1.3, 1.1));
    EXPECT_EQ(sweep.tools[1].shape, ToolShapeKind::Ellipsoid);
    EXPECT_EQ(sweep.tools[1].size, Eigen::Vector3d(0.1, 0.2, 0.3));
    EXPECT_EQ(sweep.tools[1].path[2].axis, Eigen::Vector3d(1, 0, 0));
    const auto& swirl = std::get<SwirlStroke>(a.strokes[1]);
    EXPECT_EQ(swirl.ring, SwirlRing::Convolution);
    EXPECT_EQ(swirl.swirls, 12);
    EXPECT_EQ(swirl.move, Eigen::Vector3d(0, 0, 0.5));

    // Written and read back, everything is equal, and writing again is byte-identical.
    const std::string once = formatStrokeScript(a);
    const StrokeScript b = parseStrokeScript(once, "again.json");
    EXPECT_EQ(formatStrokeScript(b), once);
    const auto& sweepB = std::get<SweepStroke>(b.strokes[0]);
    for (std::size_t t = 0; t < 2; ++t)
        for (std::size_t i = 0; i < 3; ++i)
            EXPECT_TRUE(sweepB.tools[t].path[i] == sweep.tools[t].path[i]);
    EXPECT_EQ(b.start.center, a.start.center);
}

TEST(StrokeScript, FileStartsRoundTripAndAtomicWrite) {
    const fs::path dir = fs::temp_directory_path() / "sweepers_script_test";
    fs::create_directories(dir);
    for (const char* start : {R"({"vdb": "shapes/bunny.vdb"})", R"({"mesh": "tool.obj"})",
                              R"({"vdb": "shapes/several.vdb", "grid": "ears"})"}) {
        const std::string text =
            std::string(R"({"sweepers": 1, "start": )") + start + R"(, "strokes": []})";
        const StrokeScript s = parseStrokeScript(text, "s.json");
        const fs::path file = dir / "out.json";
        writeStrokeScript(s, file.string());
        const StrokeScript back = readStrokeScript(file.string());
        EXPECT_EQ(back.start.kind, s.start.kind);
        EXPECT_EQ(back.start.file, s.start.file);
        EXPECT_EQ(back.start.gridName, s.start.gridName);
    }
    EXPECT_EQ(parseStrokeScript(R"({"sweepers": 1, "start": {"vdb": "a.vdb", "grid": "ears"},
                                   "strokes": []})",
                                "s.json")
                  .start.gridName,
              "ears");
    // Nothing but the target is left in the directory.
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir))
        files += e.is_regular_file();
    EXPECT_EQ(files, 1);
    // An unwritable target fails cleanly.
    EXPECT_THROW(writeStrokeScript(StrokeScript{}, (dir / "missing" / "x.json").string()),
                 std::runtime_error);
    fs::remove_all(dir);
}

TEST(StrokeScript, BadInputIsRefusedWithFileLocationAndReason) {
    struct Bad {
        std::string text, location, reason;
    };
    const std::vector<Bad> bad{
        {"{\"sweepers\": 1,\n  \"strokes\": [ }", "line 2, column 16", "invalid JSON"},
        {withStroke(
             R"({"type": "sweep", "tools": [{"shape": "cube", "size": 0.3, "falloff": 0.3, "path": []}]})"),
         "/strokes/0/tools/0/shape", "unknown shape \"cube\""},
        {withStroke(
             R"({"type": "sweep", "tools": [{"shape": "ball", "size": -0.3, "falloff": 0.3, "path": []}]})"),
         "/strokes/0/tools/0/size", "must be positive"},
        {withStroke(
             R"({"type": "sweep", "tools": [{"shape": "ball", "size": 0, "falloff": 0.3, "path": []}]})"),
         "/strokes/0/tools/0/size", "must be positive"},
        {withStroke(
             R"({"type": "sweep", "tools": [{"shape": "ellipsoid", "size": [0.1, 0, 0.2], "falloff": 0.3, "path": []}]})"),
         "/strokes/0/tools/0/size/1", "must be positive"},
        {withStroke(R"({"type": "sweep", "tools": [{)" + kGoodTool.substr(0, 44) +
                    R"("falloff": NaN}]})"),
         "line 1", "invalid JSON"},
        {withStroke(
             R"({"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 1e999, "path": []}]})"),
         "line 1, column 99", "the number 1e999 is not finite"},
        {withStroke(
             R"({"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3, "path": [{"t": [0,0,0]}]}]})"),
         "/strokes/0/tools/0/path", "at least two placements"},
        {withStroke(R"({"type": "smudge"})"), "/strokes/0/type", "unknown stroke type \"smudge\""},
        {withStroke(R"({"type": "sweep", "strength": 1.5, "tools": [{)" + kGoodTool + R"(}]})"),
         "/strokes/0/strength", "at most 1"},
        {withStroke(
             R"({"type": "smooth", "strength": 10.5, "tool": {"shape": "ball", "size": 0.3, "falloff": 0.3, "path": [{"t": [0,0,0]}]}})"),
         "/strokes/0/strength", "at most 10"},
        {withStroke(R"({"type": "sweep", "tools": [{)" + kGoodTool + R"(, "fallof": 0.2}]})"),
         "/strokes/0/tools/0/fallof", "unknown field"},
        {withStroke(
             R"({"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3, "path": [{"t": [0,0]}, {"t": [0,0,1]}]}]})"),
         "/strokes/0/tools/0/path/0/t", "3 numbers"},
        {withStroke(
             R"({"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3, "path": [{"t": [0,0,0]}, {"t": [0,0,0], "r": [0,0,1,180]}]}]})"),
         "/strokes/0/tools/0/path/1", "more than 179 degrees"},
        {withStroke(
             R"({"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3, "path": [{"t": [0,0,0]}, {"t": [0,0,0], "s": [1, -1, 1]}]}]})"),
         "/strokes/0/tools/0/path/1/s/1", "must be positive"},
        {withStroke(
             R"({"type": "swirl", "at": [0,0,0], "move": [0,0,1], "radius": 0.2, "ring": "square"})"),
         "/strokes/0/ring", "discrete"},
        {R"({"sweepers": 2, "strokes": []})", "/sweepers", "unsupported format version"},
        {R"({"sweepers": 1})", "/strokes", "missing field"},
        {R"({"sweepers": 1, "grid": {"voxel_size": "small"}, "strokes": []})", "/grid/voxel_size",
         "expected a number"},
        {R"({"sweepers": 1, "start": {"sphere": {"center": [0,0,0], "radius": 1}, "vdb": "a.vdb"}, "strokes": []})",
         "/start", "exactly one"},
        {R"({"sweepers": 1, "start": {"vdb": "a.vdb", "grid": ""}, "strokes": []})", "/start/grid",
         "empty grid name"},
        {R"({"sweepers": 1, "start": {"mesh": "a.obj", "grid": "b"}, "strokes": []})",
         "/start/grid", "this start is not a VDB file"},
        {R"({"sweepers": 1, "start": {"grid": "b"}, "strokes": []})", "/start", "exactly one"},
        {R"([1, 2])", "/", "expected an object"},
        {withStroke(
             R"({"type": "pinch", "at": [0,0,0], "axis": [0,0,0], "size": 1, "falloff": 0.3, "open": 0.1})"),
         "/strokes/0/axis", "needs a direction"},
        {withStroke(
             R"({"type": "pinch", "at": [0,0,0], "axis": [0,1,0], "size": 1, "falloff": 0.3, "open": -0.1})"),
         "/strokes/0/open", "must be positive"},
        {withStroke(
             R"({"type": "pinch", "at": [0,0,0], "axis": [0,1,0], "size": 1e4, "falloff": 0.001, "open": 0.1})"),
         "/strokes/0/size", "over 1000 falloffs"},
        // Extreme values, refused before any conversion to an index or a count.
        {withStroke(
             R"({"type": "smooth", "tool": {"shape": "ball", "size": 1e30, "falloff": 0.1, "path": [{"t": [0, 1, 0]}]}})"),
         "/strokes/0/tool/size", "beyond the largest number a script takes, 1e5"},
        {withStroke(R"({"type": "inflate", "at": [0, 1, 0], "radius": 1e30})"), "/strokes/0/radius",
         "beyond the largest number"},
        {withStroke(R"({"type": "swirl", "at": [0, 1, 0], "move": [0, 0.1, 0], "radius": 1e30})"),
         "/strokes/0/radius", "beyond the largest number"},
        {withStroke(R"({"type": "fluid", "radius": 1e-300, "path": [[0, 0.85, 0], [0, 1, 0]]})"),
         "/strokes/0/radius", "below the smallest positive number a script takes, 1e-9"},
        {withStroke(
             R"({"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3, "path": [{"t": [0, 1e8, 0]}, {"t": [0, 1, 0]}]}]})"),
         "/strokes/0/tools/0/path/0/t/1", "beyond the largest number"},
        {withStroke(
             R"({"type": "strangle", "at": [0,0,0], "axis": [0,1,0], "size": 1, "falloff": 0.3})"),
         "/strokes/0/open", "missing field"},
        {withStroke(
             R"({"type": "strangle", "at": [0,0,0], "axis": [0,1,0], "size": 1, "falloff": 0.3, "open": 0.2, "gap": 1})"),
         "/strokes/0/gap", "unknown field"},
    };
    for (const Bad& b : bad) {
        const std::string msg = errorOf(b.text);
        EXPECT_EQ(msg.rfind("bad.json: ", 0), 0u) << msg;
        EXPECT_NE(msg.find(b.location), std::string::npos) << msg << "\n  wanted " << b.location;
        EXPECT_NE(msg.find(b.reason), std::string::npos) << msg << "\n  wanted " << b.reason;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
    }
}

TEST(StrokeScript, TopologyToolsRoundTrip) {
    const StrokeScript a = parseStrokeScript(
        withStroke(
            R"({"type": "pinch", "at": [0.1, 0, 0], "axis": [0, 2, 0], "size": 1.25, "falloff": 0.4, "open": 0.3},
                      {"type": "strangle", "at": [0, 1.4, 0], "axis": [0, 1, 0], "size": 0.6, "falloff": 0.25, "open": 0.2})"),
        "tools.json");
    ASSERT_EQ(a.strokes.size(), 2u);
    const auto& pinch = std::get<PinchStroke>(a.strokes[0]);
    EXPECT_EQ(pinch.at, Eigen::Vector3d(0.1, 0, 0));
    EXPECT_EQ(pinch.axis, Eigen::Vector3d(0, 2, 0));
    EXPECT_EQ(pinch.size, 1.25);
    EXPECT_EQ(pinch.falloff, 0.4);
    EXPECT_EQ(pinch.open, 0.3);
    const auto& strangle = std::get<StrangleStroke>(a.strokes[1]);
    EXPECT_EQ(strangle.at, Eigen::Vector3d(0, 1.4, 0));
    EXPECT_EQ(strangle.open, 0.2);
    const std::string once = formatStrokeScript(a);
    EXPECT_EQ(formatStrokeScript(parseStrokeScript(once, "again.json")), once);
    // A pinch is its needles' segments and the pull; a strangle, the noose's and the pull.
    EXPECT_EQ(segmentCount(a.strokes[0], 1.0 / 32), 14u);
    EXPECT_GT(segmentCount(a.strokes[1], 1.0 / 32), 2u);
}

// Parsing is data only: a script naming files that are not there parses, its baked tool and
// sampled field unloaded and no fluid solved (no cache made); loading its inputs reads what
// it names and refuses the script at the JSON location of what cannot be made, including a
// baked tool's motion, whose sub-steps need the tool's shape.
TEST(StrokeScript, ParsingTouchesNoDiskLoadingReadsWhatItNames) {
    const test::ScratchDir dir;
    const char* had = std::getenv("SWEEPERS_CACHE");
    const std::string before = had ? had : "";
    ::setenv("SWEEPERS_CACHE", (dir / "cache").c_str(), 1);
    const auto tool = [](const std::string& file, const std::string& turn) {
        return withStroke(R"({"type": "sweep", "tools": [{"shape": {"vdb": ")" + file +
                          R"("}, "size": 0.3, "falloff": 0.3, "path": [{"t": [0, 1, 0]},
                          {"t": [0, 1.2, 0], "r": [0, 0, 1, )" +
                          turn + "]}]}]}");
    };
    const std::string field =
        withStroke(R"({"type": "flow", "field": {"vdb": "field.vdb"}, "from": 0, "to": 1})");
    const std::string fluid =
        withStroke(R"({"type": "fluid", "radius": 0.3, "path": [[0, 0.85, 0], [0, 1, 0]]})");
    const StrokeScript a = parseStrokeScript(tool("tool.vdb", "10"), "a.json");
    EXPECT_FALSE(std::get<SweepStroke>(a.strokes[0]).tools[0].baked);
    EXPECT_FALSE(std::get<FlowStroke>(parseStrokeScript(field, "b.json").strokes[0]).field.sampled);
    EXPECT_FALSE(std::get<FluidStroke>(parseStrokeScript(fluid, "c.json").strokes[0]).fluid);
    EXPECT_FALSE(fs::exists(dir / "cache"));
    const auto refusal = [&](const std::string& text) {
        try {
            loadStrokeScript(text, "s.json", dir.path.string());
        } catch (const ScriptError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(refusal(tool("tool.vdb", "10")).rfind("s.json: /strokes/0/tools/0/shape: ", 0), 0u)
        << refusal(tool("tool.vdb", "10"));
    EXPECT_EQ(refusal(field).rfind("s.json: /strokes/0/field/vdb: ", 0), 0u) << refusal(field);
    // The tool there: loading it plans its sweep, and a turn past 179 degrees is refused then.
    writeLevelSet(*makeSphere(Eigen::Vector3d::Zero(), 1.0, 1.0 / 8, 3.0), dir / "tool.vdb");
    EXPECT_EQ(refusal(tool("tool.vdb", "10")), "");
    EXPECT_NO_THROW(parseStrokeScript(tool("tool.vdb", "179.5"), "d.json"));
    EXPECT_EQ(refusal(tool("tool.vdb", "179.5")).rfind("s.json: /strokes/0/tools/0/path/1: ", 0),
              0u)
        << refusal(tool("tool.vdb", "179.5"));
    // A ball's sweep needs no file: the same turn is refused when parsed.
    EXPECT_THROW(parseStrokeScript(withStroke(R"({"type": "sweep", "tools": [{"shape": "ball",
        "size": 0.3, "falloff": 0.3, "path": [{"t": [0, 1, 0]},
        {"t": [0, 1.2, 0], "r": [0, 0, 1, 179.5]}]}]})"),
                                   "e.json"),
                 ScriptError);
    if (had)
        ::setenv("SWEEPERS_CACHE", before.c_str(), 1);
    else
        ::unsetenv("SWEEPERS_CACHE");
}

TEST(StrokeScript, MissingFileIsAScriptError) {
    try {
        readStrokeScript("/nonexistent/dir/script.json");
        FAIL() << "no error";
    } catch (const ScriptError& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/script.json: cannot open"),
                  std::string::npos);
    }
}

TEST(StrokeScript, ShippedScriptsAreValid) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(SWEEPERS_DATA_DIR)) {
        if (e.path().extension() != ".json") continue;
        ++n;
        EXPECT_NO_THROW(readStrokeScript(e.path().string())) << e.path();
    }
    EXPECT_GT(n, 0);
}

// The reference users write scripts from names every field the parser accepts, as `name`:
// a field added to the parser and not to docs/stroke-scripts.md fails here.
TEST(StrokeScript, TheReferenceNamesEveryFieldTheParserAccepts) {
    std::ifstream in(std::string(SWEEPERS_DOCS_DIR) + "/stroke-scripts.md");
    ASSERT_TRUE(in) << "docs/stroke-scripts.md is missing";
    const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::vector<std::string> fields = strokeScriptFields();
    EXPECT_GE(fields.size(), 30u); // every object's fields, not an empty list
    for (const std::string& f : fields)
        EXPECT_NE(doc.find("`" + f + "`"), std::string::npos)
            << "docs/stroke-scripts.md does not name the field `" << f << "`";
}

// The list is the parser's own: a field it names is accepted where the list puts it, and a
// name outside it is refused.
TEST(StrokeScript, TheFieldListIsWhatTheParserAccepts) {
    const std::vector<std::string> fields = strokeScriptFields();
    for (const char* f : {"sweepers", "half_width", "degrees_per_second", "swirls", "open",
                          "duration", "time", "voxel_size"})
        EXPECT_NE(std::find(fields.begin(), fields.end(), f), fields.end()) << f;
    EXPECT_THROW(parseStrokeScript(R"({"sweepers": 1, "strokes": [], "colour": 1})", "s.json"),
                 ScriptError);
}
