// SPDX-License-Identifier: Apache-2.0
// Marching cubes over a narrow-band level set, kept in chunks of one VDB leaf each, so a
// stroke re-meshes only the leaves it touched (plus one ring of neighbours).
//
// A cube belongs to the leaf holding its lowest corner and is meshed when that corner is
// active (a valid band of half-width >= 2 has every surface-crossing cube so). Vertices
// sit on cube edges at the linear zero crossing and are named by their edge (lowest voxel
// and axis), which welds chunks into one watertight mesh. Normals are the SDF gradient:
// central differences at the edge's two voxels, interpolated along the edge (5.17).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "levelset/interrupt.h"
#include "mesh/triangle_mesh.h"
#include "vdb/vdb.h"

namespace sweepers {

struct MeshChunk {
    std::vector<Eigen::Vector3f> positions, normals;
    std::vector<std::uint64_t> edgeKeys; // one per vertex
    std::vector<Eigen::Vector3i> triangles;
    double volume = 0.0; // the enclosedVolume of its triangles (their part of the whole)
    // A hash of everything the triangles were made from (the values the leaf's cubes and
    // normals read, its active voxels, the grid's placement; 0: none): a leaf whose hash is
    // unchanged is not meshed again.
    std::uint64_t madeFrom = 0;
};

// What changed in a mesher since it was last asked: everything, or the chunks whose
// leaves overlap a box.
struct MeshChanges {
    bool all = false;
    openvdb::CoordBBox box; // index space; empty when nothing changed
    bool any() const { return all || !box.empty(); }
};

class SurfaceMesher {
  public:
    SurfaceMesher();
    ~SurfaceMesher();
    SurfaceMesher(SurfaceMesher&&) noexcept;
    SurfaceMesher& operator=(SurfaceMesher&&) noexcept;

    // Meshes every active leaf; a cancelled rebuild (Cancelled) changes nothing.
    void rebuild(const Grid& grid, Interrupter* interrupter = nullptr);
    // Re-meshes the leaves overlapping `touched` grown by two voxels (as far as a leaf's
    // normals read) whose values changed; returns how many chunks were made or emptied.
    std::size_t update(const Grid& grid, const openvdb::CoordBBox& touched);
    // Re-meshes the leaves whose cubes or normals read a voxel of one of the boxes and whose
    // values changed. For small boxes, such as the box per leaf in which advectSegment reports
    // what a segment changed: the leaves a stroke changed, not every leaf of its box.
    std::size_t update(const Grid& grid, const std::vector<openvdb::CoordBBox>& changed);

    const std::map<openvdb::Coord, MeshChunk>& chunks() const { return chunks_; }
    // The changes since the last call (a renderer re-uploads only those).
    MeshChanges takeChanges();
    std::size_t triangleCount() const;
    // Enclosed volume of the chunks' triangles (a shared edge vertex has the same
    // coordinates in both chunks, so no welding is needed): the sum of the volumes each
    // chunk keeps, so asking after every segment costs an addition per chunk.
    double enclosedVolume() const;
    // One mesh with the chunks welded along their shared edges.
    TriangleMesh weld() const;

  private:
    // Returns how many chunks changed (made again, or emptied: meshLeaf).
    std::size_t meshLeaves(const Grid& grid, const std::vector<openvdb::Coord>& origins,
                           Interrupter* interrupter = nullptr);
    std::map<openvdb::Coord, MeshChunk> chunks_;
    MeshChanges changes_{true, {}};
    // Per thread, what a leaf is meshed in: kept from one update to the next.
    struct Scratch;
    std::unique_ptr<Scratch> scratch_;
};

// Convenience: the welded mesh of a whole grid.
TriangleMesh meshLevelSet(const Grid& grid);

} // namespace sweepers
