// SPDX-License-Identifier: Apache-2.0
// The data scripts end to end on real grids: the heavy engine tests, labelled `slow`. Each
// runs at the voxel size it names, or at twice it (eight times fewer voxels) when
// SWEEPERS_COARSE_TESTS is set, as the sanitizer builds do.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "coarse.h"
#include "grids.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "levelset/band.h"
#include "levelset/measure.h"
#include "levelset/peer_check.h"
#include "mesh/marching_cubes.h"
#include "meshes.h"
#include "replay.h"

using namespace sweepers;

using sweepers::test::coarse;

namespace {

std::string dataPath(const std::string& name) {
    return std::string(SWEEPERS_DATA_DIR) + "/" + name + ".json";
}

// The voxel size a test runs at: `fine`, or twice it in the coarse variant.
double voxelSize(double fine) {
    return coarse() ? 2.0 * fine : fine;
}

Placement at(const Eigen::Vector3d& t) {
    Placement p;
    p.t = t;
    return p;
}

} // namespace

// (Outside the anonymous namespace: the tests GoogleTest derives from it are not in it.)
class DataScript : public ::testing::TestWithParam<const char*> {};

// The share of interface voxels whose |grad phi| lies in [0.9, 1.1]. A pinch or a strangle
// tears a hole whose rim is a crease of the exact shape (the image of the point where the
// surface met itself), where central differences straddle the crease. The crease's share of
// the interface doubles with the voxel size: at the scripts' 1/64 they keep 95%, at the
// coarse variant's 1/32 they keep 84.9% (two_handles) to 94.9%.
double minimumUnitGradientFraction(const std::string& name) {
    const bool tears = name == "pinch_torus" || name == "strangle_torus" || name == "two_handles" ||
                       name == "severed_horn";
    return tears && coarse() ? 0.8 : 0.95;
}

// The topology after each stroke of the scripts that change it on purpose: Euler
// characteristic (counted on the voxels and on the welded mesh) and components.
const std::map<std::string, std::vector<std::pair<int, std::size_t>>> kTopology = {
    {"pinch_torus", {{0, 1}}},            // a sphere pinched into a torus
    {"two_handles", {{0, 1}, {-2, 1}}},   // two pinches: genus 2
    {"strangle_torus", {{0, 1}, {2, 1}}}, // a torus whose tube is cut: a sphere again
    {"severed_horn", {{2, 1}, {4, 2}}},   // a pulled horn, then cut off
};

// What OpenVDB's checkLevelSet (all nine tests) refuses in a script's result that the info
// report does not put on a feature the grid does not resolve (thin parts, gaps, creases:
// levelset/peer_check.h): at the scripts' own voxel sizes, nothing; at twice them, where the
// lips of the torn scripts' mouths are about a voxel across, at most as many as measured when
// this test was written (none is the goal).
const std::map<std::string, std::size_t> kUnexplainedAtTwiceTheVoxelSize = {
    {"strangle_torus", 12},
    {"two_handles", 32},
};

TEST_P(DataScript, KeepsAValidNarrowBandAfterEveryStroke) {
    const std::string name = GetParam();
    const StrokeScript script = readStrokeScript(dataPath(name));
    const double h = voxelSize(script.grid.voxelSize);
    applyScript(script, SWEEPERS_DATA_DIR, h, [&](std::size_t stroke, const Grid& g) {
        const BandReport r = checkBand(g);
        EXPECT_EQ(r.vdbCheck, "") << name << " stroke " << stroke;
        EXPECT_GE(r.unitGradientFraction(), minimumUnitGradientFraction(name))
            << name << " stroke " << stroke;
        EXPECT_EQ(r.beyondBand, 0u) << name << " stroke " << stroke;
        EXPECT_EQ(r.bandHoles, 0u) << name << " stroke " << stroke;
        if (const auto it = kTopology.find(name); it != kTopology.end()) {
            ASSERT_LT(stroke, it->second.size());
            const auto [euler, components] = it->second[stroke];
            const MeshTopology t = meshTopology(meshLevelSet(g));
            EXPECT_EQ(topologicalEulerCharacteristic(g), euler) << name << " stroke " << stroke;
            EXPECT_EQ(t.eulerCharacteristic(), euler) << name << " stroke " << stroke;
            EXPECT_TRUE(t.watertight()) << name << " stroke " << stroke;
            EXPECT_EQ(measureLevelSet(g).components, components) << name << " stroke " << stroke;
        }
        std::printf("[ band ] %s at 1/%g, stroke %zu: %zu active, |grad| in [0.9, 1.1] on "
                    "%.2f%% of %zu interface voxels, %zu holes\n",
                    name.c_str(), 1.0 / h, stroke, r.activeVoxels, 100 * r.unitGradientFraction(),
                    r.nearInterface, r.bandHoles);
    });
}

// Each script's result, at its own voxel size and at twice it, as written before the engine's
// rooms were last moved (test::gridDigest): a change meant to move code only must give every
// grid to the bit. A change meant to change results updates the table, and says so.
const std::map<std::string, std::string> kResultDigests = {
    {"drag at 1/64", "b186f6f04745a530"},
    {"drag at 1/32", "392d1f713a6696fb"},
    {"finger at 1/64", "8ff629e6d6057e83"},
    {"finger at 1/32", "38604ad556d45864"},
    {"horn at 1/64", "632cf5636989cdf8"},
    {"horn at 1/32", "03781a44e0724c1e"},
    {"mirrored_ears at 1/64", "422930ae3b08efbf"},
    {"mirrored_ears at 1/32", "484d9117bc37b882"},
    {"pinch at 1/64", "8392f81bdf35141c"},
    {"pinch at 1/32", "d15f0c0aac39ea58"},
    {"pinch_torus at 1/64", "c2da5573188b5cfe"},
    {"pinch_torus at 1/32", "6d16c34f5d26b2ad"},
    {"pull at 1/50", "f20ce25383c0ff39"},
    {"pull at 1/25", "e61d56258a257ee1"},
    {"severed_horn at 1/64", "094f409eade4aff9"},
    {"severed_horn at 1/32", "626b8622ddbea67b"},
    {"starfish_swirls at 1/64", "e8a61253515e130a"},
    {"starfish_swirls at 1/32", "256178b68c628237"},
    {"strangle_torus at 1/64", "b8c8711f97a48909"},
    {"strangle_torus at 1/32", "645178b3b6625ab4"},
    {"twisted_limb at 1/64", "4c06a15c3d8e2ae8"},
    {"twisted_limb at 1/32", "0c8b5988b66d814f"},
    {"two_handles at 1/64", "4862f3cd7c19da7b"},
    {"two_handles at 1/32", "2031795026bb0635"},
};

// OpenVDB's checkLevelSet on each script's result, at its own voxel size and at twice it
// (whichever variant runs: the check costs little).
TEST_P(DataScript, OpenVdbsCheckRefusesOnlyWhatTheReportExplains) {
    const std::string name = GetParam();
    const StrokeScript script = readStrokeScript(dataPath(name));
    for (const double scale : {1.0, 2.0}) {
        const double h = scale * script.grid.voxelSize;
        const GridPtr g = applyScript(script, SWEEPERS_DATA_DIR, h);
        const std::string digest = sweepers::test::gridDigest(*g);
        const std::string key = name + " at 1/" + std::to_string(int(std::lround(1.0 / h)));
        std::printf("[ digest ] %s: %s\n", key.c_str(), digest.c_str());
        const auto expected = kResultDigests.find(key);
        EXPECT_TRUE(expected != kResultDigests.end() && expected->second == digest)
            << key << " gave " << digest;
        const PeerCheck peer = peerCheck(*g);
        const std::size_t unexplained = peer.eikonal - peer.eikonalThin;
        std::printf("[ peer ] %s at 1/%g: checkLevelSet refuses %zu of %zu voxels next to "
                    "the surface, %zu of them on features the grid does not resolve\n",
                    name.c_str(), 1.0 / h, peer.eikonal, peer.surfaceVoxels, peer.eikonalThin);
        if (peer.eikonal == 0)
            EXPECT_EQ(peer.message, "") << name;
        else
            EXPECT_NE(peer.message.find("outside the range of NormGrad"), std::string::npos)
                << name << ": " << peer.message;
        const auto known = kUnexplainedAtTwiceTheVoxelSize.find(name);
        const std::size_t most =
            scale == 1.0 || known == kUnexplainedAtTwiceTheVoxelSize.end() ? 0 : known->second;
        EXPECT_LE(unexplained, most) << name << " at 1/" << 1.0 / h;
    }
}

// The mesh a Sculptor keeps up to date, segment by segment from what each segment reports it
// changed, is after every stroke the mesh of the whole grid: chunk for chunk, normals included.
TEST_P(DataScript, TheMeshKeptUpToDateIsTheMeshOfTheGrid) {
    const std::string name = GetParam();
    const StrokeScript script = readStrokeScript(dataPath(name));
    Sculptor sculptor(makeStartGrid(script, SWEEPERS_DATA_DIR, voxelSize(script.grid.voxelSize)));
    sculptor.startMeshing();
    applyStrokes(sculptor, script.strokes, {}, [&](std::size_t stroke) {
        SurfaceMesher whole;
        whole.rebuild(sculptor.grid());
        ASSERT_EQ(sweepers::test::chunkDifference(sculptor.mesher(), whole), "")
            << name << " stroke " << stroke;
        std::printf("[ mesh ] %s, stroke %zu: the %zu chunks kept are the grid's\n", name.c_str(),
                    stroke, whole.chunks().size());
    });
}

INSTANTIATE_TEST_SUITE_P(Data, DataScript,
                         ::testing::Values("drag", "finger", "horn", "mirrored_ears", "pinch",
                                           "pinch_torus", "pull", "severed_horn", "starfish_swirls",
                                           "strangle_torus", "twisted_limb", "two_handles"),
                         [](const auto& info) { return std::string(info.param); });

TEST(DataScripts, EveryScriptInDataIsCovered) {
    // A script added to data/ must be added to the list above.
    std::size_t scripts = 0;
    for (const auto& entry : std::filesystem::directory_iterator(SWEEPERS_DATA_DIR))
        scripts += entry.path().extension() == ".json";
    EXPECT_EQ(scripts, 12u);
}

TEST(Advect, PinchOpensAHole) {
    // At the script's voxel size only: the squeeze is one voxel thin there on purpose. The
    // hole is the grid's, not the deformation's (a sweep cannot tear space): the exact shape
    // stays a sphere, and from 1/256 on the grid holds the membrane (sweepers-cli study).
    const StrokeScript script = readStrokeScript(dataPath("pinch"));
    Sculptor sculptor(makeStartGrid(script, SWEEPERS_DATA_DIR));
    const GridPtr g = sculptor.gridPtr();
    EXPECT_EQ(topologicalEulerCharacteristic(*g), 2);
    EXPECT_EQ(meshTopology(meshLevelSet(*g)).eulerCharacteristic(), 2);
    applyStrokes(sculptor, script.strokes);
    const TriangleMesh mesh = meshLevelSet(*g);
    const MeshTopology t = meshTopology(mesh);
    EXPECT_EQ(topologicalEulerCharacteristic(*g), 0);
    EXPECT_EQ(t.eulerCharacteristic(), 0);
    EXPECT_TRUE(t.watertight());
    EXPECT_TRUE(t.consistentlyOriented());
}

TEST(Advect, APinchLeavesTheWholeBand) {
    // At 1/128 in both variants: sampling reaches two voxels around the images of the
    // surface, and where the band's outer voxels lie in leaves no sample made, those leaves
    // are made afterwards; when they were not, the band missed 108 of its voxels here (at
    // 1/64 none).
    StrokeScript script = readStrokeScript(dataPath("two_handles"));
    script.strokes.resize(1);
    const GridPtr g = applyScript(script, SWEEPERS_DATA_DIR, 1.0 / 128);
    const BandReport r = checkBand(*g);
    std::printf("[ band ] the first pinch of two_handles at 1/128: %zu active, %zu band holes\n",
                r.activeVoxels, r.bandHoles);
    EXPECT_EQ(r.bandHoles, 0u);
    EXPECT_EQ(r.beyondBand, 0u);
}

TEST(Advect, SwirlsKeepVolumeWhereSweepsDoNot) {
    // The 50-stroke swirl script against sweeps of a ball along the same moves.
    const StrokeScript swirls = readStrokeScript(dataPath("starfish_swirls"));
    StrokeScript sweeps = swirls;
    sweeps.strokes.clear();
    for (const Stroke& s : swirls.strokes) {
        const auto& sw = std::get<SwirlStroke>(s);
        ToolSpec tool;
        tool.shape = ToolShapeKind::Ball;
        tool.size = Eigen::Vector3d::Constant(0.1);
        tool.falloff = sw.radius;
        tool.path = {at(sw.at), at(sw.at + sw.move)};
        SweepStroke stroke;
        stroke.tools.push_back(tool);
        sweeps.strokes.emplace_back(stroke);
    }
    ASSERT_EQ(swirls.strokes.size(), 50u);
    // A unit sphere 256 voxels across (64 in the coarse variant).
    const double h = coarse() ? 1.0 / 32 : 1.0 / 128;
    Sculptor a(makeStartGrid(swirls, SWEEPERS_DATA_DIR, h)), b(a.grid().deepCopy());
    const double v0 = levelSetVolume(a.grid());
    applyStrokes(a, swirls.strokes);
    applyStrokes(b, sweeps.strokes);
    const double swirlDrift = (levelSetVolume(a.grid()) - v0) / v0;
    const double sweepDrift = (levelSetVolume(b.grid()) - v0) / v0;
    std::printf("[ volume ] 50 strokes at voxel size %g: swirls %+.3f%%, sweeps %+.3f%%\n", h,
                100 * swirlDrift, 100 * sweepDrift);
    EXPECT_LT(std::abs(swirlDrift), 0.01);
    EXPECT_GT(std::abs(sweepDrift), 10 * std::abs(swirlDrift));
    EXPECT_EQ(topologicalEulerCharacteristic(a.grid()), 2);
}
