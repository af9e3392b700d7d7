// SPDX-License-Identifier: Apache-2.0
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include <gtest/gtest.h>
#include <openvdb/tools/LevelSetMeasure.h>

#include "deform/sweep.h"
#include "grids.h"
#include "levelset/advect.h"
#include "levelset/create.h"
#include "levelset/measure.h"
#include "mesh/marching_cubes.h"
#include "mesh/mc_table.h"
#include "meshes.h"
#include "tools/ellipsoid.h"

using namespace sweepers;

TEST(MarchingCubes, TableClosesEveryConfiguration) {
    // In every configuration the triangles use a vertex on each crossing edge and on no
    // other edge, and each cycle centre they use belongs to a cycle of the case.
    for (int mask = 0; mask < 256; ++mask) {
        std::array<int, 12> uses{};
        for (const auto& tri : mc::triangles(mask))
            for (int e : tri) {
                if (e >= mc::kCentre) {
                    EXPECT_LT(e - mc::kCentre, int(mc::lookup(mask).cycles.size()));
                    continue;
                }
                ++uses[e];
            }
        for (int e = 0; e < 12; ++e) {
            const bool crossing =
                ((mask >> mc::kEdges[e].c0) & 1) != ((mask >> mc::kEdges[e].c1) & 1);
            EXPECT_EQ(uses[e] > 0, crossing) << "mask " << mask << " edge " << e;
        }
    }
    EXPECT_TRUE(mc::triangles(0).empty());
    EXPECT_TRUE(mc::triangles(255).empty());
    EXPECT_EQ(mc::triangles(1).size(), 1u);
}

namespace {

// A noise field of 12^3 voxels, positive on its border so that its surface is closed;
// values within `zeroBelow` of 0 are made exactly 0 (counted in `zeros`).
GridPtr noiseBox(std::mt19937& rng, float zeroBelow = 0.0f, std::size_t* zeros = nullptr) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    GridPtr g = Grid::create(3.0f);
    g->setTransform(documentTransform(0.1));
    auto acc = g->getAccessor();
    for (int x = 0; x < 12; ++x)
        for (int y = 0; y < 12; ++y)
            for (int z = 0; z < 12; ++z) {
                const bool border = x == 0 || y == 0 || z == 0 || x == 11 || y == 11 || z == 11;
                float v = border ? 1.0f : u(rng);
                if (!border && std::abs(v) < zeroBelow) {
                    v = 0.0f;
                    ++*zeros;
                }
                acc.setValueOn(openvdb::Coord(x, y, z), v);
            }
    return g;
}

} // namespace

TEST(MarchingCubes, RandomFieldsGiveWatertightOrientedMeshes) {
    // Noise fields exercise every ambiguous configuration; the mesh must still close.
    std::mt19937 rng(5);
    for (int trial = 0; trial < 5; ++trial) {
        const MeshTopology t = meshTopology(meshLevelSet(*noiseBox(rng)));
        EXPECT_GT(t.faces, 100u);
        EXPECT_TRUE(t.watertight()) << trial;
        EXPECT_TRUE(t.consistentlyOriented()) << trial;
    }
}

TEST(MarchingCubes, ExactZerosGiveNoCoincidentVerticesOrFlatTriangles) {
    // A value of exactly zero would put the crossing of every edge through that voxel on the
    // voxel itself: vertices at one point, triangles between them of no area.
    std::mt19937 rng(11);
    std::size_t zeros = 0;
    for (int trial = 0; trial < 5; ++trial) {
        // About one voxel in seven exactly zero.
        const TriangleMesh m = meshLevelSet(*noiseBox(rng, 0.15f, &zeros));
        std::set<std::array<float, 3>> seen;
        for (const Eigen::Vector3f& p : m.positions)
            EXPECT_TRUE(seen.insert({p.x(), p.y(), p.z()}).second) << "coincident vertices";
        std::size_t flat = 0;
        for (const Eigen::Vector3i& t : m.triangles) {
            const Eigen::Vector3f a = m.positions[t[0]], b = m.positions[t[1]],
                                  c = m.positions[t[2]];
            flat += (b - a).cross(c - a).norm() == 0.0f;
        }
        EXPECT_EQ(flat, 0u) << trial;
        const MeshTopology topo = meshTopology(m);
        EXPECT_TRUE(topo.watertight()) << trial;
        EXPECT_TRUE(topo.consistentlyOriented()) << trial;
    }
    EXPECT_GT(zeros, 500u);
}

TEST(MarchingCubes, SphereAndTorusMeshes) {
    const double h = 1.0 / 40;
    struct Shape {
        GridPtr grid;
        long chi;
        double volume;
    };
    const std::vector<Shape> shapes{
        {makeSphere({0.1, 0, 0}, 0.7, h, 3), 2, 4.0 / 3.0 * M_PI * std::pow(0.7, 3)},
        {test::gridFromSdf([](const Eigen::Vector3d& p) { return test::torusSdf(p, 0.6, 0.25); }, h,
                           3, openvdb::CoordBBox::createCube({-40, -40, -15}, 80)),
         0, 2.0 * M_PI * M_PI * 0.6 * 0.25 * 0.25}};
    for (const Shape& s : shapes) {
        const TriangleMesh m = meshLevelSet(*s.grid);
        const MeshTopology t = meshTopology(m);
        EXPECT_TRUE(t.watertight());
        EXPECT_TRUE(t.consistentlyOriented());
        EXPECT_EQ(t.eulerCharacteristic(), s.chi);
        EXPECT_EQ(topologicalEulerCharacteristic(*s.grid), s.chi);
        const double grid = openvdb::tools::levelSetVolume(*s.grid);
        // The volume alone (what `apply` reports) is the full measure's, and the shape's.
        EXPECT_EQ(levelSetVolume(*s.grid), measureLevelSet(*s.grid).volume);
        EXPECT_NEAR(levelSetVolume(*s.grid), s.volume, 0.005 * s.volume);
        EXPECT_NEAR(enclosedVolume(m), grid, 0.01 * grid); // positive: normals face out
        // Vertex normals (SDF gradient) agree with the triangles' orientation.
        std::size_t agree = 0;
        for (const Eigen::Vector3i& tri : m.triangles) {
            const Eigen::Vector3f n = (m.positions[tri[1]] - m.positions[tri[0]])
                                          .cross(m.positions[tri[2]] - m.positions[tri[0]]);
            agree += n.dot(m.normals[tri[0]] + m.normals[tri[1]] + m.normals[tri[2]]) > 0;
        }
        EXPECT_GT(double(agree) / m.triangles.size(), 0.999);
    }
}

// Each vertex normal (the gradients at its edge's two corners, blended) is the sphere's own
// normal there, to within the grid's central differences.
TEST(MarchingCubes, VertexNormalsAreTheSurfaceNormals) {
    const Eigen::Vector3f centre(0.1f, 0.0f, 0.0f);
    const TriangleMesh m = meshLevelSet(*makeSphere(centre.cast<double>(), 0.7, 1.0 / 40, 3));
    ASSERT_FALSE(m.normals.empty());
    float worst = 1.0f;
    for (std::size_t i = 0; i < m.positions.size(); ++i)
        worst = std::min(worst, m.normals[i].dot((m.positions[i] - centre).normalized()));
    std::printf("[ normals ] %zu vertices, least cosine to the sphere's normal %.6f\n",
                m.positions.size(), double(worst));
    EXPECT_GT(worst, 0.9995f);
}

// A pull and the push back, each re-meshed incrementally (into the chunks' kept storage):
// the mesher then holds chunk for chunk what a rebuild holds (none missing, none left
// without a triangle), and its volume is the rebuild's to the bit.
TEST(MarchingCubes, IncrementalUpdateMatchesRebuild) {
    const double h = 1.0 / 32;
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
    SurfaceMesher incremental;
    incremental.rebuild(*g);
    Placement a, b;
    a.t = {0, 0.9, 0};
    b.t = {0.1, 1.3, 0};
    const auto ball = std::make_shared<EllipsoidShape>(0.3);
    // The mesher updated from what each segment reports it changed (as a Sculptor updates it)
    // holds the same chunks too.
    SurfaceMesher fromChanges;
    fromChanges.rebuild(*g);
    for (const Sweep& sweep : {Sweep{{{ball, 0.3, {a, b}}}}, Sweep{{{ball, 0.3, {b, a}}}}}) {
        std::vector<openvdb::CoordBBox> changed;
        const AdvectStats stats = advectSegment(*g, SweepSegment(sweep, 0), {}, &changed);
        const std::size_t remeshed = incremental.update(*g, stats.touched);
        EXPECT_EQ(fromChanges.update(*g, changed), remeshed);
        SurfaceMesher full;
        full.rebuild(*g);
        EXPECT_LT(remeshed, g->tree().leafCount() / 2); // only the stroke's neighbourhood
        EXPECT_EQ(sweepers::test::chunkDifference(incremental, full), "");
        EXPECT_EQ(sweepers::test::chunkDifference(fromChanges, full), "");
        const TriangleMesh x = incremental.weld(), y = full.weld();
        ASSERT_EQ(x.triangles.size(), y.triangles.size());
        ASSERT_EQ(x.positions.size(), y.positions.size());
        EXPECT_NEAR(enclosedVolume(x), enclosedVolume(y), 1e-9);
        // The per-chunk volume (used for per-stroke drift) needs no weld.
        EXPECT_NEAR(incremental.enclosedVolume(), enclosedVolume(y), 1e-9);
        EXPECT_EQ(incremental.enclosedVolume(), full.enclosedVolume());
        EXPECT_TRUE(meshTopology(x).watertight());
        for (const auto& [origin, chunk] : incremental.chunks())
            EXPECT_FALSE(chunk.triangles.empty()) << origin;
    }
}

TEST(MarchingCubes, ALeafIsMeshedAgainExactlyWhenWhatItReadsChanged) {
    // One value at a time is moved (its sign kept) around a leaf with surface: inside it, on
    // the layers past its faces that its cubes read, and two past its upper faces and one
    // before its lower ones, which its normals read. The update of that voxel alone must
    // give the rebuilt mesh, normals included; updating where nothing changed meshes
    // nothing.
    const double h = 1.0 / 16;
    GridPtr g = makeSphere(Eigen::Vector3d::Zero(), 1.0, h, 3);
    SurfaceMesher incremental, fromChanges;
    incremental.rebuild(*g);
    fromChanges.rebuild(*g);
    const auto changedWithFar = [](const openvdb::Coord& c) {
        const openvdb::Coord far = c.offsetBy(-4000, -4000, -4000);
        return std::vector{openvdb::CoordBBox(c, c), openvdb::CoordBBox(far, far)};
    };
    const openvdb::Coord origin = incremental.chunks().begin()->first;
    const openvdb::CoordBBox around(origin.offsetBy(-2), origin.offsetBy(LeafNode::DIM + 2));
    EXPECT_EQ(incremental.update(*g, around), 0u);
    auto acc = g->getAccessor();
    std::size_t moved = 0;
    for (const int x : {-1, 0, 4, 7, 8, 9})
        for (const int y : {-1, 0, 4, 7, 8, 9})
            for (const int z : {-1, 0, 4, 7, 8, 9}) {
                const openvdb::Coord c = origin.offsetBy(x, y, z);
                const float was = acc.getValue(c);
                if (!acc.isValueOn(c)) continue; // the band's values only
                acc.setValue(c, 0.7f * was);
                // Told of the voxel as a box to look around, and as what changed (with a box
                // far away, where nothing is: the readers' origins are then sorted, not marked
                // in an array over the boxes' extent).
                incremental.update(*g, openvdb::CoordBBox(c, c));
                fromChanges.update(*g, changedWithFar(c));
                SurfaceMesher full;
                full.rebuild(*g);
                const auto want = full.chunks().find(origin);
                ASSERT_NE(want, full.chunks().end());
                for (const SurfaceMesher* m : {&incremental, &fromChanges}) {
                    const auto it = m->chunks().find(origin);
                    ASSERT_NE(it, m->chunks().end());
                    EXPECT_EQ(it->second.positions, want->second.positions) << c;
                    EXPECT_EQ(it->second.normals, want->second.normals) << c;
                    EXPECT_EQ(it->second.triangles, want->second.triangles) << c;
                }
                acc.setValue(c, was);
                incremental.update(*g, openvdb::CoordBBox(c, c));
                fromChanges.update(*g, changedWithFar(c));
                ++moved;
            }
    EXPECT_GT(moved, 40u);
}
