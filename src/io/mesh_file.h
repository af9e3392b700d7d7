// SPDX-License-Identifier: Apache-2.0
// Triangle mesh files through Assimp: OBJ, PLY and binary STL out, and whatever Assimp
// reads in (OBJ, PLY, STL, ...). The format follows the file extension.
#pragma once

#include <string>

#include "io/vdb_file.h"
#include "mesh/triangle_mesh.h"

namespace sweepers {

// Throws FileError for an unknown extension or a failed write; the write is atomic.
void writeMesh(const TriangleMesh& mesh, const std::string& path);
// The same, written and flushed but not yet in place: commit() puts it there.
AtomicWrite prepareMesh(const TriangleMesh& mesh, const std::string& path);
// Throws FileError when the file cannot be read or holds no triangles.
TriangleMesh readMesh(const std::string& path);

// True when the extension names a format writeMesh knows (.obj, .ply, .stl).
bool isMeshPath(const std::string& path);
// Throws FileError naming the formats when it does not.
void requireMeshPath(const std::string& path);

} // namespace sweepers
