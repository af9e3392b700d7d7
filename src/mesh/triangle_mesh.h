// SPDX-License-Identifier: Apache-2.0
// An indexed triangle mesh and the checks an exported surface must pass.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace sweepers {

struct TriangleMesh {
    std::vector<Eigen::Vector3f> positions;
    std::vector<Eigen::Vector3f> normals; // per vertex, may be empty
    std::vector<Eigen::Vector3i> triangles;
};

struct MeshTopology {
    std::size_t vertices = 0, edges = 0, faces = 0;
    std::size_t boundaryEdges = 0;    // edges in one triangle only
    std::size_t nonManifoldEdges = 0; // edges in more than two triangles
    std::size_t misorientedEdges = 0; // edges whose two triangles run the same way
    bool watertight() const { return boundaryEdges == 0 && nonManifoldEdges == 0; }
    bool consistentlyOriented() const { return misorientedEdges == 0; }
    long eulerCharacteristic() const { return long(vertices) - long(edges) + long(faces); }
};

MeshTopology meshTopology(const TriangleMesh& mesh);

// Signed enclosed volume (divergence theorem); positive for outward-facing triangles.
double enclosedVolume(const TriangleMesh& mesh);
// The same sum over any triangles (they need not be welded: a closed surface cut into
// pieces whose shared vertices have equal coordinates gives the same volume).
double enclosedVolume(const std::vector<Eigen::Vector3f>& positions,
                      const std::vector<Eigen::Vector3i>& triangles);
double surfaceArea(const TriangleMesh& mesh);

// The mesh turned a quarter turn about x, so that our up axis (y) becomes z: for tools
// whose importers take z as up (Blender's PLY and STL importers, most CAD tools).
TriangleMesh zUp(TriangleMesh mesh);

} // namespace sweepers
