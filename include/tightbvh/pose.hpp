#pragma once
// A rigid transform x -> rotation * x + translation.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tightbvh {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

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
