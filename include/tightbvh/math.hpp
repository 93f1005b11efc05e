#pragma once
/// @file
/// The vector and matrix types of the whole library (Eigen, double precision).
#include <Eigen/Core>

namespace tightbvh {

using Vec2 = Eigen::Vector2d;  ///< A 2D point or vector (projections onto a plane).
using Vec3 = Eigen::Vector3d;  ///< A 3D point or vector.
using Mat3 = Eigen::Matrix3d;  ///< A 3x3 matrix: rotations, and box axes as columns.

}  // namespace tightbvh
