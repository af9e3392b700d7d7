// SPDX-License-Identifier: Apache-2.0
// Seeded random stroke histories: scripts nobody wrote by hand, drawn from every stroke kind
// and option a script accepts, placed near and across the surface of a start shape about a
// unit across (a sphere, a level set read from a .vdb file, or a closed mesh), at voxel
// sizes from 1/32 to 1/80. A history is a stroke script (JSON): what fails can be written
// out, shrunk and kept as a regression test.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "random.h"

namespace sweepers::test {

struct HistoryOptions {
    int fewestStrokes = 4, mostStrokes = 12;
    // Voxel sizes 1/coarsest .. 1/finest.
    int coarsest = 32, finest = 80;
    // Files a start may name (empty: spheres only), and the voxel size of the .vdb's grid (a
    // VDB start keeps its own).
    std::string vdbStart, meshStart;
    double vdbVoxelSize = 0.0;
    // The strokes that take seconds (pinch, strangle) are drawn this often.
    double tearShare = 0.04;
};

class HistoryGenerator {
  public:
    HistoryGenerator(unsigned seed, HistoryOptions options = {}) : rng_(seed), o_(options) {}

    nlohmann::json script() {
        using nlohmann::json;
        const int inverse = int(std::lround(rng_.uniform(o_.coarsest, o_.finest)));
        json out = {{"sweepers", 1}, {"grid", {{"voxel_size", 1.0 / inverse}}}};
        const double start = rng_.uniform(0, 1);
        if (!o_.vdbStart.empty() && start < 0.2) {
            out["start"] = {{"vdb", o_.vdbStart}};
            out["grid"]["voxel_size"] = o_.vdbVoxelSize;
        } else if (!o_.meshStart.empty() && start < 0.4)
            out["start"] = {{"mesh", o_.meshStart}};
        else
            out["start"] = {{"sphere", {{"center", vec(rng_.vec(-0.1, 0.1))}, {"radius", 1.0}}}};
        const int n =
            int(std::lround(rng_.uniform(o_.fewestStrokes - 0.49, o_.mostStrokes + 0.49)));
        json strokes = json::array();
        for (int i = 0; i < n; ++i)
            strokes.push_back(stroke());
        out["strokes"] = strokes;
        return out;
    }

  private:
    static nlohmann::json vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

    bool chance(double p) { return rng_.uniform(0, 1) < p; }
    int integer(int lo, int hi) { return int(std::floor(rng_.uniform(lo, hi + 1 - 1e-9))); }

    // A point of the start's surface, about: every start is about a unit from the origin.
    Eigen::Vector3d surfacePoint(Eigen::Vector3d* normal) {
        *normal = rng_.unit();
        return 0.95 * *normal;
    }
    Eigen::Vector3d tangent(const Eigen::Vector3d& n) {
        Eigen::Vector3d t = rng_.unit();
        t -= t.dot(n) * n;
        return t.norm() < 1e-3 ? n.unitOrthogonal() : t.normalized();
    }

    nlohmann::json radial() {
        return {{"axis", vec(rng_.unit())},
                {"center", vec(Eigen::Vector3d::Zero())},
                {"count", integer(2, 5)}};
    }
    void options(nlohmann::json& s, double radialShare) {
        if (chance(0.3)) s["strength"] = rng_.uniform(0.3, 1.0);
        if (chance(radialShare)) s["radial"] = radial();
    }

    nlohmann::json stroke() {
        const double pick = rng_.uniform(0, 1);
        if (pick < o_.tearShare) return pinch();
        if (pick < 2 * o_.tearShare) return strangle();
        const double kind = rng_.uniform(0, 1); // the others, by their share
        if (kind < 0.32) return sweep();
        if (kind < 0.46) return swirl();
        if (kind < 0.62) return inflate();
        if (kind < 0.74) return fluid();
        if (kind < 0.88) return smooth();
        return flow();
    }

    nlohmann::json placement(const Eigen::Vector3d& t, const Eigen::Vector3d& axis, double degrees,
                             double scale) {
        nlohmann::json p = {{"t", vec(t)}};
        if (degrees != 0.0) p["r"] = {axis.x(), axis.y(), axis.z(), degrees};
        if (scale != 1.0) p["s"] = scale;
        return p;
    }

    nlohmann::json sweep() {
        Eigen::Vector3d n;
        const Eigen::Vector3d p = surfacePoint(&n);
        const int tools = chance(0.7) ? 1 : integer(2, 3);
        const int placements = integer(2, 4);
        const bool turns = chance(0.35), scales = chance(0.25);
        const Eigen::Vector3d axis = rng_.unit();
        // The hand's path, shared by the tools (each offset from it): mostly along the normal,
        // out (a pull) or in (a push), with some sideways drift.
        std::vector<Eigen::Vector3d> path{p + rng_.uniform(-0.2, 0.1) * n};
        const double along = chance(0.7) ? 1.0 : -0.6;
        const Eigen::Vector3d side = tangent(n);
        for (int k = 1; k < placements; ++k)
            path.push_back(path.back() + rng_.uniform(0.05, 0.25) * along * n +
                           rng_.uniform(-0.1, 0.1) * side);
        nlohmann::json list = nlohmann::json::array();
        for (int t = 0; t < tools; ++t) {
            const Eigen::Vector3d offset = t == 0 ? Eigen::Vector3d(Eigen::Vector3d::Zero())
                                                  : Eigen::Vector3d(0.3 * tangent(n));
            nlohmann::json tool = {{"falloff", rng_.uniform(0.2, 0.6)}};
            if (chance(0.7)) {
                tool["shape"] = "ball";
                tool["size"] = rng_.uniform(0.2, 0.45);
            } else {
                tool["shape"] = "ellipsoid";
                tool["size"] = vec(rng_.vec(0.15, 0.4));
            }
            nlohmann::json places = nlohmann::json::array();
            for (int k = 0; k < placements; ++k) {
                const double degrees = turns ? rng_.uniform(-60, 60) : 0.0;
                const double scale = scales ? rng_.uniform(0.7, 1.3) : 1.0;
                places.push_back(placement(path[std::size_t(k)] + offset, axis, degrees, scale));
            }
            tool["path"] = places;
            list.push_back(tool);
        }
        nlohmann::json s = {{"type", "sweep"}, {"tools", list}};
        if (chance(0.2)) s["mirror"] = std::string(1, "xyz"[integer(0, 2)]);
        options(s, 0.15);
        return s;
    }

    nlohmann::json swirl() {
        Eigen::Vector3d n;
        const Eigen::Vector3d p = surfacePoint(&n);
        nlohmann::json s = {{"type", "swirl"}};
        if (chance(0.2)) {
            // Star-shaped: the ball wholly inside the shape, where it is taken and put back.
            const double rho = rng_.uniform(0.1, 0.2);
            s["at"] = vec((0.95 - 2.5 * rho - 0.2) * n);
            s["move"] = vec(rng_.uniform(0.05, 0.2) * n);
            s["ball"] = rho;
            s["radius"] = rng_.uniform(0.3, 0.45);
        } else {
            s["at"] = vec(p + rng_.uniform(-0.1, 0.05) * n);
            s["move"] = vec(rng_.uniform(0.1, 0.4) * n + rng_.uniform(-0.1, 0.1) * tangent(n));
            s["radius"] = rng_.uniform(0.2, 0.4);
        }
        if (chance(0.4)) s["ring"] = "convolution";
        if (chance(0.3)) s["swirls"] = integer(6, 10);
        options(s, 0.15);
        return s;
    }

    nlohmann::json inflate() {
        Eigen::Vector3d n;
        const Eigen::Vector3d p = surfacePoint(&n);
        // A quarter of them centred on the surface, the others about it.
        const Eigen::Vector3d at = chance(0.25) ? n : p + rng_.uniform(-0.3, 0.1) * n;
        nlohmann::json s = {
            {"type", "inflate"}, {"at", vec(at)}, {"radius", rng_.uniform(0.15, 0.4)}};
        if (chance(0.25)) s["remove"] = true;
        options(s, 0.1);
        return s;
    }

    nlohmann::json fluid() {
        Eigen::Vector3d n;
        const Eigen::Vector3d p = surfacePoint(&n);
        const double r = rng_.uniform(0.15, 0.35);
        nlohmann::json path = nlohmann::json::array();
        Eigen::Vector3d at = p + rng_.uniform(-0.1, 0.1) * n;
        const Eigen::Vector3d way = chance(0.5) ? Eigen::Vector3d(-n) : tangent(n);
        path.push_back(vec(at));
        for (int k = integer(1, 2); k > 0; --k) {
            at += rng_.uniform(0.3, 0.8) * r * way;
            path.push_back(vec(at));
        }
        nlohmann::json s = {{"type", "fluid"}, {"radius", r}, {"path", path}};
        if (chance(0.3)) s["strength"] = rng_.uniform(0.3, 1.0);
        return s;
    }

    nlohmann::json smooth() {
        Eigen::Vector3d n;
        const Eigen::Vector3d p = surfacePoint(&n);
        const Eigen::Vector3d side = tangent(n);
        nlohmann::json path = nlohmann::json::array();
        for (int k = integer(1, 3), i = 0; i < k; ++i)
            path.push_back({{"t", vec(p + 0.05 * n + 0.08 * i * side)}});
        nlohmann::json s = {{"type", "smooth"},
                            {"tool",
                             {{"shape", "ball"},
                              {"size", rng_.uniform(0.15, 0.35)},
                              {"falloff", rng_.uniform(0.05, 0.15)},
                              {"path", path}}}};
        options(s, 0.1);
        return s;
    }

    nlohmann::json flow() {
        nlohmann::json rotation = {{"center", vec(rng_.vec(-0.3, 0.3))},
                                   {"axis", vec(rng_.unit())},
                                   {"degrees_per_second", rng_.uniform(20, 90)},
                                   {"radius", rng_.uniform(0.3, 0.6)},
                                   {"falloff", rng_.uniform(0.3, 0.5)}};
        nlohmann::json s = {
            {"type", "flow"}, {"field", {{"rotation", rotation}}}, {"from", 0}, {"to", 1}};
        if (chance(0.5)) s["segments"] = integer(1, 2);
        return s;
    }

    // A hole through the middle, the needles' tips outside the shape on either side.
    nlohmann::json pinch() {
        return {{"type", "pinch"},          {"at", vec(rng_.vec(-0.1, 0.1))},
                {"axis", vec(rng_.unit())}, {"size", 1.3},
                {"falloff", 0.45},          {"open", rng_.uniform(0.25, 0.35)}};
    }

    // The shape cut in two across its middle.
    nlohmann::json strangle() {
        return {{"type", "strangle"},       {"at", vec(rng_.vec(-0.1, 0.1))},
                {"axis", vec(rng_.unit())}, {"size", 1.2},
                {"falloff", 0.3},           {"open", 0.25}};
    }

    Rng rng_;
    HistoryOptions o_;
};

} // namespace sweepers::test
