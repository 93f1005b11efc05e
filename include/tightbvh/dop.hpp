#pragma once
/// @file
/// k-DOPs with fixed direction sets (Sunday, "Bounding Containers", The Bounding Box and The
/// Bounding Diamond): each direction d gives a slab min <= d.x <= max over the points. Directions
/// are the unnormalised integer vectors of Sunday's expressions (x + y - z, ...).
#include <array>
#include <span>

#include "tightbvh/math.hpp"

namespace tightbvh {

/// The direction set of a Dop.
enum class DopKind {
  diamond,  ///< 8-DOP: x+y+z, x+y-z, x-y+z, x-y-z (Sunday's bounding octahedron)
  dop14,    ///< box + diamond (Sunday's cuboctahedron)
  dop18,    ///< box + the 6 edge directions x+-y, x+-z, y+-z
  dop26,    ///< box + edge directions + diamond
};

/// Number of directions (k / 2) of a kind.
[[nodiscard]] int dop_axes(DopKind kind);
/// Direction i (0 <= i < dop_axes(kind)) of a kind.
[[nodiscard]] Vec3 dop_direction(DopKind kind, int i);

/// A k-DOP: the intersection of the slabs min[i] <= dop_direction(kind, i).dot(p) <= max[i].
struct Dop {
  static constexpr int max_axes = 13;  ///< The most directions of any kind (dop26).
  DopKind kind = DopKind::dop14;       ///< The direction set.
  std::array<double, max_axes> min{};  ///< slab i: min[i] <= dop_direction(kind, i).dot(p) <= max[i]
  std::array<double, max_axes> max{};  ///< slab i's upper end (see min)

  /// The number of directions of `kind` (the slabs in use: min[0 .. axes())).
  [[nodiscard]] int axes() const { return dop_axes(kind); }
  /// Closed containment; `tolerance` is an absolute distance (scaled by each direction's length).
  [[nodiscard]] bool contains(const Vec3& p, double tolerance = 0.0) const;
  /// The exact volume of the polytope the slabs define (half-space intersection; redundant
  /// slabs are fine; 0 for a flat polytope).
  [[nodiscard]] double volume() const;
};

/// Slab extremes over the points. Throws InputError `"dop: empty point set"` or
/// `"dop: point i has a non-finite coordinate (NaN or Inf)"`.
[[nodiscard]] Dop bounding_dop(std::span<const Vec3> points, DopKind kind);

/// Separating-slab test (Sunday: disjoint if one slab's max is below the other's min); both in the
/// same frame. Throws InputError when the kinds differ. A conservative test: true may be returned
/// for disjoint polytopes that no common slab direction separates.
[[nodiscard]] bool overlaps(const Dop& a, const Dop& b);

}  // namespace tightbvh
