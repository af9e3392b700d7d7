// SPDX-License-Identifier: Apache-2.0
// Sampled velocity fields (deform/sampled_field.h) and the swept fluid (deform/swept_fluid.h):
// the cubic B-spline's reproduction of linear fields and its Lipschitz bound, the solver's
// divergence, the step count and modulation of 4.26 and 4.27, the segment's inverse and
// forward maps, and fluid strokes in scripts.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "deform/box_solve.h"
#include "deform/swept_fluid.h"
#include "grids.h"
#include "io/fluid_cache.h"
#include "io/stroke_script.h"
#include "io/velocity_file.h"
#include "levelset/create.h"
#include "random.h"
#include "sculpt/sculptor.h"

using namespace sweepers;
using sweepers::test::Rng;

namespace {

// A linear field v(x) = A x + b sampled on a lattice of 12 a side, cell-centred or on the
// faces (staggered).
VelocitySamples linearSamples(const Eigen::Matrix3d& A, const Eigen::Vector3d& b, bool staggered) {
    VelocitySamples s;
    s.dims = {12, 12, 12};
    s.origin = {-1.0, -0.5, 0.25};
    s.spacing = 0.2;
    s.staggered = staggered;
    for (int k = 0; k < 12; ++k)
        for (int j = 0; j < 12; ++j)
            for (int i = 0; i < 12; ++i) {
                const Eigen::Vector3d x = s.origin + s.spacing * Eigen::Vector3d(i, j, k);
                Eigen::Vector3f v;
                for (int c = 0; c < 3; ++c) {
                    Eigen::Vector3d at = x;
                    if (staggered) at[c] -= 0.5 * s.spacing;
                    v[c] = float((A * at + b)[c]);
                }
                s.values.push_back(v);
            }
    return s;
}

// A small solve: 32^3 cells, a ball of 6.
FluidSpec smallFluid() {
    FluidSpec spec;
    spec.cells = 32;
    spec.ballRadius = 6;
    return spec;
}

const FluidSolution& smallSolution() {
    static const FluidSolution solution = solveSweptFluid(smallFluid());
    return solution;
}

// (shift - scale Laplacian) x on the box, by its 7-point stencil: a neighbour beyond a
// closed end is not there (no flow), one beyond a zero end holds zero.
std::vector<double> applyBoxOperator(const BoxProblem& p, const std::vector<double>& x) {
    const auto& d = p.dims;
    auto at = [&](int i, int j, int k) {
        return x[std::size_t(i) + std::size_t(d[0]) * (std::size_t(j) + std::size_t(d[1]) * k)];
    };
    std::vector<double> y;
    for (int k = 0; k < d[2]; ++k)
        for (int j = 0; j < d[1]; ++j)
            for (int i = 0; i < d[0]; ++i) {
                double laplacian = 0.0;
                for (int a = 0; a < 3; ++a)
                    for (const int step : {-1, 1}) {
                        int n[3] = {i, j, k};
                        n[a] += step;
                        if (n[a] >= 0 && n[a] < d[a])
                            laplacian += at(n[0], n[1], n[2]) - at(i, j, k);
                        else if (p.ends[a] == BoxEnds::Zero)
                            laplacian -= at(i, j, k);
                    }
                y.push_back(p.shift * at(i, j, k) - p.scale * laplacian);
            }
    return y;
}

std::string fluidRefusal(const std::string& stroke) {
    const std::string text = R"({"sweepers": 1, "grid": {"voxel_size": 0.02},
        "start": {"sphere": {"center": [0, 0, 0], "radius": 1}}, "strokes": [)" +
                             stroke + "]}";
    try {
        loadStrokeScript(text, "fluid.json");
    } catch (const ScriptError& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST(SampledField, TheBSplineReproducesLinearFieldsInsideItsLattice) {
    // Cubic B-splines reproduce polynomials up to degree one: away from the lattice's edge
    // (two samples in), the smoothed field is the linear field itself.
    Rng rng(11);
    Eigen::Matrix3d A;
    for (int r = 0; r < 3; ++r)
        A.row(r) = rng.vec(-1, 1).transpose();
    const Eigen::Vector3d b = rng.vec(-1, 1);
    for (const bool staggered : {false, true}) {
        const SampledField field(linearSamples(A, b, staggered));
        for (int i = 0; i < 200; ++i) {
            const Eigen::Vector3d x =
                rng.inBox(Eigen::Vector3d(-0.5, 0.0, 0.75), Eigen::Vector3d(0.8, 1.3, 2.05));
            EXPECT_LT((field.at(x) - (A * x + b)).norm(), 1e-5) << staggered;
            EXPECT_NEAR(field.divergence(x), A.trace(), 1e-4) << staggered;
            EXPECT_LT((field.jacobian(x, 0.0) - A).norm(), 1e-3) << staggered;
        }
        // Beyond two samples past the lattice, at rest.
        EXPECT_EQ(field.at(Eigen::Vector3d(-1.6, 0.0, 1.0)), Eigen::Vector3d::Zero());
        EXPECT_EQ(field.at(Eigen::Vector3d(0.0, 0.0, 3.0)), Eigen::Vector3d::Zero());
    }
}

TEST(SampledField, ItsLipschitzBoundHoldsAndBadSamplesAreRefused) {
    Rng rng(12);
    VelocitySamples s;
    s.dims = {6, 5, 7};
    s.spacing = 0.1;
    s.staggered = true;
    for (std::size_t i = 0; i < s.count(); ++i)
        s.values.push_back(rng.vec(-1, 1).cast<float>());
    const SampledField field(s);
    double most = 0.0;
    for (int i = 0; i < 2000; ++i) {
        const Eigen::Vector3d x =
            rng.inBox(Eigen::Vector3d::Constant(-0.3), Eigen::Vector3d::Constant(0.9));
        most = std::max(most, field.jacobian(x, 0.0).operatorNorm());
    }
    EXPECT_GT(most, 0.1 * field.lipschitz()); // a bound, within ten times
    EXPECT_LE(most, field.lipschitz());
    s.values[7].y() = std::nanf("");
    EXPECT_THROW(SampledField{s}, std::invalid_argument);
    s.values.pop_back();
    EXPECT_THROW(SampledField{s}, std::invalid_argument);
}

TEST(BoxSolve, SolvesTheStencilToRounding) {
    // Every mix of ends, a box of unequal sides, a random right-hand side: the operator
    // applied to the solution gives it back (less its mean where the operator cannot reach
    // it: no shift, every end closed).
    Rng rng(21);
    constexpr BoxEnds kEnds[2] = {BoxEnds::Closed, BoxEnds::Zero};
    for (int mix = 0; mix < 8; ++mix)
        for (const double shift : {0.0, 1.0}) {
            BoxProblem p;
            p.dims = {7, 5, 6};
            p.ends = {kEnds[mix & 1], kEnds[mix >> 1 & 1], kEnds[mix >> 2]};
            p.shift = shift;
            p.scale = 0.7;
            std::vector<double> b(p.size());
            for (double& v : b)
                v = rng.uniform(-1, 1);
            const bool singular = shift == 0.0 && mix == 0;
            if (singular) {
                double mean = 0.0;
                for (const double v : b)
                    mean += v / double(b.size());
                for (double& v : b)
                    v -= mean;
            }
            std::vector<double> solution = b;
            solveBox(p, solution);
            const std::vector<double> back = applyBoxOperator(p, solution);
            double most = 0.0, mean = 0.0;
            for (std::size_t i = 0; i < b.size(); ++i) {
                most = std::max(most, std::abs(back[i] - b[i]));
                mean += solution[i] / double(b.size());
            }
            EXPECT_LT(most, 1e-12) << "ends " << mix << ", shift " << shift;
            if (singular) {
                EXPECT_LT(std::abs(mean), 1e-12);
            }
        }
    BoxProblem bad;
    bad.dims = {4, 4, 4};
    std::vector<double> few(10);
    EXPECT_THROW(solveBox(bad, few), std::invalid_argument);
    std::vector<double> full(bad.size());
    bad.scale = 0.0;
    EXPECT_THROW(solveBox(bad, full), std::invalid_argument);
}

TEST(SweptFluid, TheSolutionIsDivergenceFreeOnItsGridAndMovesWithTheBall) {
    const FluidSolution& solution = smallSolution();
    std::printf("32^3 fluid: divergence %.3g\n", solution.divergence);
    // The projection is solved exactly: what is left is rounding.
    EXPECT_LT(solution.divergence, 1e-12);
    const SweptFluid fluid(solution.samples, smallFluid().ballRadius);
    // The ball goes along +x; the fluid beside it goes back to make room.
    const Eigen::Vector3d centre = fluid.field->at(Eigen::Vector3d::Zero());
    EXPECT_GT(centre.x(), 0.3);
    EXPECT_LT(centre.x(), 1.0);
    EXPECT_LT(centre.tail<2>().norm(), 1e-6);
    EXPECT_LT(fluid.field->at(Eigen::Vector3d(0, 9, 0)).x(), 0.0);
    EXPECT_EQ(fluid.field->at(Eigen::Vector3d(0, 19, 0)), Eigen::Vector3d::Zero());
    // Smoothed, the field keeps a small divergence (the B-spline's derivatives mix
    // neighbouring faces); measured on a lattice over the grid.
    double most = 0.0;
    for (double x = -15; x <= 15; x += 1.5)
        for (double y = -15; y <= 15; y += 1.5)
            for (double z = -15; z <= 15; z += 1.5)
                most = std::max(most, std::abs(fluid.field->divergence({x, y, z})));
    std::printf("smoothed: largest divergence %.3g per unit time, %.2g%% of the centre's speed "
                "per cell\n",
                most, 100.0 * most / fluid.centerSpeed);
    EXPECT_LT(most, 0.02 * fluid.centerSpeed);
}

TEST(SweptFluid, AMoveTakesTheStepsOf426AndCarriesTheBallsCentreAlong) {
    const SweptFluid fluid(smallSolution().samples, smallFluid().ballRadius);
    // A ball of radius 0.3 is 6 cells: a cell is 0.05, and a move of 0.4 is 8 cells, so
    // s = ceil(8 / |v_CENTER|).
    const Eigen::Vector3d from(0.1, 0.2, -0.3), to = from + Eigen::Vector3d(0.0, 0.4, 0.0);
    const int s = sweptFluidSteps(fluid, 0.3, from, to);
    EXPECT_EQ(s, int(std::ceil(8.0 / fluid.centerSpeed)));
    EXPECT_EQ(sweptFluidSteps(fluid, 0.3, from, from + Eigen::Vector3d(0.001, 0, 0)), 1);
    const auto seg = sweptFluidSegment(fluid, 0.3, from, to);
    // Each step lasts l = |W^-1 t| / (s |v_CENTER|) (4.27), which moves the centre of the ball
    // by t / s: the point at the ball's centre goes along with it, up to how the field slows
    // away from the centre.
    const Eigen::Vector3d moved = seg->forwardMap(from).p;
    std::printf("the ball's centre moved to %.4f %.4f %.4f (the tool to %.4f %.4f %.4f)\n",
                moved.x(), moved.y(), moved.z(), to.x(), to.y(), to.z());
    EXPECT_LT((moved - to).norm(), 0.1 * 0.4);
    EXPECT_GT(moved.y(), from.y() + 0.3);
    EXPECT_THROW(sweptFluidSegment(fluid, 0.3, from, from), std::invalid_argument);
    EXPECT_THROW(sweptFluidSegment(fluid, 0.0, from, to), std::invalid_argument);
}

TEST(SweptFluid, TheForwardMapInvertsTheInverseToAMillionthOfAVoxel) {
    const SweptFluid fluid(smallSolution().samples, smallFluid().ballRadius);
    const Eigen::Vector3d from(0.0, 0.9, 0.0), to(0.2, 1.3, 0.1);
    const auto seg = sweptFluidSegment(fluid, 0.3, from, to);
    const double voxel = 1.0 / 256;
    Rng rng(13);
    double worst = 0.0;
    for (int i = 0; i < 300; ++i) {
        const Eigen::Vector3d p = from + rng.vec(-0.8, 0.8);
        const ForwardResult f = seg->forwardMap(seg->inverseMap(p));
        EXPECT_TRUE(f.converged);
        worst = std::max(worst, (f.p - p).norm() / voxel);
    }
    std::printf("|forward(inverse(p)) - p|: at most %.3g of a 1/256 voxel\n", worst);
    EXPECT_LT(worst, 1e-6);
}

TEST(SweptFluid, ScriptsReadAndWriteFluidStrokesAndRefuseBadOnes) {
    const std::string good = R"({"type": "fluid", "radius": 0.3,
                                 "path": [[0, 0.85, 0], [0, 1.15, 0], [0.1, 1.3, 0]]})";
    EXPECT_EQ(fluidRefusal(good), "");
    const StrokeScript s = loadStrokeScript(
        R"({"sweepers": 1, "start": {"sphere": {"center": [0, 0, 0], "radius": 1}}, "strokes": [)" +
            good + "]}",
        "fluid.json");
    const auto& f = std::get<FluidStroke>(s.strokes.at(0));
    EXPECT_EQ(f.path.size(), 3u);
    ASSERT_TRUE(f.fluid);
    EXPECT_EQ(segmentCount(s.strokes[0], 0.02), 2u);
    const StrokeScript again = loadStrokeScript(formatStrokeScript(s), "again.json");
    EXPECT_EQ(std::get<FluidStroke>(again.strokes.at(0)).path, f.path);
    EXPECT_EQ(std::get<FluidStroke>(again.strokes.at(0)).radius, 0.3);
    EXPECT_NE(fluidRefusal(R"({"type": "fluid", "radius": 0.3, "path": [[0, 1, 0]]})")
                  .find("/strokes/0/path: expected two points or more"),
              std::string::npos);
    EXPECT_NE(fluidRefusal(R"({"type": "fluid", "radius": 0.3, "path": [[0, 1, 0], [0, 1, 0]]})")
                  .find("/strokes/0/path/1: the tool does not move"),
              std::string::npos);
    EXPECT_NE(fluidRefusal(R"({"type": "fluid", "radius": 0, "path": [[0, 1, 0], [0, 2, 0]]})")
                  .find("/strokes/0/radius"),
              std::string::npos);
    EXPECT_NE(
        fluidRefusal(
            R"({"type": "fluid", "radius": 0.3, "path": [[0, 1, 0], [0, 2, 0]], "falloff": 1})")
            .find("/strokes/0/falloff: unknown field"),
        std::string::npos);
}

// SWEEPERS_CACHE pointed at a fresh directory of its own while it lives, then as it was.
struct FreshCache {
    explicit FreshCache(const std::string& name) : dir(::testing::TempDir() + "/" + name) {
        std::filesystem::remove_all(dir);
        if (const char* v = std::getenv("SWEEPERS_CACHE")) had = v;
        ::setenv("SWEEPERS_CACHE", dir.c_str(), 1);
    }
    ~FreshCache() {
        if (had)
            ::setenv("SWEEPERS_CACHE", had->c_str(), 1);
        else
            ::unsetenv("SWEEPERS_CACHE");
    }
    std::string dir;
    std::optional<std::string> had;
};

TEST(SweptFluid, TheCacheKeepsTheSolutionAndSurvivesDamageAndReadOnlyPlaces) {
    // Small grids, each its own solution (and cache file).
    const FreshCache cache("fluid_cache_test");
    FluidSpec a;
    a.cells = 16;
    a.ballRadius = 4;
    std::string said;
    const auto first = sweptFluid(a, &said);
    EXPECT_NE(said.find("solved the swept fluid (16^3 cells)"), std::string::npos) << said;
    EXPECT_NE(said.find("kept it in " + fluidCachePath(a)), std::string::npos) << said;
    EXPECT_TRUE(std::filesystem::exists(fluidCachePath(a)));
    EXPECT_EQ(sweptFluid(a, &said), first);
    EXPECT_EQ(said, "the swept fluid was found earlier in this run");
    // A damaged cache file is solved again and replaced.
    FluidSpec b = a;
    b.ballRadius = 3;
    std::ofstream(fluidCachePath(b)) << "not a vdb";
    const auto second = sweptFluid(b, &said);
    EXPECT_NE(said.find("not a readable VDB file"), std::string::npos) << said;
    EXPECT_NE(said.find("kept it in"), std::string::npos) << said;
    EXPECT_GT(std::filesystem::file_size(fluidCachePath(b)), 1000u);
    // A velocity file in its place that was not solved with these parameters: solved again.
    FluidSpec d = a;
    d.viscosity = 1.0;
    writeVelocity(first->field->samples(), fluidCachePath(d), "velocity");
    const auto fourth = sweptFluid(d, &said);
    EXPECT_NE(said.find("was solved with other parameters"), std::string::npos) << said;
    EXPECT_NE(fourth->centerSpeed, first->centerSpeed);
    // A cache that cannot be written costs the solve, nothing else.
    ::setenv("SWEEPERS_CACHE", "/dev/null/cache", 1);
    FluidSpec c = a;
    c.ballRadius = 2;
    const auto third = sweptFluid(c, &said);
    ASSERT_TRUE(third);
    EXPECT_GT(third->centerSpeed, 0.1);
    EXPECT_NE(said.find("could not keep it"), std::string::npos) << said;
}

// The swept fluid made by the run that solves it and by the runs that read it from the cache
// is the same field: the same lattice, the same samples, to the bit, so a fluid stroke
// sculpts the same grid either way (a solver of few cells, so that it solves in a moment).
TEST(SweptFluid, TheRunThatSolvesItAndTheRunsThatReadItSculptTheSameGrid) {
    const FreshCache cache("fluid_lattice_test");
    FluidSpec spec;
    spec.cells = 24;
    spec.ballRadius = 4;
    const auto solved = sweptFluid(spec); // solves, keeps it in the cache
    ASSERT_TRUE(std::filesystem::exists(fluidCachePath(spec)));
    const VelocitySamples read = readVelocitySamples(fluidCachePath(spec), "velocity");
    const VelocitySamples made = solved->field->samples();
    // The solver's outer layer is at rest (the closed walls): the lattice must keep it.
    EXPECT_EQ(read.dims, made.dims);
    EXPECT_EQ(read.origin, made.origin);
    EXPECT_EQ(read.spacing, made.spacing);
    ASSERT_EQ(read.values.size(), made.values.size());
    EXPECT_EQ(std::memcmp(read.values.data(), made.values.data(),
                          read.values.size() * sizeof(Eigen::Vector3f)),
              0);
    const auto fromFile = std::make_shared<SweptFluid>(read, spec.ballRadius);
    FluidStroke stroke;
    stroke.radius = 0.3;
    stroke.path = {{0, 0.85, 0}, {0, 1.05, 0.1}};
    GridPtr grids[2];
    int k = 0;
    for (const auto& fluid : {solved, std::shared_ptr<const SweptFluid>(fromFile)}) {
        stroke.fluid = fluid;
        Sculptor sculptor(makeSphere(Eigen::Vector3d::Zero(), 1.0, 1.0 / 32, 3.0));
        sculptor.applyStroke(stroke);
        grids[k++] = sculptor.gridPtr();
    }
    EXPECT_EQ(sweepers::test::differingBits(*grids[0], *grids[1]), 0u);
}
