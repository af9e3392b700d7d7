// SPDX-License-Identifier: Apache-2.0
// Comparing the meshes two SurfaceMeshers keep, chunk by chunk.
#pragma once

#include <sstream>
#include <string>

#include "mesh/marching_cubes.h"

namespace sweepers::test {

// "" when both hold the same chunks (the same leaves; positions, normals and triangles to the
// bit), else the first difference.
inline std::string chunkDifference(const SurfaceMesher& a, const SurfaceMesher& b) {
    std::ostringstream out;
    if (a.chunks().size() != b.chunks().size()) {
        out << a.chunks().size() << " chunks against " << b.chunks().size();
        return out.str();
    }
    for (const auto& [origin, chunk] : b.chunks()) {
        const auto it = a.chunks().find(origin);
        if (it == a.chunks().end())
            out << "no chunk at " << origin;
        else if (it->second.positions != chunk.positions)
            out << "positions differ at " << origin;
        else if (it->second.normals != chunk.normals)
            out << "normals differ at " << origin;
        else if (it->second.triangles != chunk.triangles)
            out << "triangles differ at " << origin;
        if (!out.str().empty()) return out.str();
    }
    return "";
}

} // namespace sweepers::test
