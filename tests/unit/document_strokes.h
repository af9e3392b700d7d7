// SPDX-License-Identifier: Apache-2.0
// Strokes a test makes on a Document as the modeler's drags make them.
#pragma once

#include "document/document.h"

namespace sweepers::test {

// A ball tool of radius 0.25 at p.
inline ToolSpec ballAt(const Eigen::Vector3d& p) {
    ToolSpec t;
    t.size = Eigen::Vector3d::Constant(0.25);
    t.falloff = 0.3;
    Placement pl;
    pl.t = p;
    t.path = {pl};
    return t;
}

// A drag of `n` segments from p along d.
inline void drag(Document& doc, const Eigen::Vector3d& p, const Eigen::Vector3d& d, int n) {
    doc.beginStroke(ballAt(p), MirrorAxis::None);
    for (int i = 1; i <= n; ++i) {
        Placement pl;
        pl.t = p + d * (double(i) / n);
        doc.extendStroke(pl);
    }
    doc.endStroke();
}

} // namespace sweepers::test
