#pragma once
/// @file
/// Axis-aligned bounding box.
#include <array>
#include <limits>
#include <span>

#include "tightbvh/pose.hpp"

namespace tightbvh {

/// An axis-aligned box [min, max] (closed), in whatever frame its points are given. The default
/// box is empty.
struct Aabb {
  /// The lowest corner. An empty box (min > max) absorbs nothing: extend() on it gives the first
  /// point.
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());  ///< The highest corner.

  /// Whether the box holds no point (min > max along some axis).
  [[nodiscard]] bool empty() const { return (min.array() > max.array()).any(); }
  /// Grows the box to contain `p`.
  void extend(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  /// The midpoint of min and max (meaningless for an empty box).
  [[nodiscard]] Vec3 center() const { return 0.5 * (min + max); }
  /// max - min: the side lengths (zero for an empty box).
  [[nodiscard]] Vec3 extents() const { return empty() ? Vec3::Zero() : Vec3(max - min); }
  /// The product of the side lengths (0 for an empty box).
  [[nodiscard]] double volume() const { return extents().prod(); }
  /// The length of the diagonal (0 for an empty box).
  [[nodiscard]] double diagonal() const { return extents().norm(); }
  /// Closed containment with an absolute tolerance.
  [[nodiscard]] bool contains(const Vec3& p, double tolerance = 0.0) const {
    return ((p.array() >= min.array() - tolerance) && (p.array() <= max.array() + tolerance)).all();
  }
  /// The 8 corners; bit 0, 1, 2 of the index picks max over min along x, y, z.
  [[nodiscard]] std::array<Vec3, 8> corners() const {
    std::array<Vec3, 8> c;
    for (int i = 0; i < 8; ++i)
      c[i] = Vec3((i & 1) ? max.x() : min.x(), (i & 2) ? max.y() : min.y(), (i & 4) ? max.z() : min.z());
    return c;
  }
  /// The AABB of this box after a rigid transform.
  [[nodiscard]] Aabb transformed(const Pose& pose) const {
    Aabb out;
    if (empty()) return out;
    const Vec3 c = pose.apply(center());
    const Vec3 h = pose.rotation.cwiseAbs() * (0.5 * extents());
    out.min = c - h;
    out.max = c + h;
    return out;
  }
};

/// The smallest axis-aligned box containing `points` (empty when there are none).
[[nodiscard]] inline Aabb bounds_of(std::span<const Vec3> points) {
  Aabb box;
  for (const Vec3& p : points) box.extend(p);
  return box;
}

}  // namespace tightbvh
