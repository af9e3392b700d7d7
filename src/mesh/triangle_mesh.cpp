// SPDX-License-Identifier: Apache-2.0
#include "mesh/triangle_mesh.h"

#include <algorithm>
#include <unordered_map>

#include <Eigen/Geometry>

namespace sweepers {

MeshTopology meshTopology(const TriangleMesh& mesh) {
    MeshTopology t;
    t.faces = mesh.triangles.size();
    // Count the vertices that triangles use (a welded mesh has no others).
    std::vector<bool> used(mesh.positions.size(), false);
    // Undirected edge -> (count, sum of directions): two triangles running an edge in
    // opposite directions sum to zero.
    struct Use {
        int count = 0, direction = 0;
    };
    std::unordered_map<std::uint64_t, Use> edges;
    edges.reserve(mesh.triangles.size() * 2);
    for (const Eigen::Vector3i& tri : mesh.triangles) {
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = tri[k], b = tri[(k + 1) % 3];
            used[a] = true;
            const std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            Use& u = edges[key];
            ++u.count;
            u.direction += a < b ? 1 : -1;
        }
    }
    t.vertices = std::size_t(std::count(used.begin(), used.end(), true));
    t.edges = edges.size();
    for (const auto& [key, u] : edges) {
        if (u.count == 1) ++t.boundaryEdges;
        if (u.count > 2) ++t.nonManifoldEdges;
        if (u.count == 2 && u.direction != 0) ++t.misorientedEdges;
    }
    return t;
}

double enclosedVolume(const std::vector<Eigen::Vector3f>& positions,
                      const std::vector<Eigen::Vector3i>& triangles) {
    double v = 0.0;
    for (const Eigen::Vector3i& t : triangles) {
        const Eigen::Vector3d a = positions[t[0]].cast<double>();
        const Eigen::Vector3d b = positions[t[1]].cast<double>();
        const Eigen::Vector3d c = positions[t[2]].cast<double>();
        v += a.dot(b.cross(c));
    }
    return v / 6.0;
}

double enclosedVolume(const TriangleMesh& mesh) {
    return enclosedVolume(mesh.positions, mesh.triangles);
}

TriangleMesh zUp(TriangleMesh mesh) {
    // (x, y, z) -> (x, -z, y): a rotation, so orientation and normals stay consistent.
    const auto turn = [](Eigen::Vector3f& v) { v = Eigen::Vector3f(v.x(), -v.z(), v.y()); };
    for (Eigen::Vector3f& p : mesh.positions)
        turn(p);
    for (Eigen::Vector3f& n : mesh.normals)
        turn(n);
    return mesh;
}

double surfaceArea(const TriangleMesh& mesh) {
    double s = 0.0;
    for (const Eigen::Vector3i& t : mesh.triangles) {
        const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
        const Eigen::Vector3d b = mesh.positions[t[1]].cast<double>();
        const Eigen::Vector3d c = mesh.positions[t[2]].cast<double>();
        s += 0.5 * (b - a).cross(c - a).norm();
    }
    return s;
}

} // namespace sweepers
