// SPDX-License-Identifier: Apache-2.0
#define GL_GLEXT_PROTOTYPES
#include "app/gl_renderer.h"

#include <GL/gl.h>
#include <GL/glext.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "levelset/stencils.h"

namespace sweepers {

namespace {

constexpr int kBrick = 32; // voxels: 4 x 4 x 4 leaves

std::string readFile(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error(path + ": cannot open shader");
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

unsigned compile(GLenum kind, const std::string& path) {
    const std::string src = readFile(path);
    const char* text = src.c_str();
    const unsigned s = glCreateShader(kind);
    glShaderSource(s, 1, &text, nullptr);
    glCompileShader(s);
    int ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        throw std::runtime_error(path + ": " + log);
    }
    return s;
}

unsigned program(const std::string& dir, const std::string& name) {
    const unsigned vs = compile(GL_VERTEX_SHADER, dir + "/" + name + ".vert");
    const unsigned fs = compile(GL_FRAGMENT_SHADER, dir + "/" + name + ".frag");
    const unsigned p = glCreateProgram();
    glAttachShader(p, vs);
    glAttachShader(p, fs);
    glLinkProgram(p);
    glDeleteShader(vs);
    glDeleteShader(fs);
    int ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetProgramInfoLog(p, sizeof log, nullptr, log);
        throw std::runtime_error(dir + "/" + name + ": " + log);
    }
    return p;
}

openvdb::Coord brickOf(const openvdb::Coord& c) {
    return floorToMultiple(c, kBrick);
}

void setMatrix(unsigned prog, const char* name, const glm::mat4& m) {
    glUniformMatrix4fv(glGetUniformLocation(prog, name), 1, GL_FALSE, glm::value_ptr(m));
}

} // namespace

std::string findShaderDir(const std::string& argv0) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) exe = fs::absolute(argv0);
    std::vector<fs::path> places{exe.parent_path() / "shaders",
                                 exe.parent_path() / ".." / "share" / "sweepers" / "shaders"};
    // The source tree only for the modeler in the tree it was built in: an installed one
    // must find its installed shaders, not a checkout that may have changed since.
    if (fs::equivalent(exe.parent_path(), fs::path(SWEEPERS_BUILD_DIR), ec))
        places.emplace_back(SWEEPERS_SHADER_DIR);
    for (const fs::path& d : places)
        if (fs::exists(d / "clay.vert")) return d.string();
    throw std::runtime_error("cannot find the shaders (clay.vert) in " + places[0].string() +
                             " or " + places[1].string());
}

const char* lookName(SurfaceLook look) {
    switch (look) {
    case SurfaceLook::Clay:
        return "clay";
    case SurfaceLook::Glossy:
        return "glossy";
    case SurfaceLook::RedWax:
        return "red-wax";
    case SurfaceLook::Normals:
        return "normals";
    }
    return "";
}

std::optional<SurfaceLook> parseLook(const std::string& name) {
    for (const SurfaceLook look : kSurfaceLooks)
        if (name == lookName(look)) return look;
    return std::nullopt;
}

GlRenderer::GlRenderer(const std::string& shaderDir) {
    clay_ = program(shaderDir, "clay");
    flat_ = program(shaderDir, "flat");

    // A unit sphere (latitude-longitude) for the tool shells.
    std::vector<float> v;
    std::vector<unsigned> idx;
    const int nu = 32, nv = 16;
    for (int j = 0; j <= nv; ++j)
        for (int i = 0; i <= nu; ++i) {
            const double th = M_PI * j / nv, ph = 2 * M_PI * i / nu;
            v.insert(v.end(), {float(std::sin(th) * std::cos(ph)), float(std::cos(th)),
                               float(std::sin(th) * std::sin(ph))});
        }
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const unsigned a = j * (nu + 1) + i, b = a + nu + 1;
            idx.insert(idx.end(), {a, b, a + 1, a + 1, b, b + 1});
        }
    glGenVertexArrays(1, &sphere_.vao);
    glBindVertexArray(sphere_.vao);
    glGenBuffers(1, &sphere_.vbo);
    glBindBuffer(GL_ARRAY_BUFFER, sphere_.vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(v.size() * sizeof(float)), v.data(), GL_STATIC_DRAW);
    glGenBuffers(1, &sphere_.ebo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, sphere_.ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(idx.size() * sizeof(unsigned)), idx.data(),
                 GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
    sphere_.indexCount = int(idx.size());

    // The ground grid: lines every 0.25 over [-2, 2]^2 in the plane y = 0 (moved at draw).
    std::vector<float> g;
    for (int i = -8; i <= 8; ++i) {
        const float s = 0.25f * float(i);
        g.insert(g.end(), {s, 0, -2, s, 0, 2, -2, 0, s, 2, 0, s});
    }
    gridLines_ = int(g.size() / 3);
    glGenVertexArrays(1, &grid_.vao);
    glBindVertexArray(grid_.vao);
    glGenBuffers(1, &grid_.vbo);
    glBindBuffer(GL_ARRAY_BUFFER, grid_.vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(g.size() * sizeof(float)), g.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);

    // The preview's lines: filled at every draw.
    glGenVertexArrays(1, &lines_.vao);
    glBindVertexArray(lines_.vao);
    glGenBuffers(1, &lines_.vbo);
    glBindBuffer(GL_ARRAY_BUFFER, lines_.vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
    glBindVertexArray(0);
}

GlRenderer::~GlRenderer() {
    for (auto& [k, m] : bricks_)
        releaseBrick(m);
    releaseBrick(sphere_);
    releaseBrick(grid_);
    releaseBrick(lines_);
    glDeleteProgram(clay_);
    glDeleteProgram(flat_);
}

void GlRenderer::releaseBrick(GpuMesh& m) {
    if (m.vao) glDeleteVertexArrays(1, &m.vao);
    if (m.vbo) glDeleteBuffers(1, &m.vbo);
    if (m.ebo) glDeleteBuffers(1, &m.ebo);
    m = GpuMesh{};
}

void GlRenderer::uploadBrick(const SurfaceMesher& mesher, const openvdb::Coord& brick) {
    std::vector<float> v;
    std::vector<unsigned> idx;
    const int leaf = int(Grid::TreeType::LeafNodeType::DIM);
    for (int x = 0; x < kBrick; x += leaf)
        for (int y = 0; y < kBrick; y += leaf)
            for (int z = 0; z < kBrick; z += leaf) {
                const auto it = mesher.chunks().find(brick.offsetBy(x, y, z));
                if (it == mesher.chunks().end()) continue;
                const MeshChunk& c = it->second;
                const unsigned base = unsigned(v.size() / 6);
                for (std::size_t i = 0; i < c.positions.size(); ++i) {
                    const auto& p = c.positions[i];
                    const auto& n = c.normals[i];
                    v.insert(v.end(), {p.x(), p.y(), p.z(), n.x(), n.y(), n.z()});
                }
                for (const auto& t : c.triangles)
                    idx.insert(idx.end(), {base + unsigned(t[0]), base + unsigned(t[1]),
                                           base + unsigned(t[2])});
            }
    auto found = bricks_.find(brick);
    if (idx.empty()) {
        if (found != bricks_.end()) {
            releaseBrick(found->second);
            bricks_.erase(found);
        }
        return;
    }
    GpuMesh& m = bricks_[brick];
    if (!m.vao) {
        glGenVertexArrays(1, &m.vao);
        glGenBuffers(1, &m.vbo);
        glGenBuffers(1, &m.ebo);
        glBindVertexArray(m.vao);
        glBindBuffer(GL_ARRAY_BUFFER, m.vbo);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.ebo);
        glEnableVertexAttribArray(0);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
        glEnableVertexAttribArray(1);
        // OpenGL takes a byte offset into the bound buffer as a pointer.
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                              reinterpret_cast<void*>(3 * sizeof(float))); // NOLINT
    }
    glBindVertexArray(m.vao);
    glBindBuffer(GL_ARRAY_BUFFER, m.vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(v.size() * sizeof(float)), v.data(), GL_DYNAMIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(idx.size() * sizeof(unsigned)), idx.data(),
                 GL_DYNAMIC_DRAW);
    m.indexCount = int(idx.size());
    glBindVertexArray(0);
}

void GlRenderer::update(const SurfaceMesher& mesher, const MeshChanges& changes) {
    lastUploads_ = 0;
    if (!changes.any()) return;
    std::set<openvdb::Coord> dirty;
    if (changes.all) {
        for (auto& [k, m] : bricks_)
            releaseBrick(m);
        bricks_.clear();
        for (const auto& [origin, chunk] : mesher.chunks())
            dirty.insert(brickOf(origin));
    } else {
        const openvdb::Coord lo = brickOf(changes.box.min()), hi = brickOf(changes.box.max());
        for (int x = lo.x(); x <= hi.x(); x += kBrick)
            for (int y = lo.y(); y <= hi.y(); y += kBrick)
                for (int z = lo.z(); z <= hi.z(); z += kBrick)
                    dirty.insert(openvdb::Coord(x, y, z));
    }
    for (const openvdb::Coord& b : dirty)
        uploadBrick(mesher, b);
    lastUploads_ = dirty.size();
}

void GlRenderer::draw(const glm::dmat4& view, const glm::dmat4& projection, bool wireframe,
                      const ToolOverlay& tool, double groundY) {
    const glm::mat4 vp(projection * view), v(view);
    glEnable(GL_DEPTH_TEST);
    glUseProgram(clay_);
    setMatrix(clay_, "viewProjection", vp);
    setMatrix(clay_, "view", v);
    glUniform3f(glGetUniformLocation(clay_, "baseColor"), 0.78f, 0.62f, 0.52f);
    glUniform1i(glGetUniformLocation(clay_, "look"), int(look_));
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);
    for (const auto& [k, m] : bricks_) {
        glBindVertexArray(m.vao);
        glDrawElements(GL_TRIANGLES, m.indexCount, GL_UNSIGNED_INT, nullptr);
    }
    glDisable(GL_POLYGON_OFFSET_FILL);

    glUseProgram(flat_);
    setMatrix(flat_, "viewProjection", vp);
    const GLint model = glGetUniformLocation(flat_, "model"),
                tint = glGetUniformLocation(flat_, "tint");
    if (wireframe) {
        glUniformMatrix4fv(model, 1, GL_FALSE, glm::value_ptr(glm::mat4(1.0f)));
        glUniform4f(tint, 0.15f, 0.12f, 0.1f, 1.0f);
        glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
        for (const auto& [k, m] : bricks_) {
            glBindVertexArray(m.vao);
            glDrawElements(GL_TRIANGLES, m.indexCount, GL_UNSIGNED_INT, nullptr);
        }
        glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    }
    // Ground grid.
    const glm::mat4 ground = glm::translate(glm::mat4(1.0f), glm::vec3(0, float(groundY), 0));
    glUniformMatrix4fv(model, 1, GL_FALSE, glm::value_ptr(ground));
    glUniform4f(tint, 0.45f, 0.47f, 0.52f, 1.0f);
    glBindVertexArray(grid_.vao);
    glDrawArrays(GL_LINES, 0, gridLines_);

    // The tool (inner zone) and its coating, translucent, without writing depth.
    if (tool.visible) {
        glEnable(GL_BLEND);
        glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
        glDepthMask(GL_FALSE);
        glBindVertexArray(sphere_.vao);
        const struct {
            double r;
            float a;
        } shells[2] = {{tool.radius, 0.28f}, {tool.radius + tool.falloff, 0.10f}};
        for (const auto& s : shells) {
            const glm::mat4 m = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(tool.center)),
                                           glm::vec3(float(s.r)));
            glUniformMatrix4fv(model, 1, GL_FALSE, glm::value_ptr(m));
            glUniform4f(tint, 0.25f, 0.55f, 0.95f, s.a);
            glDrawElements(GL_TRIANGLES, sphere_.indexCount, GL_UNSIGNED_INT, nullptr);
        }
        glDepthMask(GL_TRUE);
        glDisable(GL_BLEND);
    }
    // The preview, over everything: the far needle and the back of a circle matter too.
    if (!tool.lines.empty()) {
        glDisable(GL_DEPTH_TEST);
        glUniformMatrix4fv(model, 1, GL_FALSE, glm::value_ptr(glm::mat4(1.0f)));
        glUniform4f(tint, 1.0f, 0.78f, 0.2f, 1.0f);
        glBindVertexArray(lines_.vao);
        glBindBuffer(GL_ARRAY_BUFFER, lines_.vbo);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(tool.lines.size() * sizeof(glm::vec3)),
                     tool.lines.data(), GL_STREAM_DRAW);
        glDrawArrays(GL_LINES, 0, GLsizei(tool.lines.size()));
        glEnable(GL_DEPTH_TEST);
    }
    glBindVertexArray(0);
}

} // namespace sweepers
