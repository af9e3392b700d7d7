#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <openvdb/tools/LevelSetMeasure.h>

#include "grids.h"
#include "levelset/band.h"
#include "levelset/fast_marching.h"

using namespace sweepers;
using sweepers::test::gridFromSdf;

namespace {

struct Errors {
    double maxNear = 0.0, rmsNear = 0.0; // voxels adjacent to the zero crossing
    double maxBand = 0.0;                // every active voxel
    std::size_t signFlips = 0, near = 0;
};

Errors compare(const Grid& g, const std::function<double(const Eigen::Vector3d&)>& sdf) {
    Errors e;
    const double h = g.voxelSize()[0];
    auto acc = g.getConstAccessor();
    double sum2 = 0.0;
    for (auto leaf = g.tree().cbeginLeaf(); leaf; ++leaf)
        for (auto it = leaf->cbeginValueOn(); it; ++it) {
            const double exact = sdf(toEigen(g.indexToWorld(it.getCoord())));
            const double err = std::abs(*it - exact) / h;
            if ((*it < 0) != (exact < 0)) ++e.signFlips;
            e.maxBand = std::max(e.maxBand, err);
            if (!nextToCrossing(*leaf, it.pos(), acc)) continue;
            ++e.near;
            e.maxNear = std::max(e.maxNear, err);
            sum2 += err * err;
        }
    e.rmsNear = std::sqrt(sum2 / std::max<std::size_t>(e.near, 1));
    return e;
}

// Scales the values by a smooth positive factor between 1.2 and 2, as a deformation
// would leave them: the surface (the zero set) stays where it is, the distances are wrong
// everywhere else.
void distort(Grid& g) {
    for (auto it = g.beginValueOn(); it; ++it) {
        const Eigen::Vector3d p = toEigen(g.indexToWorld(it.getCoord()));
        const double wobble = 1.6 + 0.4 * std::sin(4.0 * p.x() + 3.0 * p.y() - 2.0 * p.z());
        it.setValue(float(*it * wobble));
    }
}

void renormalizes(const char* name, GridPtr g,
                  const std::function<double(const Eigen::Vector3d&)>& sdf) {
    distort(*g);
    const Errors before = compare(*g, sdf);
    GridPtr first = g->deepCopy();
    renormalizeAll(*first, FmmOrder::First);
    renormalizeAll(*g, FmmOrder::Second);
    const Errors e1 = compare(*first, sdf), e2 = compare(*g, sdf);
    std::printf("[ fmm ] %-6s distorted: max band error %.3f voxels; first order: near max %.4f "
                "rms %.4f band max %.3f; second order: near max %.4f rms %.4f band max %.3f\n",
                name, before.maxBand, e1.maxNear, e1.rmsNear, e1.maxBand, e2.maxNear, e2.rmsNear,
                e2.maxBand);
    EXPECT_GT(before.maxBand, 1.0); // the distortion was real
    EXPECT_LT(e2.maxNear, 0.05) << name;
    EXPECT_EQ(e2.signFlips, 0u) << name; // the zero crossing did not move across a voxel
    EXPECT_LT(e2.maxBand, 0.25) << name;
    const BandReport band = checkBand(*g);
    EXPECT_EQ(band.beyondBand, 0u);
    EXPECT_EQ(band.vdbCheck, "");
    EXPECT_GE(band.unitGradientFraction(), 0.99);
}

} // namespace

TEST(FastMarching, RenormalizesADistortedSphere) {
    const double h = 1.0 / 48;
    auto sdf = [](const Eigen::Vector3d& p) { return p.norm() - 0.8; };
    renormalizes("sphere",
                 gridFromSdf(sdf, h, 3, openvdb::CoordBBox::createCube({-45, -45, -45}, 90)), sdf);
}

TEST(FastMarching, RenormalizesADistortedTorus) {
    const double h = 1.0 / 48;
    auto sdf = [](const Eigen::Vector3d& p) { return test::torusSdf(p, 0.6, 0.25); };
    renormalizes("torus",
                 gridFromSdf(sdf, h, 3, openvdb::CoordBBox::createCube({-45, -45, -20}, 90)), sdf);
}

TEST(FastMarching, ThinRodSurvivesManyRenormalizations) {
    // A rod two voxels thick along a diagonal of the lattice.
    const double h = 1.0 / 32;
    const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 0.5).normalized();
    auto rod = [&](const Eigen::Vector3d& p) {
        const double along = p.dot(axis);
        const double radial = (p - along * axis).norm() - h; // radius one voxel
        const double cap = std::abs(along) - 0.5;
        return std::max(radial, cap);
    };
    GridPtr g = gridFromSdf(rod, h, 3, openvdb::CoordBBox::createCube({-24, -24, -24}, 48));
    const double v0 = openvdb::tools::levelSetVolume(*g);
    ASSERT_GT(v0, 0.0);
    for (int i = 0; i < 100; ++i) {
        renormalizeAll(*g, FmmOrder::Second);
        if (i == 0 || i == 9)
            std::printf("[ fmm ] rod volume after %d: %.6g\n", i + 1,
                        openvdb::tools::levelSetVolume(*g));
    }
    const double v1 = openvdb::tools::levelSetVolume(*g);
    std::printf("[ fmm ] rod volume %.6g -> %.6g after 100 renormalizations (%+.2f%%)\n", v0, v1,
                100 * (v1 - v0) / v0);
    EXPECT_NEAR(v1, v0, 0.05 * v0);
}
