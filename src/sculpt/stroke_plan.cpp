// SPDX-License-Identifier: Apache-2.0
#include "sculpt/stroke_plan.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <openvdb/tools/Interpolation.h>

#include "core/format.h"
#include "core/limits.h"
#include "deform/inflate.h"
#include "levelset/band.h"

namespace sweepers {

namespace {

// Peak resident memory per band voxel an inflation adds, while it is applied (the new band,
// the sampled band's copies and the fill's marks), with headroom.
constexpr double kInflationBytesPerVoxel = 400.0;

// Where an inflation planned at `centre` is centred (inflate.h says why): a centre just
// outside the surface, within the band, moves onto the surface along the normal (a few Newton
// steps on the distance the grid holds); any other is kept.
Eigen::Vector3d ontoSurface(const Grid& grid, const Eigen::Vector3d& centre) {
    const double h = grid.voxelSize()[0], band = halfWidthOf(grid) * h;
    const Grid::ConstAccessor acc = grid.getConstAccessor();
    const openvdb::tools::GridSampler<Grid::ConstAccessor, openvdb::tools::BoxSampler> sample(
        acc, grid.transform());
    const auto at = [&](const Eigen::Vector3d& p) { return double(sample.wsSample(toVdb(p))); };
    Eigen::Vector3d c = centre;
    double d = at(c);
    if (d >= 0.999 * band) return c;
    for (int step = 0; step < 4 && d > 0.0; ++step) {
        Eigen::Vector3d g;
        for (int a = 0; a < 3; ++a) {
            const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(a);
            g[a] = (at(c + e) - at(c - e)) / (2.0 * h);
        }
        if (!(g.norm() > 1e-6)) break;
        c -= d / g.squaredNorm() * g;
        d = at(c);
    }
    return c;
}

// Plans one stroke at voxel size h, on `shape` when there is one (apply), else ahead of it
// (check): the one place where a stroke kind becomes steps.
class StrokePlanner {
  public:
    StrokePlanner(double h, const Grid* shape) : h_(h), shape_(shape) {}

    std::vector<PlannedStep> run(const Stroke& stroke) {
        if (const auto* s = std::get_if<SweepStroke>(&stroke)) {
            const Sweep sweep = toSweep(*s);
            for (std::size_t k = 0; k < sweep.segmentCount(); ++k)
                addSweep("sweep", std::make_unique<SweepSegment>(sweep, k));
        } else if (const auto* s = std::get_if<SwirlStroke>(&stroke)) {
            swirl(*s);
        } else if (const auto* s = std::get_if<InflateStroke>(&stroke)) {
            inflate(*s);
        } else if (const auto* s = std::get_if<PinchStroke>(&stroke)) {
            for (auto& part : planPinch(*s, h_)) {
                const bool pull = part->tears();
                add(pull ? "pinch pull" : "pinch needles", std::move(part), pull ? 1 : 2);
            }
        } else if (const auto* s = std::get_if<StrangleStroke>(&stroke)) {
            for (auto& part : planStrangle(*s, h_)) {
                const bool pull = part->tears();
                add(pull ? "strangle pull" : "strangle noose", std::move(part), 1);
            }
        } else if (const double duration = keyedDuration(stroke); duration > 0.0) {
            // As a keyed stroke ends: at its last key.
            const char* kind =
                std::holds_alternative<KeyframedStroke>(stroke) ? "keyframed" : "slide";
            for (auto& part : planKeyedStroke(stroke, duration))
                addSweep(kind, std::move(part));
        } else if (const auto* s = std::get_if<FlowStroke>(&stroke)) {
            flow(*s);
        } else if (const auto* s = std::get_if<FluidStroke>(&stroke)) {
            fluid(*s);
        } else if (const auto* s = std::get_if<SmoothStroke>(&stroke)) {
            // Not a deformation: each dab relaxes the surface the one before left.
            for (std::size_t k = 0; k < s->tool.path.size() * std::size_t(s->radial.count); ++k)
                next("smooth").dab = smoothDab(*s, k);
        }
        return std::move(steps_);
    }

  private:
    PlannedStep& next(std::string kind) {
        PlannedStep& step = steps_.emplace_back();
        step.segment = steps_.size() - 1;
        step.kind = std::move(kind);
        return step;
    }

    PlannedStep& add(std::string kind, std::shared_ptr<const StepDeformation> deformation,
                     std::size_t tools) {
        PlannedStep& step = next(std::move(kind));
        step.subSteps = deformation->steps();
        step.affected = deformation->affectedBox();
        step.tools = tools;
        step.deformation = std::move(deformation);
        return step;
    }

    void addSweep(const char* kind, std::shared_ptr<const SweepSegment> segment) {
        const std::size_t tools = segment->toolCount();
        const double bound = segment->stepBound();
        add(kind, std::move(segment), tools).bound = bound;
    }

    // A step whose deformation the shape decides, planned ahead.
    void leftToShape(const char* kind) {
        PlannedStep& step = next(kind);
        step.tools = 1;
        step.leftToShape = true;
    }

    // A swirl carrying a ball and an inflation reach the whole shape (found by walking the
    // grid: only for those two).
    Box reach() const { return activeWorldBox(*shape_).expanded(2 * h_); }

    void swirl(const SwirlStroke& s) {
        for (int k = 0; k < s.radial.count; ++k) {
            if (s.ball <= 0.0)
                add("swirl", std::make_unique<SwirlSegment>(toSwirl(s, k)), 1);
            else if (shape_)
                add("star-shaped swirl", starShapedSwirl(toSwirl(s, k), s.ball, reach()), 1);
            else
                leftToShape("star-shaped swirl");
        }
    }

    void inflate(const InflateStroke& s) {
        const char* kind = s.remove ? "remove" : "inflate";
        if (!shape_) {
            for (int k = 0; k < s.radial.count; ++k)
                leftToShape(kind);
            return;
        }
        // Planned on the shape as it is before the first copy: each copy may grow it by its
        // ball, which the later copies' reach takes in.
        const double rho = s.strength * s.radius, halfWidth = halfWidthOf(*shape_);
        const Box around = reach().expanded(2.0 * rho * (s.radial.count - 1));
        const InflationFill fill{halfWidth * h_};
        if (!s.remove) {
            // Each ball's surface joins the band: far larger a ball than the shape makes the
            // grid far larger than it was. (The grid there is already has its memory.)
            const double voxels =
                s.radial.count * 4.0 * M_PI * rho * rho / (h_ * h_) * 2.0 * halfWidth;
            requireMemory(voxels * kInflationBytesPerVoxel,
                          "an inflation of radius " + formatNumber(rho),
                          formatNumber(voxels) + " band voxels at voxel size " + formatNumber(h_));
        }
        for (int k = 0; k < s.radial.count; ++k) {
            const Eigen::Vector3d at = s.radial.turn(k) * s.at;
            add(kind,
                std::make_unique<Inflation>(s.remove ? at : ontoSurface(*shape_, at), rho, around,
                                            s.remove, fill),
                1);
        }
    }

    void flow(const FlowStroke& s) {
        const auto field = makeField(s.field);
        const std::string kind = "flow (" + fieldName(s.field.kind) + ")";
        if (s.segments == 0 && !shape_) {
            // The segment count is measured on the surface as the stroke finds it: ahead of
            // it, the whole span's sub-steps and box.
            const auto whole = planFlow(field, s.from, s.to, 1);
            PlannedStep& step = next(kind);
            step.subSteps = whole.front()->steps();
            step.affected = whole.front()->affectedBox();
            step.leftToShape = true;
            return;
        }
        const int n = s.segments > 0
                          ? s.segments
                          : flowSegments(*field, s.from, s.to, surfacePoints(*shape_, 512));
        for (auto& part : planFlow(field, s.from, s.to, n))
            add(kind, std::move(part), 0);
    }

    void fluid(const FluidStroke& s) {
        if (!s.fluid) throw std::invalid_argument("the swept fluid was not solved");
        const std::vector<Eigen::Vector3d> path = s.ballPath();
        for (std::size_t k = 0; k + 1 < path.size(); ++k) {
            const int chained = sweptFluidSteps(*s.fluid, s.radius, path[k], path[k + 1]);
            PlannedStep& step =
                add("fluid", sweptFluidSegment(*s.fluid, s.radius, path[k], path[k + 1]), 1);
            step.fluidSteps = chained;
            if (!shape_) continue;
            // Each flow step resamples the band its segment reaches: at most the whole band,
            // at most the voxels of the segment's box.
            const Eigen::Vector3d extent = (step.affected.max - step.affected.min) / h_;
            requireWork(chained * std::min(double(shape_->activeVoxelCount()), extent.prod()),
                        "fluid segment " + std::to_string(k + 1) + " of radius " +
                            formatNumber(s.radius));
        }
    }

    double h_;
    const Grid* shape_;
    std::vector<PlannedStep> steps_;
};

} // namespace

std::vector<PlannedStep> planStroke(const Grid& shape, const Stroke& stroke) {
    return StrokePlanner(shape.voxelSize()[0], &shape).run(stroke);
}

std::vector<PlannedStep> planStrokeAhead(const Stroke& stroke, double voxelSize) {
    return StrokePlanner(voxelSize, nullptr).run(stroke);
}

} // namespace sweepers
