#include "deform/placement.h"

#include <cmath>

namespace sweepers {

Eigen::Affine3d Placement::matrix() const {
    Eigen::Affine3d X = Eigen::Affine3d::Identity();
    X.translate(t);
    if (hasRotation()) X.rotate(Eigen::AngleAxisd(angleDegrees * M_PI / 180.0, axis.normalized()));
    X.scale(scale);
    return X;
}

} // namespace sweepers
