// SPDX-License-Identifier: Apache-2.0
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "io/mesh_file.h"
#include "io/vdb_file.h"
#include "levelset/band.h"
#include "levelset/create.h"
#include "mesh/marching_cubes.h"
#include "scratch_dir.h"

using namespace sweepers;
namespace fs = std::filesystem;

namespace {

using test::ScratchDir;

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

void writeGrids(const std::string& path, openvdb::GridPtrVec grids) {
    openvdb::io::File file(path);
    file.write(grids);
    file.close();
}

} // namespace

TEST(VdbFile, RoundTripIsBitExact) {
    ScratchDir dir;
    GridPtr g = makeSphere({0.1, 0.2, 0.3}, 0.5, 1.0 / 50, 3);
    writeLevelSet(*g, dir / "s.vdb");
    EXPECT_EQ(dir.count(), 1u); // no temporary left behind
    GridPtr back = readLevelSet(dir / "s.vdb");
    EXPECT_EQ(back->getName(), "surface");
    EXPECT_EQ(back->getGridClass(), openvdb::GRID_LEVEL_SET);
    // OpenVDB recomputes the map's derived terms on reading: equal to a few ulps.
    EXPECT_DOUBLE_EQ(back->voxelSize()[0], g->voxelSize()[0]);
    EXPECT_EQ(back->background(), g->background());
    EXPECT_EQ(back->activeVoxelCount(), g->activeVoxelCount());
    EXPECT_TRUE(back->tree().hasSameTopology(g->tree()));
    std::size_t differ = 0;
    auto acc = g->getConstAccessor();
    for (auto it = back->cbeginValueAll(); it; ++it)
        differ += acc.getValue(it.getCoord()) != *it;
    EXPECT_EQ(differ, 0u);
    EXPECT_EQ(back->metaValue<std::string>("creator"), "sweepers " SWEEPERS_VERSION);
    EXPECT_FLOAT_EQ(back->metaValue<float>("half_width"), 3.0f);
}

TEST(VdbFile, ReadsTheFirstLevelSetAndRefusesOtherGrids) {
    ScratchDir dir;
    initVdb();
    openvdb::FloatGrid::Ptr fog = openvdb::FloatGrid::create(0.0f);
    fog->setName("density");
    fog->setGridClass(openvdb::GRID_FOG_VOLUME);
    fog->tree().setValue(openvdb::Coord(1, 2, 3), 0.5f);
    openvdb::Vec3fGrid::Ptr vel = openvdb::Vec3fGrid::create();
    vel->setName("vel");
    openvdb::FloatGrid::Ptr ls =
        openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, {0, 0, 0}, 0.1f, 3.0f);
    ls->setName("my_shape");

    writeGrids(dir / "mixed.vdb", {fog, vel, ls});
    GridPtr g = readLevelSet(dir / "mixed.vdb");
    EXPECT_EQ(g->activeVoxelCount(), ls->activeVoxelCount());

    writeGrids(dir / "fog.vdb", {fog});
    EXPECT_NE(errorOf([&] {
                  readLevelSet(dir / "fog.vdb");
              }).find("no float level set in the file (it holds 'density' (float, fog volume))"),
              std::string::npos);
    writeGrids(dir / "vec.vdb", {vel});
    EXPECT_NE(errorOf([&] { readLevelSet(dir / "vec.vdb"); }).find("'vel' (vec3s"),
              std::string::npos);

    std::ofstream(dir / "junk.vdb") << "this is not a vdb file";
    EXPECT_NE(errorOf([&] { readLevelSet(dir / "junk.vdb"); }).find("not a readable VDB file"),
              std::string::npos);
    EXPECT_NE(errorOf([&] { readLevelSet(dir / "none.vdb"); }).find("cannot open"),
              std::string::npos);

    openvdb::FloatGrid::Ptr thin =
        openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, {0, 0, 0}, 0.1f, 1.5f);
    writeGrids(dir / "thin.vdb", {thin});
    EXPECT_NE(errorOf([&] { readLevelSet(dir / "thin.vdb"); }).find("needs at least 2"),
              std::string::npos);
}

TEST(VdbFile, HalfPrecisionRoundsWithinItsBoundAndIsNotPassedOn) {
    ScratchDir dir;
    const double h = 1.0 / 50;
    GridPtr g = makeSphere({0.1, 0.2, 0.3}, 0.5, h, 3);
    LevelSetWriteOptions half;
    half.half = true;
    writeLevelSet(*g, dir / "half.vdb", half);
    writeLevelSet(*g, dir / "full.vdb");
    EXPECT_LT(fs::file_size(dir / "half.vdb"), fs::file_size(dir / "full.vdb"));
    GridPtr back = readLevelSet(dir / "half.vdb");
    EXPECT_TRUE(back->saveFloatAsHalf());
    // 3 x 1/50 is no 16-bit float: the background is the next one up, never narrower than the
    // band, and every inactive value is it, as OpenVDB's checks want.
    EXPECT_GT(back->background(), g->background());
    EXPECT_LT(back->background(), g->background() * (1 + 1.0 / 1024));
    std::size_t offBackground = 0;
    for (auto it = back->cbeginValueOff(); it; ++it)
        offBackground += std::abs(*it) != back->background();
    EXPECT_EQ(offBackground, 0u);
    EXPECT_TRUE(back->tree().hasSameTopology(g->tree()));
    // Each value within 1/2048 of itself, or of a voxel near the surface; rounded somewhere.
    double worst = 0.0;
    auto acc = g->getConstAccessor();
    for (auto it = back->cbeginValueOn(); it; ++it) {
        const double exact = acc.getValue(it.getCoord());
        worst = std::max(worst, std::abs(*it - exact) / std::max(std::abs(exact), h));
    }
    EXPECT_GT(worst, 0.0);
    EXPECT_LE(worst, 1.0 / 2048);
    // A grid read from a half file carries the flag; written without asking, it is exact.
    writeLevelSet(*back, dir / "again.vdb");
    GridPtr again = readLevelSet(dir / "again.vdb");
    EXPECT_FALSE(again->saveFloatAsHalf());
    EXPECT_GT(fs::file_size(dir / "again.vdb"), fs::file_size(dir / "half.vdb"));
    std::size_t differ = 0;
    auto backAcc = back->getConstAccessor();
    for (auto it = again->cbeginValueAll(); it; ++it)
        differ += backAcc.getValue(it.getCoord()) != *it;
    EXPECT_EQ(differ, 0u);
    // Voxel sizes where 16-bit floats lose their precision or overflow: refused, nothing left.
    EXPECT_EQ(halfPrecisionProblem(h, 3.0), "");
    EXPECT_NE(halfPrecisionProblem(5e-5, 3.0).find("under 6.1e-05"), std::string::npos);
    EXPECT_NE(halfPrecisionProblem(30000.0, 3.0).find("end at 65504"), std::string::npos);
    GridPtr speck = makeSphere({0, 0, 0}, 1e-3, 5e-5, 3);
    EXPECT_NE(errorOf([&] { writeLevelSet(*speck, dir / "speck.vdb", half); }).find("6.1e-05"),
              std::string::npos);
    EXPECT_FALSE(fs::exists(dir / "speck.vdb"));
}

TEST(VdbFile, UnwritableTargetFailsCleanly) {
    ScratchDir dir;
    GridPtr g = makeSphere({0, 0, 0}, 0.5, 0.05, 3);
    EXPECT_THROW(writeLevelSet(*g, dir / "no/such/dir/x.vdb"), std::runtime_error);
    EXPECT_EQ(dir.count(), 0u);
}

TEST(MeshFile, ExportsReadBackWatertight) {
    ScratchDir dir;
    GridPtr g = makeSphere({0, 0, 0}, 0.6, 1.0 / 30, 3);
    const TriangleMesh mesh = meshLevelSet(*g);
    for (const char* name : {"s.obj", "s.ply", "s.stl"}) {
        writeMesh(mesh, dir / name);
        const TriangleMesh back = readMesh(dir / name);
        EXPECT_EQ(back.triangles.size(), mesh.triangles.size()) << name;
        const MeshTopology t = meshTopology(back);
        EXPECT_TRUE(t.watertight()) << name;
        EXPECT_TRUE(t.consistentlyOriented()) << name;
        EXPECT_EQ(t.eulerCharacteristic(), 2) << name;
        EXPECT_NEAR(enclosedVolume(back), enclosedVolume(mesh), 1e-4 * enclosedVolume(mesh))
            << name;
    }
    EXPECT_EQ(dir.count(), 3u);
    EXPECT_THROW(writeMesh(mesh, dir / "s.xyz"), FileError);
}

TEST(MeshFile, MeshStartBecomesALevelSet) {
    ScratchDir dir;
    GridPtr g = makeSphere({0, 0, 0}, 0.6, 1.0 / 30, 3);
    writeMesh(meshLevelSet(*g), dir / "s.obj");
    const TriangleMesh m = readMesh(dir / "s.obj");
    GridPtr back = levelSetFromMesh(m.positions, m.triangles, 1.0 / 30, 3);
    EXPECT_EQ(back->getGridClass(), openvdb::GRID_LEVEL_SET);
    EXPECT_EQ(checkBand(*back).vdbCheck, "");
    EXPECT_NEAR(openvdb::tools::levelSetVolume(*back), openvdb::tools::levelSetVolume(*g),
                0.01 * openvdb::tools::levelSetVolume(*g));
}

// A box of twelve triangles (the random histories' mesh start): OpenVDB's band left 258
// voxels up to a voxel inside its edge without a neighbour, near the faces' diagonals.
TEST(MeshFile, MeshStartHoldsItsWholeBand) {
    std::vector<Eigen::Vector3f> corners;
    for (int k = 0; k < 8; ++k)
        corners.emplace_back(k & 1 ? 0.8f : -0.8f, k & 2 ? 0.8f : -0.8f, k & 4 ? 0.8f : -0.8f);
    const std::vector<Eigen::Vector3i> faces = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                                {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                                {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    const GridPtr box = levelSetFromMesh(corners, faces, 1.0 / 77, 3);
    const BandReport band = checkBand(*box);
    EXPECT_EQ(band.bandHoles, 0u);
    EXPECT_EQ(band.beyondBand, 0u);
    EXPECT_NEAR(openvdb::tools::levelSetVolume(*box), 1.6 * 1.6 * 1.6, 0.002);
}
