// SPDX-License-Identifier: Apache-2.0
#include "tools/tool_shape.h"

#include <stdexcept>
#include <string>

#include "core/falloff.h"

namespace sweepers {

PlacedTool::PlacedTool(std::unique_ptr<PlacedShape> shape, double falloff)
    : shape_(std::move(shape)), falloff_(falloff) {
    if (!(falloff > 0.0)) throw std::invalid_argument("a tool's falloff must be positive");
    if (falloff > shape_->exactBelow() * (1.0 + 1e-9))
        throw std::invalid_argument("the falloff " + std::to_string(falloff) +
                                    " reaches past the tool's distance band (" +
                                    std::to_string(shape_->exactBelow()) + ")");
    coating_ = shape_->bounds().expanded(falloff);
}

double PlacedTool::influence(const Eigen::Vector3d& p) const {
    if (!coating_.contains(p)) return 0.0;
    return falloffMu(shape_->distanceBelow(p, falloff_), falloff_);
}

void PlacedTool::influences(const Eigen::Vector3d* p, std::size_t n, double* out) const {
    shape_->distancesBelow(p, n, falloff_, out);
    for (std::size_t i = 0; i < n; ++i)
        out[i] = coating_.contains(p[i]) ? falloffMu(out[i], falloff_) : 0.0;
}

} // namespace sweepers
