#pragma once
// The vector and matrix types of the whole library (Eigen, double precision).
#include <Eigen/Core>

namespace tightbvh {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

}  // namespace tightbvh
