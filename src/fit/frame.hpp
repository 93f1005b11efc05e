#pragma once
// Internal: boxes from a given orthonormal frame, and frames from one or two directions.
#include <span>

#include "tightbvh/obb.hpp"

namespace tightbvh::fit_detail {

// A right-handed orthonormal frame whose first column is along `v` (v need not be unit).
// Returns the identity when v is zero.
[[nodiscard]] Mat3 frame_from_axis(const Vec3& v);

// Re-orthonormalises the columns of `axes` (Gram-Schmidt, in order) and makes the frame
// right-handed (third column = first x second). Degenerate columns are completed.
[[nodiscard]] Mat3 orthonormalize(const Mat3& axes);

// The tightest box with the given orthonormal right-handed axes containing `points`.
// Projections are taken relative to `origin` (use a point near the set) so that a set far
// from the origin (1e6) keeps its relative precision.
[[nodiscard]] Obb box_with_axes(std::span<const Vec3> points, const Mat3& axes, const Vec3& origin);
// The same, also telling whether every projected coordinate was finite (a NaN/Inf input point,
// or an overflow, makes `finite` false): lets a caller skip a separate finiteness pass.
[[nodiscard]] Obb box_with_axes(std::span<const Vec3> points, const Mat3& axes, const Vec3& origin, bool& finite);

// Whether box `a` is smaller than box `b`: by volume, and by surface area where the volumes are
// rounding noise (flat sets: a patch of coplanar triangles has a zero-volume box in many frames,
// and the volume alone would pick among them at random, not the one of least area). Compares
// volume + 1e-9 * half surface area * L, L the larger half-extent sum of the two: on solid boxes
// the second term is negligible.
[[nodiscard]] bool smaller_box(const Obb& a, const Obb& b);
// That measure for extents (or half extents) `e`: e.prod() + 1e-9 * (half) surface area * length.
[[nodiscard]] inline double box_size_score(const Vec3& e, double length) {
  return e.prod() + 1e-9 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x()) * length;
}

// A point of the set's bounding box center, used as the local origin.
[[nodiscard]] Vec3 local_origin(std::span<const Vec3> points);

}  // namespace tightbvh::fit_detail
