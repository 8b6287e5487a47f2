// Small vector type used throughout: Eigen's fixed 3-vector (SI units).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace granary {
using Vec3 = Eigen::Vector3d;
}  // namespace granary
