#pragma once
/// @file
/// A rigid transform x -> rotation * x + translation.
#include <Eigen/Geometry>

#include "tightbvh/math.hpp"

namespace tightbvh {

/// A rigid transform x -> rotation * x + translation. A mesh's pose maps its mesh frame to the
/// world frame.
struct Pose {
  Mat3 rotation = Mat3::Identity();  ///< A proper rotation (orthonormal, determinant +1).
  Vec3 translation = Vec3::Zero();   ///< Applied after the rotation.

  /// The transform that leaves every point where it is.
  [[nodiscard]] static Pose identity() { return {}; }
  /// rotation * p + translation.
  [[nodiscard]] Vec3 apply(const Vec3& p) const { return rotation * p + translation; }
  /// The inverse transform (rotation transposed).
  [[nodiscard]] Pose inverse() const {
    const Mat3 rt = rotation.transpose();
    return {rt, -(rt * translation)};
  }
  /// Composition: (a * b).apply(x) == a.apply(b.apply(x)).
  [[nodiscard]] friend Pose operator*(const Pose& a, const Pose& b) {
    return {a.rotation * b.rotation, a.rotation * b.translation + a.translation};
  }
};

}  // namespace tightbvh
