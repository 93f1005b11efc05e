#pragma once
// Oriented bounding box: center + orthonormal right-handed axes (the columns of `axes`)
// + half extents along each axis. A point p is inside iff |axes^T (p - center)| <= half_extents.
#include <array>

#include "tightbvh/aabb.hpp"
#include "tightbvh/pose.hpp"

namespace tightbvh {

struct Obb {
  Vec3 center = Vec3::Zero();
  Mat3 axes = Mat3::Identity();
  Vec3 half_extents = Vec3::Zero();

  [[nodiscard]] double volume() const { return 8.0 * half_extents.prod(); }
  [[nodiscard]] Vec3 to_local(const Vec3& p) const { return axes.transpose() * (p - center); }
  // Closed containment with an absolute tolerance.
  [[nodiscard]] bool contains(const Vec3& p, double tolerance = 0.0) const {
    return (to_local(p).cwiseAbs().array() <= half_extents.array() + tolerance).all();
  }
  [[nodiscard]] std::array<Vec3, 8> corners() const;
  [[nodiscard]] Obb transformed(const Pose& pose) const {
    return {pose.apply(center), pose.rotation * axes, half_extents};
  }
};

[[nodiscard]] Obb to_obb(const Aabb& box);

// The tolerance used when checking that a box contains its input: relative to the box size
// so that it means the same at 1e-3 and at 1e6 coordinates.
[[nodiscard]] double containment_tolerance(const Obb& box, double relative = 1e-9);

}  // namespace tightbvh
