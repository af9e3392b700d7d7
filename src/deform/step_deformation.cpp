// SPDX-License-Identifier: Apache-2.0
#include "deform/step_deformation.h"

#include <algorithm>

namespace sweepers {

Eigen::Vector3d StepDeformation::inverseStep(int k, const Eigen::Vector3d& p) const {
    const std::optional<MotionLog> L = stepLog(k, p);
    return L ? (-*L).applyExp(p) : p;
}

Eigen::Vector3d StepDeformation::inverseMap(const Eigen::Vector3d& p) const {
    if (stillAt(p)) return p;
    Eigen::Vector3d q = p;
    for (int k = steps_ - 1; k >= 0; --k)
        q = inverseStep(k, q);
    return q;
}

void StepDeformation::inverseMaps(const Eigen::Vector3d* p, std::size_t n, Eigen::Vector3d* out,
                                  MapScratch&) const {
    for (std::size_t i = 0; i < n; ++i)
        out[i] = inverseMap(p[i]);
}

ForwardResult StepDeformation::forwardStep(int k, const Eigen::Vector3d& q,
                                           double tolerance) const {
    return iterateForward(q, tolerance, forwardMaxIterations_, [&](const Eigen::Vector3d& p) {
        const std::optional<MotionLog> L = stepLog(k, p);
        return L ? L->applyExp(q) : q;
    });
}

void StepDeformation::forwardSteps(int k, const Eigen::Vector3d* q, std::size_t n, double tolerance,
                                   Eigen::Vector3d* out, MapScratch&) const {
    for (std::size_t i = 0; i < n; ++i)
        out[i] = forwardStep(k, q[i], tolerance).p;
}

ForwardResult StepDeformation::forwardMap(const Eigen::Vector3d& p) const {
    ForwardResult r{p, true, 0};
    // Outside the box every inverse sub-step fixes p, and being one-to-one, no other point
    // maps onto it: the forward map fixes it too.
    if (!affected_.contains(p)) return r;
    for (int k = 0; k < steps_; ++k) {
        const ForwardResult s = forwardStep(k, r.p);
        r.p = s.p;
        r.converged = r.converged && s.converged;
        r.iterations = std::max(r.iterations, s.iterations);
    }
    return r;
}

} // namespace sweepers
