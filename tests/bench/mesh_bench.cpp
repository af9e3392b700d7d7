// SPDX-License-Identifier: Apache-2.0
// Meshing: our marching cubes (every leaf, welded into one mesh, as for export) against
// tools::volumeToMesh (dual contouring without adaptivity), on the same grids.
#include "bench.h"
#include "levelset/create.h"
#include "mesh/marching_cubes.h"

namespace sweepers::bench {
namespace {

void registerGrid(const std::string& item, std::function<GridPtr()> make) {
    auto shared = std::make_shared<GridPtr>();
    auto get = [shared, make]() -> const Grid& {
        if (!*shared) *shared = make();
        return **shared;
    };
    add(
        "mesh/" + item + "/sweepers_marching_cubes",
        [get](benchmark::State& state) {
            const Grid& g = get();
            TriangleMesh mesh;
            for (auto _ : state)
                mesh = meshLevelSet(g);
            addMeshCounters(state, mesh);
        },
        3);
    add(
        "mesh/" + item + "/openvdb_volumeToMesh",
        [get](benchmark::State& state) {
            const Grid& g = get();
            VdbMesh mesh;
            for (auto _ : state)
                mesh = openvdbMesh(g);
            addMeshCounters(state, toTriangleMesh(mesh));
        },
        3);
}

} // namespace

void registerMeshBenchmarks() {
    for (const int div : voxelDivisions()) {
        registerGrid("sphere_h" + std::to_string(div),
                     [div] { return makeSphere(Eigen::Vector3d::Zero(), 1.0, 1.0 / div, 3.0); });
        registerGrid("stroke_h" + std::to_string(div),
                     [div] { return afterLargeStroke(div, true); });
    }
}

} // namespace sweepers::bench
