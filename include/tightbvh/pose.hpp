#pragma once
// A rigid transform x -> rotation * x + translation.
#include <Eigen/Geometry>

#include "tightbvh/math.hpp"

namespace tightbvh {

struct Pose {
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();

  [[nodiscard]] static Pose identity() { return {}; }
  [[nodiscard]] Vec3 apply(const Vec3& p) const { return rotation * p + translation; }
  [[nodiscard]] Pose inverse() const {
    const Mat3 rt = rotation.transpose();
    return {rt, -(rt * translation)};
  }
  // (a * b).apply(x) == a.apply(b.apply(x))
  [[nodiscard]] friend Pose operator*(const Pose& a, const Pose& b) {
    return {a.rotation * b.rotation, a.rotation * b.translation + a.translation};
  }
};

}  // namespace tightbvh
