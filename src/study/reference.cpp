// SPDX-License-Identifier: Apache-2.0
#include "study/reference.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <openvdb/tools/Interpolation.h>

namespace sweepers {

ExactReference::StartFunction ExactReference::sphere(const Eigen::Vector3d& center, double radius) {
    return [center, radius](const Eigen::Vector3d& p) { return (p - center).norm() - radius; };
}

ExactReference::StartFunction ExactReference::sampled(const GridPtr& start) {
    if (!start) throw std::invalid_argument("ExactReference::sampled: no start grid");
    return [start](const Eigen::Vector3d& p) {
        // One accessor per call keeps the function safe to call from several threads; the
        // sampler keeps a reference to it.
        const Grid::ConstAccessor acc = start->getConstAccessor();
        const openvdb::tools::GridSampler<Grid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
            acc, start->transform());
        return double(sampler.wsSample(toVdb(p)));
    };
}

ExactReference::ExactReference(StartFunction start) : start_(std::move(start)) {
    if (!start_) throw std::invalid_argument("ExactReference: no start shape");
}

void ExactReference::append(std::shared_ptr<const StepDeformation> deformation) {
    if (!deformation) throw std::invalid_argument("ExactReference::append: no deformation");
    fills_ = fills_ || deformation->fills();
    // A fill's value at its centre before it, computed once: every point it fills reads it.
    fromValues_.push_back(deformation->fills() ? value(deformation->filledFrom()) : 0.0);
    latestFirst_.insert(latestFirst_.begin(), history_.size());
    history_.push_back(std::move(deformation));
}

Eigen::Vector3d ExactReference::pullBack(const Eigen::Vector3d& x) const {
    // The last deformation applied is undone first.
    Eigen::Vector3d p = x;
    for (auto it = history_.rbegin(); it != history_.rend(); ++it)
        p = (*it)->inverseMap(p);
    return p;
}

double ExactReference::value(const Eigen::Vector3d& x) const {
    return *valueAlong(latestFirst_, nullptr, x);
}

std::optional<double> ExactReference::valueAlong(const std::vector<std::size_t>& steps,
                                                 const std::vector<Box>* after,
                                                 const Eigen::Vector3d& x) const {
    // Each deformation turns the value found at a point's pre-image into the point's value: the
    // same value, except where it tears space (it adds how deep the point lies in what it
    // opened, tear.h) or fills it (an inflation's ball, from the value its centre had before
    // it: inflate.h). Those are applied from the first deformation on, once the start's value
    // is known; tears alone only add up.
    Eigen::Vector3d p = x;
    if (!fills_) {
        double opened = 0.0;
        for (std::size_t i = 0; i < steps.size(); ++i) {
            const StepDeformation& seg = *history_[steps[i]];
            if (seg.tears()) opened += std::max(0.0, seg.openedDepth(p));
            p = seg.inverseMap(p);
            if (after && !(*after)[i].contains(p)) return std::nullopt;
        }
        return start_(p) + opened;
    }
    std::vector<std::pair<std::size_t, Eigen::Vector3d>> turns; // latest first
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const std::size_t k = steps[i];
        const StepDeformation& seg = *history_[k];
        if (seg.tears() || (seg.fills() && seg.filledBox(fromValues_[k]).contains(p)))
            turns.emplace_back(k, p);
        p = seg.inverseMap(p);
        if (after && !(*after)[i].contains(p)) return std::nullopt;
    }
    double v = start_(p);
    for (auto it = turns.rbegin(); it != turns.rend(); ++it) {
        const StepDeformation& seg = *history_[it->first];
        if (seg.tears()) v += std::max(0.0, seg.openedDepth(it->second));
        if (seg.fills()) v = seg.filledValue(it->second, v, fromValues_[it->first], nullptr);
    }
    return v;
}

ExactReference::Near ExactReference::near(const Box& box) const {
    Near n;
    n.reference_ = this;
    n.box_ = box;
    // Back from the last deformation: one that is the identity on every point the box's points
    // can be at by then is skipped (a tear or a fill is kept: its value changes even where it
    // does not move the point); one that is not grows that bound by what it reaches, as its
    // inverse keeps the points of its affected box inside it.
    Box bound = box;
    for (std::size_t k = history_.size(); k-- > 0;) {
        const StepDeformation& seg = *history_[k];
        if (!seg.tears() && !seg.fills() && seg.identityOn(bound)) continue;
        bound.add(seg.affectedBox());
        n.steps_.push_back(k);
        n.after_.push_back(bound);
    }
    return n;
}

double ExactReference::Near::value(const Eigen::Vector3d& x) const {
    if (box_.contains(x))
        if (const auto v = reference_->valueAlong(steps_, &after_, x)) return *v;
    return reference_->value(x); // a point that left the bound: the whole history
}

namespace {

// The point of [a, b] where `value` changes sign, by bisection to `tolerance` along it.
template <typename Value>
std::optional<Eigen::Vector3d> bisect(const Value& value, const Eigen::Vector3d& a,
                                      const Eigen::Vector3d& b, double tolerance) {
    double lo = 0.0, hi = 1.0;
    const double va = value(a), vb = value(b);
    if (va == 0.0) return a;
    if (vb == 0.0) return b;
    if ((va < 0.0) == (vb < 0.0)) return std::nullopt;
    const bool insideAtLo = va < 0.0;
    // Bisection: phi_ref is continuous but not a distance (a sweep can stretch it by any
    // factor), so only the bracket, not the values, says how far the crossing is.
    const double length = (b - a).norm();
    while ((hi - lo) * length > tolerance && hi - lo > 1e-15) {
        const double mid = 0.5 * (lo + hi);
        const double v = value(a + mid * (b - a));
        if (v == 0.0) return a + mid * (b - a);
        if ((v < 0.0) == insideAtLo)
            lo = mid;
        else
            hi = mid;
    }
    return a + 0.5 * (lo + hi) * (b - a);
}

} // namespace

std::optional<Eigen::Vector3d> ExactReference::crossing(const Eigen::Vector3d& a,
                                                        const Eigen::Vector3d& b,
                                                        double tolerance) const {
    return bisect([this](const Eigen::Vector3d& x) { return value(x); }, a, b, tolerance);
}

std::optional<Eigen::Vector3d> ExactReference::Near::crossing(const Eigen::Vector3d& a,
                                                              const Eigen::Vector3d& b,
                                                              double tolerance) const {
    return bisect([this](const Eigen::Vector3d& x) { return value(x); }, a, b, tolerance);
}

} // namespace sweepers
