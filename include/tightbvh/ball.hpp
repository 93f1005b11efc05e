#pragma once
/// @file
/// Bounding balls (Sunday, "Bounding Containers for Polygons, Polyhedra, and Point Sets", the
/// Bounding Ball and A Fast Approximation): the exact minimum enclosing ball (Welzl 1991 with
/// Gaertner's 1999 pivoting) and Ritter's 1990 two-pass approximation.
#include <numbers>
#include <span>

#include "tightbvh/pose.hpp"

namespace tightbvh {

/// A closed ball: the points within `radius` of `center`.
struct Ball {
  Vec3 center = Vec3::Zero();  ///< The center.
  double radius = 0.0;         ///< The radius (>= 0).

  /// Closed containment with an absolute tolerance.
  [[nodiscard]] bool contains(const Vec3& p, double tolerance = 0.0) const {
    return (p - center).norm() <= radius + tolerance;
  }
  /// 4/3 pi radius^3.
  [[nodiscard]] double volume() const { return 4.0 / 3.0 * std::numbers::pi * radius * radius * radius; }
  /// The same ball after a rigid transform (radius unchanged).
  [[nodiscard]] Ball transformed(const Pose& pose) const { return {pose.apply(center), radius}; }
};

/// Closed balls intersect (touching counts).
[[nodiscard]] inline bool overlaps(const Ball& a, const Ball& b) {
  return (a.center - b.center).norm() <= a.radius + b.radius;
}

/// The exact minimum enclosing ball: Gaertner's pivoting (repeatedly the farthest point enters the
/// support set) over an exact small-ball solver for at most 5 points (Welzl 1991, Section 2: the ball
/// of a set is the circumball of an affinely independent support subset of at most 4 points).
/// Computed relative to a local origin. The radius is finally grown so that every point is inside
/// (contains(p) holds with tolerance 0 for every input point).
/// Throws InputError for an empty set or a non-finite coordinate.
[[nodiscard]] Ball bounding_ball(std::span<const Vec3> points);

/// Ritter's approximation (Sunday's fastBall() in 3D): the initial diameter joins the farthest
/// pair among the x, y, z extreme points, then one pass grows the ball to each outside point.
/// Finally grown like bounding_ball(), so every point is inside. Same errors.
[[nodiscard]] Ball fast_ball(std::span<const Vec3> points);

}  // namespace tightbvh
