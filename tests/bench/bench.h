// SPDX-License-Identifier: Apache-2.0
// Shared pieces of sweepers-bench: the voxel sizes to run, analytic shapes, and the
// figures the benchmarks compare (distance errors, symmetric differences, meshes).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "mesh/triangle_mesh.h"
#include "vdb/vdb.h"

namespace sweepers::bench {

// Voxel sizes as fractions of the unit sphere's radius: 64 means h = 1/64.
const std::vector<int>& voxelDivisions();
void setVoxelDivisions(std::vector<int> divisions);

using Sdf = std::function<double(const Eigen::Vector3d&)>;

// Narrow band (half-width 3) of an analytic signed distance over a world box.
GridPtr gridFromSdf(const Sdf& sdf, double voxelSize, const Eigen::Vector3d& lo,
                    const Eigen::Vector3d& hi);

struct DistanceErrors {
    double maxNear = 0.0, rmsNear = 0.0; // voxels next to the zero crossing, in voxels
    double maxBand = 0.0, rmsBand = 0.0; // every active voxel, in voxels
};
DistanceErrors distanceErrors(const Grid& grid, const Sdf& exact);

// Volume of the region where the two level sets disagree in sign, divided by the first
// one's surface area: the thickness of the disagreement, in voxel layers.
double symmetricDifferenceLayers(const Grid& a, const Grid& b);

// tools::volumeToMesh's output, and the same as triangles (each quad split in two).
struct VdbMesh {
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
};
VdbMesh openvdbMesh(const Grid& grid);
TriangleMesh toTriangleMesh(const VdbMesh& mesh);
// Triangles and whether every edge has exactly two of them, consistently oriented.
void addMeshCounters(benchmark::State& state, const TriangleMesh& mesh);

// The unit sphere at voxel size 1/div after one large pull (a ball of radius 0.4, falloff
// 0.5, moved from (0, 0, 0.9) to (0.3, 0.2, 1.5)), renormalized or not; `touched` gets the
// box the engine renormalizes after it.
GridPtr afterLargeStroke(int div, bool renormalize, openvdb::CoordBBox* touched = nullptr);

// Times `run` on a fresh copy of `start` in every iteration (the copy is not timed) and
// returns the last result.
GridPtr timedOnCopies(benchmark::State& state, const Grid& start,
                      const std::function<void(Grid&)>& run);

// Registration, one function per group (called by main in this order).
void registerDragBenchmarks();
void registerThreadBenchmarks();
void registerScaleBenchmarks();
void registerAdvectBenchmarks();
void registerRenormalizeBenchmarks();
void registerMeshBenchmarks();
void registerEnrightBenchmarks();
void registerBrushBenchmarks();

// The benchmark name is "group/case/method"; times are wall-clock milliseconds.
benchmark::internal::Benchmark* add(const std::string& name,
                                    std::function<void(benchmark::State&)> fn, int iterations);

} // namespace sweepers::bench
