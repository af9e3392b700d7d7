// SPDX-License-Identifier: Apache-2.0
// Draws a document with OpenGL 3.3 core: the clay surface in bricks of 4^3 leaves (only
// bricks whose chunks changed are re-uploaded), an optional wireframe, the ground grid,
// the tool with its coating as translucent shells, and the lines of a stroke's preview.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/marching_cubes.h"

namespace sweepers {

struct ToolOverlay {
    bool visible = false;
    glm::dvec3 center{0.0};
    double radius = 0.25, falloff = 0.25;
    // Line segments (pairs of ends) drawn over the shape: the preview of a pinch or a
    // strangle.
    std::vector<glm::vec3> lines;
};

// How the surface looks (shaders/clay.frag): the lit clay, or a matcap (a colour per
// direction the surface faces the camera, by sphere mapping) that reads form without
// lights: a glossy glaze, red wax, or the normals as colours.
enum class SurfaceLook { Clay, Glossy, RedWax, Normals };
inline constexpr SurfaceLook kSurfaceLooks[] = {SurfaceLook::Clay, SurfaceLook::Glossy,
                                                SurfaceLook::RedWax, SurfaceLook::Normals};
// clay, glossy, red-wax, normals.
const char* lookName(SurfaceLook look);
std::optional<SurfaceLook> parseLook(const std::string& name);

class GlRenderer {
  public:
    // Compiles the shaders found in `shaderDir`; throws with the compiler's log on failure.
    explicit GlRenderer(const std::string& shaderDir);
    ~GlRenderer();
    GlRenderer(const GlRenderer&) = delete;
    GlRenderer& operator=(const GlRenderer&) = delete;

    // Re-uploads what changed.
    void update(const SurfaceMesher& mesher, const MeshChanges& changes);
    void draw(const glm::dmat4& view, const glm::dmat4& projection, bool wireframe,
              const ToolOverlay& tool, double groundY);
    void setLook(SurfaceLook look) { look_ = look; }
    SurfaceLook look() const { return look_; }

    std::size_t bricks() const { return bricks_.size(); }
    std::size_t uploadedBricksLastUpdate() const { return lastUploads_; }

  private:
    struct GpuMesh {
        unsigned vao = 0, vbo = 0, ebo = 0;
        int indexCount = 0;
    };
    void uploadBrick(const SurfaceMesher& mesher, const openvdb::Coord& brick);
    void releaseBrick(GpuMesh& m);

    unsigned clay_ = 0, flat_ = 0;
    std::map<openvdb::Coord, GpuMesh> bricks_;
    GpuMesh sphere_, grid_, lines_;
    int gridLines_ = 0;
    std::size_t lastUploads_ = 0;
    SurfaceLook look_ = SurfaceLook::Clay;
};

// Where the shaders are: next to the binary (shaders/ or ../share/sweepers/shaders, where
// `cmake --install` puts them), else, for the modeler in its build tree, the source tree's.
std::string findShaderDir(const std::string& argv0);

} // namespace sweepers
