// SPDX-License-Identifier: Apache-2.0
// The common shape of every deformation the engine applies: s sub-steps, each defined by
// the closed form of its inverse, p -> exp(-L_k(p)) . p (thesis 5.18, 5.19), with a box
// outside which all of them are the identity. Sweeps (sweep.h) and swirl rings (swirl.h)
// provide L_k; composing inverses, and the forward map by fixed-point iteration
// (INVERTFASTER, 5.4.1), are shared here.
#pragma once

#include <limits>
#include <optional>
#include <vector>

#include "core/box.h"
#include "core/motion_log.h"

namespace sweepers {

// What the batched maps use while they run (inverseMaps, forwardSteps): the caller keeps
// one per thread, so that its storage serves call after call.
struct MapScratch {
    std::vector<std::size_t> which; // the points still moving, or still iterating
    std::vector<double> tolerance;  // forwardSteps: each point's stopping distance
    // The points of `which` in a sub-step's box, and a tool's influence there.
    std::vector<std::size_t> index;
    std::vector<Eigen::Vector3d> points;
    std::vector<double> phi;
};

struct ForwardResult {
    Eigen::Vector3d p;
    bool converged = true;
    int iterations = 0; // largest count over the sub-steps
};

// Where a ray meets the surface of a level set: the least t in [start, most] at which the
// value at from + t * direction (a unit direction) is no longer negative, and the value's
// gradient there; t = `most` and a zero gradient where there is none.
struct SurfaceExit {
    double t = 0.0;
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
};
class SurfaceProbe {
  public:
    virtual ~SurfaceProbe() = default;
    virtual SurfaceExit firstExit(const Eigen::Vector3d& from, const Eigen::Vector3d& direction,
                                  double start, double most) const = 0;
};

class StepDeformation {
  public:
    virtual ~StepDeformation() = default;

    int steps() const { return steps_; }
    // Outside this box every sub-step, and so the whole deformation, is the identity.
    const Box& affectedBox() const { return affected_; }

    // True when every sub-step is the identity on all of `box` (false when unsure): there,
    // sampling the inverse would give back each voxel's own value. By default, when the
    // box misses the affected box.
    virtual bool identityOn(const Box& box) const { return !affected_.overlaps(box); }

    // True when no sub-step moves p (false when unsure): inverseMap then skips them all. By
    // default, when p lies outside the affected box.
    virtual bool stillAt(const Eigen::Vector3d& p) const { return !affected_.contains(p); }

    // Inverse of sub-step k.
    virtual Eigen::Vector3d inverseStep(int k, const Eigen::Vector3d& p) const;
    // Whole inverse: inverse sub-steps s-1 down to 0.
    Eigen::Vector3d inverseMap(const Eigen::Vector3d& p) const;
    // The whole inverse at the n points p, into out (the same values as inverseMap, to the
    // bit): sampling maps a leaf's voxels in one call.
    virtual void inverseMaps(const Eigen::Vector3d* p, std::size_t n, Eigen::Vector3d* out,
                             MapScratch& scratch) const;
    void inverseMaps(const Eigen::Vector3d* p, std::size_t n, Eigen::Vector3d* out) const {
        MapScratch scratch;
        inverseMaps(p, n, out, scratch);
    }
    // Forward sub-step k: the p with inverseStep(k, p) = q, to `tolerance` (relative to
    // 1 + |q|; forwardTolerance() when 0). inverseStep(k, p) = exp(-L(p)) p = q holds
    // exactly when p = exp(L(p)) q, which is iterated on p: a contraction wherever the
    // sub-step is fold-over free.
    virtual ForwardResult forwardStep(int k, const Eigen::Vector3d& q,
                                      double tolerance = 0.0) const;
    // forwardStep(k, q[i], tolerance).p for the n points q, into out (the same values, to
    // the bit): the band's growth maps a run of interface voxels in one call.
    virtual void forwardSteps(int k, const Eigen::Vector3d* q, std::size_t n, double tolerance,
                              Eigen::Vector3d* out, MapScratch& scratch) const;
    void forwardSteps(int k, const Eigen::Vector3d* q, std::size_t n, double tolerance,
                      Eigen::Vector3d* out) const {
        MapScratch scratch;
        forwardSteps(k, q, n, tolerance, out, scratch);
    }
    // Whole forward map: forward sub-steps 0 up to s-1.
    ForwardResult forwardMap(const Eigen::Vector3d& p) const;

    // Whether the deformation tears space open (tear.h; such a deformation has one sub-step):
    // then inverseMap gives a point with no pre-image the torn point it came from, and
    // openedDepth how deep it lies inside the opened region, which the value sampled there
    // gains (its positive part). openedDepth is signed: beyond the opening's rim, minus the
    // distance to it; -infinity for a deformation that does not tear.
    bool tears() const { return tears_; }
    virtual double openedDepth(const Eigen::Vector3d& /*x*/) const {
        return -std::numeric_limits<double>::infinity();
    }
    // A box holding every point whose openedDepth is positive (empty when nothing tears).
    virtual Box openedBox() const { return {}; }
    // How far the tear pushes its torn set open (0 when nothing tears).
    virtual double opening() const { return 0.0; }
    // The least value a distance to the surface can have at p before the deformation, from
    // what the deformation knows of the shape there: a tear's torn set lies outside it (tear.h),
    // so no distance is below minus the distance to that set. -infinity where nothing is known.
    virtual double leastValue(const Eigen::Vector3d& /*p*/) const {
        return -std::numeric_limits<double>::infinity();
    }
    // Whether sampling carries the value it reads inside the opening (the largest along the
    // torn set around a point's pre-image: advect.cpp, resample) past the opening's rim,
    // less the distance to the rim: where the membrane the grid keeps where the surface meets
    // itself reaches past the rim too. False when nothing tears.
    virtual bool windowPastRim() const { return false; }
    // A unit direction along the torn set at the point x was torn from (zero when nothing
    // tears there).
    virtual Eigen::Vector3d alongTorn(const Eigen::Vector3d& /*x*/) const {
        return Eigen::Vector3d::Zero();
    }

    // Whether the deformation fills a region that has no pre-image but one point,
    // filledFrom(), with clay of its own (an inflation's ball, inflate.h; such a deformation
    // has one sub-step). Then the value sampled at x, at its pre-image, becomes
    // filledValue(x, value, fromValue), fromValue the value at filledFrom() before the
    // deformation: a distance to the new surface rather than one value across the region.
    // filledBox(fromValue) holds every point where filledValue differs from the value it is
    // given; where fillsWith(fromValue) is false, it differs nowhere. Below -deepestFill(),
    // fillsWith is false: a grid whose values stop short of that depth must find the depth
    // of filledFrom() below its surface.
    bool fills() const { return fills_; }
    virtual Eigen::Vector3d filledFrom() const { return Eigen::Vector3d::Zero(); }
    virtual bool fillsWith(double /*fromValue*/) const { return false; }
    // `probe`, where given, finds where rays from filledFrom() meet the surface as it was
    // before the deformation (the filled region's value is then the distance along the ray
    // to that crossing's image); without one, a bound from fromValue alone.
    virtual double filledValue(const Eigen::Vector3d& /*x*/, double value, double /*fromValue*/,
                               const SurfaceProbe* /*probe*/) const {
        return value;
    }
    virtual Box filledBox(double /*fromValue*/) const { return {}; }
    virtual double deepestFill() const { return 0.0; }
    // A box holding filledBox(v) for every v, and one holding every point where carriedValue
    // changes a value.
    virtual Box fillReach() const { return {}; }
    virtual Box carriedReach() const { return {}; }
    // A filling deformation squeezes a whole shell around its region into the neighbourhood of
    // filledFrom(), so a value sampled at x's pre-image y varies across the shell far faster
    // than the grid resolves: this gives it as a distance at x to first order, from the
    // value and its gradient g at y (the value over the norm of g carried through the map,
    // J^T g with J the inverse map's Jacobian at x, times the norm of g), where the map
    // stretches much; it gives way to the value itself farther out, and outside
    // carriedReach() is the value itself, as for a deformation that does not fill.
    virtual double carriedValue(const Eigen::Vector3d& /*x*/, double value,
                                const Eigen::Vector3d& /*g*/) const {
        return value;
    }

    double forwardTolerance() const { return forwardTolerance_; }

    // A bound on how far the whole inverse map spreads points apart, as advection measures it
    // (the largest singular value of its Jacobian by central differences over a voxel of any
    // size), which also holds for its first sub-steps alone (StepPrefix); +infinity when none
    // is known. Where the bound asks for no wider band than the
    // grid's, advection does not measure the stretch.
    virtual double stretchBound() const { return std::numeric_limits<double>::infinity(); }

  protected:
    // How far apart two iterates of a forward step from q may be to stop: `tolerance`
    // (forwardTolerance() when 0) relative to 1 + |q|.
    double forwardToleranceAt(const Eigen::Vector3d& q, double tolerance) const {
        return (tolerance > 0.0 ? tolerance : forwardTolerance_) * (1.0 + q.norm());
    }

    // Solves p = next(p) for the p that sub-step k maps back onto q, by fixed-point
    // iteration from q to `tolerance` (relative to 1 + |q|; forwardTolerance() when 0), in
    // at most maxIterations steps (converged false when they run out).
    template <typename Next>
    ForwardResult iterateForward(const Eigen::Vector3d& q, double tolerance, int maxIterations,
                                 const Next& next) const {
        ForwardResult r{q, false, 0};
        const double tol = forwardToleranceAt(q, tolerance);
        for (int it = 1; it <= maxIterations; ++it) {
            const Eigen::Vector3d p = next(r.p);
            const double change = (p - r.p).norm();
            r.p = p;
            r.iterations = it;
            if (change <= tol) {
                r.converged = true;
                break;
            }
        }
        return r;
    }

    // L_k(p); nullopt where sub-step k leaves p in place. Deformations that are not of the
    // form exp(-L(p)) p override inverseStep and forwardStep instead.
    virtual std::optional<MotionLog> stepLog(int /*k*/, const Eigen::Vector3d& /*p*/) const {
        return std::nullopt;
    }

    int steps_ = 1;
    Box affected_;
    double forwardTolerance_ = 1e-12;
    int forwardMaxIterations_ = 500;
    bool tears_ = false;
    bool fills_ = false;
};

} // namespace sweepers
