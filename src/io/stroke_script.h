// Stroke scripts: the JSON file format of DESIGN.md section 5.
//
//   { "sweepers": 1,
//     "grid":  { "voxel_size": 0.02, "half_width": 3 },
//     "start": { "sphere": { "center": [0,0,0], "radius": 1 } }   | {"vdb": F} | {"mesh": F}
//     "strokes": [ { "type": "sweep", "mirror": "x", "tools": [ {shape, size, falloff, path} ] },
//                  { "type": "swirl", "at": [..], "move": [..], "radius": r,
//                    "ring": "discrete" | "convolution", "swirls": 8, "ball": rho },
//                  { "type": "inflate", "at": [..], "radius": rho } ] }
//
// Reading validates everything, including that every segment's motion has a logarithm,
// and refuses the whole script on the first problem with a ScriptError whose message
// names the file, the JSON location (a JSON pointer) and the reason. Unknown fields are
// refused too: in a hand-written script they are nearly always typos.
#pragma once

#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "deform/placement.h"
#include "deform/sweep.h"
#include "deform/swirl.h"

namespace sweepers {

class ScriptError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

struct GridSpec {
    double voxelSize = 0.02;
    double halfWidth = 3.0; // in voxels
};

struct StartShape {
    enum class Kind { Sphere, Vdb, Mesh };
    Kind kind = Kind::Sphere;
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    double radius = 1.0;
    std::string file; // as written in the script (relative to it)
};

struct ToolSpec {
    std::string shape = "ball";                            // "ball" | "ellipsoid"
    Eigen::Vector3d size = Eigen::Vector3d::Constant(0.3); // ball: all three equal
    double falloff = 0.3;
    std::vector<Placement> path;
};

struct SweepStroke {
    MirrorAxis mirror = MirrorAxis::None;
    std::vector<ToolSpec> tools;
};

struct SwirlStroke {
    Eigen::Vector3d at = Eigen::Vector3d::Zero();
    Eigen::Vector3d move = Eigen::Vector3d::Zero();
    double radius = 0.3;
    std::string ring = "discrete"; // "discrete" | "convolution"
    int swirls = 8;
    double ball = 0.0; // > 0: star-shaped swirl carrying a ball of this radius (4.19)
};

struct InflateStroke {
    Eigen::Vector3d at = Eigen::Vector3d::Zero();
    double radius = 0.1;
};

using Stroke = std::variant<SweepStroke, SwirlStroke, InflateStroke>;

struct StrokeScript {
    int version = 1;
    GridSpec grid;
    StartShape start;
    std::vector<Stroke> strokes;
};

// Parse and validate; `name` is used in messages (usually the file path).
StrokeScript parseStrokeScript(const std::string& text, const std::string& name);
// Read a file; a missing or unreadable file is a ScriptError too.
StrokeScript readStrokeScript(const std::string& path);
// Serialize (pretty-printed, numbers round-trip exactly).
std::string formatStrokeScript(const StrokeScript& script);
// Write atomically: temporary file beside the target, flush, rename.
void writeStrokeScript(const StrokeScript& script, const std::string& path);

// The deformation a sweep stroke describes.
Sweep toSweep(const SweepStroke& stroke);
// The swirl ring a swirl stroke describes.
SwirlSpec toSwirl(const SwirlStroke& stroke);

} // namespace sweepers
