// SPDX-License-Identifier: Apache-2.0
// The stroke model: what a sculptor does to a shape, as data. A stroke script (io/) and
// the modeler's drags (app/) both produce these; sculpt/stroke_plan.h is the one place where
// a stroke kind becomes deformations.
//
//   sweep   - tools (balls, ellipsoids or baked shapes) moved along paths of placements
//             (thesis 3.3, 3.4.3)
//   swirl   - a ring of swirls carrying clay while keeping its volume (4.1-4.19)
//   inflate - Decaudin's inflation adding a ball of material (2.30)
//   pinch   - two needles poke a hole through the shape, then pull it open (3.5.1)
//   strangle - a circle contracts around a limb until it parts, then pulls the parts apart
//             (3.5.2)
//   keyframed - a tool whose target placement is keyed over time (3.6.1)
//   slide   - a sweep in a local frame keyed over time (3.6.1)
//   flow    - the shape carried by a velocity field over a span of time (chapter 4)
//   fluid   - a ball pushed through the shape as through a fluid (swept fluid, 4.2)
//   smooth  - the surface under a ball relaxed by mean-curvature flow (levelset/smooth.h):
//             not a deformation of space, so no exact shape stands behind it
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "deform/flow.h"
#include "deform/keyframes.h"
#include "deform/pinch.h"
#include "deform/placement.h"
#include "deform/step_deformation.h"
#include "deform/strangle.h"
#include "deform/sweep.h"
#include "deform/swept_fluid.h"
#include "deform/swirl.h"
#include "levelset/smooth.h"
#include "vdb/vdb.h"

namespace sweepers {

struct GridSpec {
    double voxelSize = 0.02;
    double halfWidth = 3.0; // in voxels
    // Whether the script gave them (a VDB start, which keeps its own grid, must then agree).
    bool voxelSizeGiven = false, halfWidthGiven = false;
};

struct StartShape {
    enum class Kind { Sphere, Vdb, Mesh };
    Kind kind = Kind::Sphere;
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    double radius = 1.0;
    std::string file;     // as written in the script (relative to it)
    std::string gridName; // of a VDB start: the level set to take (empty: the first usable)
};

enum class ToolShapeKind { Ball, Ellipsoid, Baked };

// Where a baked tool (3.4.3) comes from: a level set in a .vdb file or a closed mesh.
struct BakedToolSource {
    enum class Kind { Vdb, Mesh };
    Kind kind = Kind::Vdb;
    std::string file;       // as written in the script (relative to it)
    std::string gridName;   // of a .vdb: the level set to take (empty: the first usable)
    double voxelSize = 0.0; // of a mesh: the sampling of its distance, in its own units
};

struct ToolSpec {
    ToolShapeKind shape = ToolShapeKind::Ball;
    // Ball: the radius, three times. Ellipsoid: the semi-axes. Baked: the uniform scale,
    // three times.
    Eigen::Vector3d size = Eigen::Vector3d::Constant(0.3);
    double falloff = 0.3;
    std::vector<Placement> path;
    BakedToolSource source;
    // A baked tool's shape at its size, as loaded by io/ (the file is read when the script
    // is, so every run of a script, at any voxel size, sculpts with the same tool).
    std::shared_ptr<const ToolShape> baked;
};

// N copies of a stroke, turned about the axis through the centre by multiples of 360/N
// degrees (1: the stroke alone). A sweep's copies are tools swept together with its own;
// a swirl's, an inflation's and a smooth dab's are applied one after another.
struct RadialSymmetry {
    Eigen::Vector3d axis = Eigen::Vector3d::UnitY();
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    int count = 1;
    // Copy k: the turn by k 360/N degrees about the axis through the centre.
    Eigen::Affine3d turn(int k) const;
};

// A stroke's strength (0, 1]: the fraction of the hand's motion a sweep applies, of a
// swirl's move, of an inflation's radius. 1 applies them as they are.
struct SweepStroke {
    MirrorAxis mirror = MirrorAxis::None;
    std::vector<ToolSpec> tools;
    double strength = 1.0;
    RadialSymmetry radial{};
};

struct SwirlStroke {
    Eigen::Vector3d at = Eigen::Vector3d::Zero();
    Eigen::Vector3d move = Eigen::Vector3d::Zero();
    double radius = 0.3;
    SwirlRing ring = SwirlRing::Discrete;
    int swirls = 8;
    double ball = 0.0; // > 0: star-shaped swirl carrying a ball of this radius (4.19)
    double strength = 1.0;
    RadialSymmetry radial{};
};

// remove: the ball is sucked back into its centre instead (2.31, the inverse inflation):
// clay taken away.
struct InflateStroke {
    Eigen::Vector3d at = Eigen::Vector3d::Zero();
    double radius = 0.1;
    double strength = 1.0;
    bool remove = false;
    RadialSymmetry radial{};
};

struct PinchStroke : PinchSpec {};
struct StrangleStroke : StrangleSpec {};

// A tool held in the modeling space whose target placement is keyed over time (3.6.1, the
// first technique; Figure 3.23): at time t of the stroke, the shape it started from is
// deformed by one sweep of the tool from its rest placement (the first key) to the keyed
// placement at t. A grab that follows a curve, and lets go as the curve comes back.
struct KeyframedStroke {
    ToolSpec tool; // its path: the keys' placements
    Keyframes keys;
};

// A sweep defined in a local frame, and the frame keyed over time (3.6.1, the second
// technique; Figure 3.25): at time t of the stroke, the sweep with every placement taken
// through the frame at t (a bulge moving along a pipe). Frames scale uniformly.
struct SlideStroke {
    SweepStroke local;
    Keyframes frame;
};

// The shape carried by a velocity field (deform/flow.h) from time `from` to `to`, in
// `segments` resamples; 0: the fewest the advection can follow (flowSegments, measured on the
// surface as it is when the stroke comes).
struct FlowStroke {
    FieldSpec field;
    double from = 0.0, to = 1.0;
    int segments = 0;
};

// A ball of `radius` moved along `path` through the shape as through an incompressible fluid
// (deform/swept_fluid.h): one resample a path segment, each the steps of 4.26 chained.
// strength: the ball goes that fraction of the way along the path, each point taken that
// fraction of the way from the first (the hand's path, drawn in toward where it began).
struct FluidStroke {
    double radius = 0.3;
    std::vector<Eigen::Vector3d> path; // two points or more, no two successive ones equal
    double strength = 1.0;
    // The path the ball follows: p_0 + strength (p_k - p_0).
    std::vector<Eigen::Vector3d> ballPath() const;
    // The solution it sweeps, found by io/ (io/fluid_cache.h) when the script is read.
    std::shared_ptr<const SweptFluid> fluid;
};

// A smooth dab's strength may reach past 1 (a flow time longer than the default dab's):
// up to this.
inline constexpr double kMostSmoothStrength = 10.0;

// Smoothing under a ball: one dab at each placement of the tool's path (its translation; the
// radius and falloff are the tool's), each a mean-curvature flow (levelset/smooth.h) lasting
// strength x kSmoothTimePerRadius2 x radius^2. The velocity is the surface's own curvature,
// so each dab runs on the grid the one before left: its plan holds dabs, no deformation
// (sculpt/stroke_plan.h), and a history holding one has no exact reference.
struct SmoothStroke {
    ToolSpec tool;           // a ball
    double strength = 1.0;   // (0, kMostSmoothStrength]
    RadialSymmetry radial{}; // each dab's copies follow it
};

using Stroke = std::variant<SweepStroke, SwirlStroke, InflateStroke, PinchStroke, StrangleStroke,
                            KeyframedStroke, SlideStroke, FlowStroke, FluidStroke, SmoothStroke>;

struct StrokeScript {
    int version = 1;
    GridSpec grid;
    StartShape start;
    std::vector<Stroke> strokes;
    // The seconds each stroke lasts when the script is played as a film (sculpt/film.h), by
    // stroke; 0 or missing where the script does not say.
    std::vector<double> durations;
};

// Dab k of a smooth stroke as a brush (the dabs at each placement: the placement's, then
// its radial copies).
SmoothBrush smoothDab(const SmoothStroke& stroke, std::size_t k);

// The deformation a sweep stroke describes. Throws std::invalid_argument for a baked tool
// that was not loaded.
Sweep toSweep(const SweepStroke& stroke);
// The swirl ring a swirl stroke describes (radial copy k of it).
SwirlSpec toSwirl(const SwirlStroke& stroke, int copy = 0);

// Whether the stroke is keyed over time (keyframed, slide), and then how long it lasts (its
// last key's time); 0 for other strokes.
double keyedDuration(const Stroke& stroke);

// The deformations a keyed stroke makes at `time` of its own clock (empty where it is the
// identity, as a keyframed tool at rest). Throws std::invalid_argument for another stroke.
std::vector<std::unique_ptr<SweepSegment>> planKeyedStroke(const Stroke& stroke, double time);

// How many steps planStroke (sculpt/stroke_plan.h) makes of a stroke at the given voxel size
// (a sweep's segments, a pinch's or a strangle's segments and its pull, a flow's segments
// when it gives them, a smooth stroke's dabs, else one), without planning it.
std::size_t segmentCount(const Stroke& stroke, double voxelSize);

} // namespace sweepers
