// SPDX-License-Identifier: Apache-2.0
#include "io/mesh_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "io/atomic_file.h"
#include "io/input_file.h"

namespace sweepers {

namespace {

std::string extension(const std::string& path) {
    const auto dot = path.find_last_of('.');
    if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return "";
    std::string e = path.substr(dot + 1);
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
    return e;
}

const char* exportFormat(const std::string& ext) {
    if (ext == "obj") return "objnomtl";
    if (ext == "ply") return "plyb";
    if (ext == "stl") return "stlb";
    return nullptr;
}

} // namespace

bool isMeshPath(const std::string& path) {
    return exportFormat(extension(path)) != nullptr;
}

void requireMeshPath(const std::string& path) {
    if (!isMeshPath(path)) throw FileError(path + ": unknown mesh format (use .obj, .ply or .stl)");
}

namespace {

// STL stores one normal per facet, which Assimp's exporter averages from the facet's vertex
// normals (up to several degrees off on a curved surface): each facet gets vertices of its
// own carrying its own normal instead (STL shares no vertices anyway).
TriangleMesh withFacetNormals(const TriangleMesh& mesh) {
    TriangleMesh out;
    out.positions.reserve(3 * mesh.triangles.size());
    out.normals.reserve(3 * mesh.triangles.size());
    out.triangles.reserve(mesh.triangles.size());
    for (const Eigen::Vector3i& t : mesh.triangles) {
        const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>(),
                              b = mesh.positions[t[1]].cast<double>(),
                              c = mesh.positions[t[2]].cast<double>();
        const Eigen::Vector3d n = (b - a).cross(c - a);
        const double len = n.norm();
        // (A facet of zero area has no normal of its own: it keeps its vertices' average.)
        Eigen::Vector3f normal = Eigen::Vector3f::Zero();
        if (len > 0)
            normal = (n / len).cast<float>();
        else if (mesh.normals.size() == mesh.positions.size())
            normal = (mesh.normals[t[0]] + mesh.normals[t[1]] + mesh.normals[t[2]]).normalized();
        const int first = int(out.positions.size());
        for (int k = 0; k < 3; ++k) {
            out.positions.push_back(mesh.positions[t[k]]);
            out.normals.push_back(normal);
        }
        out.triangles.emplace_back(first, first + 1, first + 2);
    }
    return out;
}

} // namespace

AtomicWrite prepareMesh(const TriangleMesh& meshIn, const std::string& path) {
    requireMeshPath(path);
    const bool stl = extension(path) == "stl";
    const TriangleMesh facetted = stl ? withFacetNormals(meshIn) : TriangleMesh{};
    const TriangleMesh& mesh = stl ? facetted : meshIn;
    if (mesh.triangles.empty())
        throw FileError(path + ": nothing to write: the surface is empty (the level set has no "
                               "zero crossing)");
    const char* format = exportFormat(extension(path));

    // A one-mesh scene; the aiScene destructor frees everything it points to.
    auto scene = std::make_unique<aiScene>();
    scene->mRootNode = new aiNode();
    scene->mRootNode->mMeshes = new unsigned int[1]{0};
    scene->mRootNode->mNumMeshes = 1;
    scene->mMaterials = new aiMaterial* [1] { new aiMaterial() };
    scene->mNumMaterials = 1;
    aiMesh* m = new aiMesh();
    scene->mMeshes = new aiMesh* [1] { m };
    scene->mNumMeshes = 1;
    m->mMaterialIndex = 0;
    m->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    m->mNumVertices = unsigned(mesh.positions.size());
    m->mVertices = new aiVector3D[m->mNumVertices];
    const bool normals = mesh.normals.size() == mesh.positions.size();
    if (normals) m->mNormals = new aiVector3D[m->mNumVertices];
    for (unsigned i = 0; i < m->mNumVertices; ++i) {
        const auto& p = mesh.positions[i];
        m->mVertices[i] = aiVector3D(p.x(), p.y(), p.z());
        if (normals)
            m->mNormals[i] =
                aiVector3D(mesh.normals[i].x(), mesh.normals[i].y(), mesh.normals[i].z());
    }
    m->mNumFaces = unsigned(mesh.triangles.size());
    m->mFaces = new aiFace[m->mNumFaces];
    for (unsigned f = 0; f < m->mNumFaces; ++f) {
        m->mFaces[f].mNumIndices = 3;
        m->mFaces[f].mIndices =
            new unsigned int[3]{unsigned(mesh.triangles[f][0]), unsigned(mesh.triangles[f][1]),
                                unsigned(mesh.triangles[f][2])};
    }
    // Exported into memory, then written with checked writes (Assimp's own file output does
    // not report a full disk).
    Assimp::Exporter exporter;
    const aiExportDataBlob* blob = exporter.ExportToBlob(scene.get(), format);
    if (!blob)
        throw FileError(path + ": cannot write the mesh (" + exporter.GetErrorString() + ")");
    return AtomicWrite(path, [&](std::ostream& out) {
        out.write(static_cast<const char*>(blob->data), std::streamsize(blob->size));
    });
}

void writeMesh(const TriangleMesh& mesh, const std::string& path) {
    prepareMesh(mesh, path).commit();
}

namespace {

// Bytes one value of a PLY scalar type takes in a binary file (0: not a type).
std::size_t plyTypeBytes(const std::string& type) {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" ||
        type == "float32")
        return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
}

// A PLY header announces how many elements follow, and Assimp allocates for them before it
// reads one: a damaged count (2^31 vertices) would ask for gigabytes. Every element takes at
// least some bytes (binary: its scalar properties and list counts; ASCII: a digit and a
// separator per property), so counts the rest of the file cannot hold are refused first.
void checkPlyCounts(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    in.seekg(0, std::ios::end);
    const auto size = static_cast<unsigned long long>(std::max<std::streamoff>(0, in.tellg()));
    in.seekg(0);
    std::string line;
    bool ascii = true;
    struct Element {
        std::string name;
        unsigned long long count = 0, bytes = 0;
    };
    std::vector<Element> elements;
    unsigned long long header = 0;
    while (std::getline(in, line) && header < (1u << 16)) {
        header += line.size() + 1;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream words(line);
        std::string word;
        words >> word;
        if (word == "end_header") break;
        if (word == "format") {
            words >> word;
            ascii = word == "ascii";
        } else if (word == "element") {
            Element e;
            words >> e.name >> e.count;
            if (!words) return; // Assimp says what is wrong with the header
            elements.push_back(e);
        } else if (word == "property" && !elements.empty()) {
            std::string type;
            words >> type;
            if (type == "list") words >> type; // the count's type: a list holds at least that
            elements.back().bytes += ascii ? 2 : std::max<std::size_t>(1, plyTypeBytes(type));
        }
    }
    const unsigned long long body = size > header ? size - header : 0;
    for (const Element& e : elements)
        if (e.bytes > 0 && e.count > body / e.bytes)
            throw FileError(path + ": the header announces " + std::to_string(e.count) + " " +
                            e.name + " elements, more than the file's " + std::to_string(body) +
                            " bytes of data can hold (a damaged header?)");
}

// What Assimp's post-processing would crash on (it trusts face indices): checked on the
// scene as read.
void validateScene(const aiScene& scene, const std::string& path) {
    std::size_t nonFinite = 0;
    for (unsigned mi = 0; mi < scene.mNumMeshes; ++mi) {
        const aiMesh* m = scene.mMeshes[mi];
        for (unsigned i = 0; i < m->mNumVertices; ++i) {
            const aiVector3D& v = m->mVertices[i];
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) ++nonFinite;
        }
        for (unsigned f = 0; f < m->mNumFaces; ++f)
            for (unsigned k = 0; k < m->mFaces[f].mNumIndices; ++k)
                if (m->mFaces[f].mIndices[k] >= m->mNumVertices)
                    throw FileError(path + ": face " + std::to_string(f) + " refers to vertex " +
                                    std::to_string(int(m->mFaces[f].mIndices[k])) +
                                    ", but the mesh has " + std::to_string(m->mNumVertices) +
                                    " vertices");
    }
    if (nonFinite > 0)
        throw FileError(path + ": " + std::to_string(nonFinite) +
                        " vertices have coordinates that are not finite numbers");
}

} // namespace

TriangleMesh readMesh(const std::string& path) {
    requireRegularFile(path);
    if (!std::ifstream(path).good()) throw FileError(path + ": cannot open the file");
    if (extension(path) == "ply") checkPlyCounts(path);
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(path, 0);
    if (scene) {
        validateScene(*scene, path);
        // Normals are dropped before joining, so that formats with per-face normals (STL)
        // weld by position and come back watertight.
        scene =
            importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_DropNormals |
                                         aiProcess_JoinIdenticalVertices | aiProcess_SortByPType);
    }
    if (!scene) {
        const std::string why = importer.GetErrorString();
        if (why.find("bad_alloc") != std::string::npos)
            throw FileError(path + ": the file announces more data than memory can hold (a "
                                   "damaged header?)");
        throw FileError(path + ": cannot read the mesh (" + why + ")");
    }
    TriangleMesh out;
    for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi) {
        const aiMesh* m = scene->mMeshes[mi];
        const int base = int(out.positions.size());
        for (unsigned i = 0; i < m->mNumVertices; ++i)
            out.positions.emplace_back(m->mVertices[i].x, m->mVertices[i].y, m->mVertices[i].z);
        for (unsigned f = 0; f < m->mNumFaces; ++f) {
            if (m->mFaces[f].mNumIndices != 3) continue;
            const unsigned* ix = m->mFaces[f].mIndices;
            out.triangles.emplace_back(base + int(ix[0]), base + int(ix[1]), base + int(ix[2]));
        }
    }
    if (out.triangles.empty()) throw FileError(path + ": the mesh has no triangles");
    // A level set needs an inside: every edge must join two triangles.
    const MeshTopology topology = meshTopology(out);
    if (topology.boundaryEdges > 0)
        throw FileError(path + ": the mesh is not closed (" +
                        std::to_string(topology.boundaryEdges) +
                        " edges border a single triangle), so it has no inside");
    return out;
}

} // namespace sweepers
