#pragma once
/// @file
/// Oriented bounding box: center + orthonormal right-handed axes (the columns of `axes`)
/// + half extents along each axis. A point p is inside iff |axes^T (p - center)| <= half_extents.
#include <array>

#include "tightbvh/aabb.hpp"
#include "tightbvh/pose.hpp"

namespace tightbvh {

/// An oriented box in double precision (see the file comment), in whatever frame its points are
/// given.
struct Obb {
  Vec3 center = Vec3::Zero();        ///< The center.
  Mat3 axes = Mat3::Identity();      ///< Orthonormal right-handed columns: the box axes.
  Vec3 half_extents = Vec3::Zero();  ///< Half the side length along each axis (>= 0).

  /// 8 times the product of the half extents.
  [[nodiscard]] double volume() const { return 8.0 * half_extents.prod(); }
  /// `p` in the box frame: its coordinates along the axes, relative to the center.
  [[nodiscard]] Vec3 to_local(const Vec3& p) const { return axes.transpose() * (p - center); }
  /// Closed containment with an absolute tolerance.
  [[nodiscard]] bool contains(const Vec3& p, double tolerance = 0.0) const {
    return (to_local(p).cwiseAbs().array() <= half_extents.array() + tolerance).all();
  }
  /// The 8 corners; bit 0, 1, 2 of the index picks + over - along axis 0, 1, 2.
  [[nodiscard]] std::array<Vec3, 8> corners() const;
  /// The same box after a rigid transform (half extents unchanged).
  [[nodiscard]] Obb transformed(const Pose& pose) const {
    return {pose.apply(center), pose.rotation * axes, half_extents};
  }
};

/// The same box as an Obb (identity axes). `box` not empty.
[[nodiscard]] Obb to_obb(const Aabb& box);

/// The tolerance used when checking that a box contains its input: relative to the box size
/// so that it means the same at 1e-3 and at 1e6 coordinates.
[[nodiscard]] double containment_tolerance(const Obb& box, double relative = 1e-9);

}  // namespace tightbvh
