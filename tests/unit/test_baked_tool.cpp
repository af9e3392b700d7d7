// SPDX-License-Identifier: Apache-2.0
// Baked tools (3.4.3): a level set or a closed mesh as a sculpting tool.
#include <cmath>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "io/mesh_file.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "io/vdb_file.h"
#include "levelset/band.h"
#include "levelset/create.h"
#include "levelset/level_set_tool.h"
#include "mesh/marching_cubes.h"
#include "random.h"
#include "scratch_dir.h"
#include "sculpt/sculptor.h"
#include "tools/ellipsoid.h"

using namespace sweepers;
using sweepers::test::Rng;
using sweepers::test::ScratchDir;

namespace {

constexpr double kToolRadius = 0.25, kToolVoxel = 1.0 / 64;

// A ball of radius kToolRadius at the origin as a tool whose distance is exact to `reach`.
LevelSetTool sphereTool(double reach) {
    const GridPtr sphere = makeSphere(Eigen::Vector3d::Zero(), kToolRadius, kToolVoxel, 3.0);
    return LevelSetTool(bakeToolGrid(*sphere, reach), "sphere");
}

Eigen::Affine3d somePlacement(double scale) {
    Eigen::Affine3d X = Eigen::Affine3d::Identity();
    X.translate(Eigen::Vector3d(0.3, -0.2, 0.1));
    X.rotate(Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 3).normalized()));
    X.scale(scale);
    return X;
}

// A script sweeping one tool (its "shape" JSON given) across the top of a unit sphere.
std::string sweepScript(const std::string& shape, double size, double voxelSize) {
    return R"({"sweepers": 1, "grid": {"voxel_size": )" + std::to_string(voxelSize) +
           R"(, "half_width": 3},
  "start": {"sphere": {"center": [0, 0, 0], "radius": 1}},
  "strokes": [{"type": "sweep", "tools": [{"shape": )" +
           shape + R"(, "size": )" + std::to_string(size) + R"(, "falloff": 0.3,
    "path": [{"t": [0, 0.95, 0]}, {"t": [0.1, 1.3, 0], "r": [0, 0, 1, 20]},
             {"t": [0.25, 1.45, 0.05], "r": [0, 0, 1, 40]}]}]}]})";
}

GridPtr sculpt(const StrokeScript& script) {
    Sculptor sculptor(makeStartGrid(script, "."));
    for (const Stroke& s : script.strokes)
        sculptor.applyStroke(s);
    return sculptor.gridPtr();
}

// RMS of a - b in voxels over the voxels of either grid next to its zero crossing.
double interfaceRms(const Grid& a, const Grid& b) {
    double sum = 0.0;
    std::size_t n = 0;
    for (const Grid* g : {&a, &b}) {
        const auto acc = g->getConstAccessor();
        const auto ca = a.getConstAccessor(), cb = b.getConstAccessor();
        for (auto leaf = g->tree().cbeginLeaf(); leaf; ++leaf)
            for (auto v = leaf->cbeginValueOn(); v; ++v) {
                if (!nextToCrossing(*leaf, v.pos(), acc)) continue;
                const double d = ca.getValue(v.getCoord()) - cb.getValue(v.getCoord());
                sum += d * d;
                ++n;
            }
    }
    return std::sqrt(sum / double(std::max<std::size_t>(n, 1))) / a.voxelSize()[0];
}

std::string scriptError(const std::string& text, const std::string& dir) {
    try {
        loadStrokeScript(text, "tool.json", dir);
    } catch (const ScriptError& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST(BakedTool, SphereDistanceMatchesTheBall) {
    // Moved, turned and scaled by 2: the sampled distance is the ball's to a small fraction
    // of the tool's (scaled) voxel within the band, and below it past the band, where it
    // still grows.
    const double scale = 2.0, reach = 0.2;
    const LevelSetTool tool = sphereTool(reach);
    const Eigen::Affine3d X = somePlacement(scale);
    const auto baked = tool.place(X);
    const auto ball = EllipsoidShape(kToolRadius).place(X);
    // The band is whole voxels: at least the reach asked, less than a voxel more.
    EXPECT_GE(baked->exactBelow(), scale * reach);
    EXPECT_LT(baked->exactBelow(), scale * (reach + kToolVoxel));
    Rng rng(7);
    double worst = 0.0;
    for (int i = 0; i < 4000; ++i) {
        const Eigen::Vector3d dir = rng.unit();
        const double r = rng.uniform(0.0, scale * (kToolRadius + reach));
        const Eigen::Vector3d p = X.translation() + r * dir;
        worst = std::max(worst, std::abs(baked->distance(p) - ball->distance(p)));
        EXPECT_EQ(baked->distanceBelow(p, 1e9), baked->distance(p));
    }
    std::printf("[ baked ] sphere tool: worst distance error %.4f tool voxels\n",
                worst / (scale * kToolVoxel));
    EXPECT_LT(worst, 0.05 * scale * kToolVoxel);
    double last = 0.0;
    for (double r = scale * (kToolRadius + reach); r < 3.0; r += 0.05) {
        const Eigen::Vector3d p = X.translation() + r * Eigen::Vector3d(0.6, 0.0, 0.8);
        const double d = baked->distance(p);
        EXPECT_LE(d, ball->distance(p) + 0.05 * scale * kToolVoxel);
        EXPECT_GE(d, last - 1e-12);
        last = d;
    }
    EXPECT_GT(last, 2.0 * scale * reach);
    // A placement that stretches the tool is refused.
    Eigen::Affine3d stretched = X;
    stretched.scale(Eigen::Vector3d(1.0, 1.5, 1.0));
    EXPECT_THROW(tool.place(stretched), std::invalid_argument);
}

TEST(BakedTool, DistanceIsWithinItsLipschitzBound) {
    const LevelSetTool tool = sphereTool(0.2);
    std::printf("[ baked ] sphere tool: Lipschitz bound %.4f\n", tool.lipschitz());
    EXPECT_GE(tool.lipschitz(), 1.0);
    EXPECT_LT(tool.lipschitz(), 1.2);
    Rng rng(11);
    double steepest = 0.0;
    for (int i = 0; i < 20000; ++i) {
        const Eigen::Vector3d a = rng.inBox(Eigen::Vector3d::Constant(-0.5),
                                            Eigen::Vector3d::Constant(0.5)),
                              b = a + 0.01 * rng.unit();
        steepest = std::max(steepest, std::abs(tool.localDistance(a) - tool.localDistance(b)) /
                                          (a - b).norm());
    }
    std::printf("[ baked ] steepest sampled slope %.4f\n", steepest);
    EXPECT_LE(steepest, tool.lipschitz() * (1.0 + 1e-6));
}

TEST(BakedTool, AFalloffPastTheBandIsRefused) {
    const auto tool = std::make_shared<LevelSetTool>(sphereTool(0.2));
    EXPECT_NO_THROW(PlacedTool(tool->place(somePlacement(1.0)), 0.2));
    EXPECT_THROW(PlacedTool(tool->place(somePlacement(1.0)), 0.25), std::invalid_argument);
    // Scaled by 2, the same band covers twice the falloff.
    EXPECT_NO_THROW(PlacedTool(tool->scaled(2.0)->place(somePlacement(1.0)), 0.4));
}

TEST(BakedTool, SphereFromAVdbSculptsLikeTheBall) {
    // The issue's test: a tool baked from a sphere of radius r gives what a ball of radius r
    // gives, to 0.1 voxel RMS. A unit sphere at voxel size 1/16, scaled to radius 0.5 and
    // 0.25: sampled as finely as the sculpt, and twice as finely.
    ScratchDir dir;
    const double h = 1.0 / 32;
    writeLevelSet(*makeSphere(Eigen::Vector3d::Zero(), 1.0, 1.0 / 16, 3.0), dir / "sphere.vdb");
    for (const double size : {0.5, 0.25}) {
        const StrokeScript ball =
            loadStrokeScript(sweepScript("\"ball\"", size, h), "ball.json", dir.path);
        const StrokeScript baked = loadStrokeScript(
            sweepScript(R"({"vdb": "sphere.vdb"})", size, h), "baked.json", dir.path);
        const GridPtr a = sculpt(ball), b = sculpt(baked);
        const double rms = interfaceRms(*a, *b);
        std::printf("[ baked ] size %.2f: baked sphere vs ball %.4f voxel RMS\n", size, rms);
        EXPECT_LT(rms, 0.1);
        // The sweep pulled the top up (the comparison is not between two untouched spheres).
        EXPECT_GT(activeWorldBox(*b).max.y(), 1.2);
        EXPECT_GT(checkBand(*b).unitGradientFraction(), 0.9);
    }
}

TEST(BakedTool, ClosedMeshSculptsLikeTheBall) {
    ScratchDir dir;
    const double h = 1.0 / 32;
    // A unit sphere meshed at 1/16 (6,000 triangles): its chords lie within 0.0005 of it.
    writeMesh(meshLevelSet(*makeSphere(Eigen::Vector3d::Zero(), 1.0, 1.0 / 16, 3.0)),
              dir / "sphere.ply");
    const StrokeScript ball =
        loadStrokeScript(sweepScript("\"ball\"", 0.3, h), "ball.json", dir.path);
    const StrokeScript baked =
        loadStrokeScript(sweepScript(R"({"mesh": "sphere.ply"})", 0.3, h), "baked.json", dir.path);
    // The mesh is sampled as finely as the sculpt at the tool's size, unless told otherwise;
    // the sampling is written back, so the script replays with the same tool.
    const auto& tool = std::get<SweepStroke>(baked.strokes[0]).tools[0];
    EXPECT_NEAR(tool.source.voxelSize, h / 0.3, 1e-12);
    const StrokeScript again = loadStrokeScript(formatStrokeScript(baked), "again", dir.path);
    EXPECT_EQ(formatStrokeScript(again), formatStrokeScript(baked));
    const double rms = interfaceRms(*sculpt(ball), *sculpt(baked));
    std::printf("[ baked ] mesh sphere vs ball %.4f voxel RMS\n", rms);
    EXPECT_LT(rms, 0.1);
}

TEST(BakedTool, BrokenToolsAreRefusedInOneLine) {
    ScratchDir dir;
    const double h = 1.0 / 32;
    // An open mesh: a closed one with a triangle taken out.
    TriangleMesh open = meshLevelSet(*makeSphere(Eigen::Vector3d::Zero(), 1.0, 0.1, 3.0));
    open.triangles.pop_back();
    writeMesh(open, dir / "open.ply");
    // An empty level set.
    initVdb();
    const GridPtr empty = Grid::create(float(3 * h));
    empty->setTransform(documentTransform(h));
    writeLevelSet(*empty, dir / "empty.vdb");
    // A level set the tool cannot be scaled through.
    writeLevelSet(*makeSphere(Eigen::Vector3d::Zero(), 1.0, 0.1, 3.0), dir / "sphere.vdb");

    const struct {
        std::string shape, path, expected;
    } cases[] = {
        {R"({"mesh": "open.ply"})", "", "not closed"},
        {R"({"vdb": "empty.vdb"})", "", "has no inside"},
        {R"({"vdb": "missing.vdb"})", "", "cannot open"},
        {R"({"vdb": "sphere.vdb", "voxel_size": 0.1})", "", "keeps its own voxel size"},
        {R"({"mesh": "open.ply", "grid": "a"})", "", "this tool is a mesh"},
        {R"({"vdb": "sphere.vdb", "mesh": "open.ply"})", "", "exactly one of vdb, mesh"},
    };
    for (const auto& c : cases) {
        const std::string why = scriptError(sweepScript(c.shape, 0.3, h), dir.path);
        EXPECT_NE(why.find(c.expected), std::string::npos) << c.shape << ": " << why;
        EXPECT_NE(why.find("/strokes/0/tools/0/shape"), std::string::npos) << why;
        EXPECT_EQ(why.find('\n'), std::string::npos) << why;
    }
    // A path that stretches a baked tool.
    const std::string stretched =
        R"({"sweepers": 1, "strokes": [{"type": "sweep", "tools": [{"shape": {"vdb": "sphere.vdb"},
        "size": 0.3, "falloff": 0.3, "path": [{"t": [0, 0, 0]}, {"t": [0, 1, 0], "s": [1, 2, 1]}]}]}]})";
    EXPECT_NE(scriptError(stretched, dir.path).find("/path/1/s: a baked tool can only be scaled"),
              std::string::npos)
        << scriptError(stretched, dir.path);
}
