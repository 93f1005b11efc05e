#pragma once
/// @file
/// A lower bound of the Euclidean distance between two oriented boxes, for the distance queries
/// (distance.hpp): it never exceeds the true distance between the boxes (so never the distance
/// between anything inside them), and is 0 when they overlap.
///
/// Three bounds from the separating-axis view (Gottschalk et al. 1996), the largest is returned:
///  - B's axis-aligned bounding box in A's box frame against A: the per-axis gaps combined
///    Euclidean-ly (sqrt of the sum of squares), since B lies inside that box;
///  - the same with the roles swapped (A's bounding box in B's frame);
///  - the 9 edge-edge axes A_i x B_j: the projected gap divided by the axis' length.
/// The projected radii use |R| + kSatEpsilon as obb_overlap() does, which only enlarges them, so
/// every gap is an under-estimate; the caller subtracts its own rounding allowance.
#include <algorithm>
#include <cmath>

#include "tightbvh/obb.hpp"
#include "tightbvh/obb_overlap.hpp"

namespace tightbvh {

/// The kernel, in obb_overlap()'s frame: A axis-aligned at the origin with half extents `ea`; B
/// with axes the columns of `r`, center `t`, half extents `eb`.
[[nodiscard]] inline double obb_distance_lower_bound(const Mat3& r, const Vec3& t, const Vec3& ea, const Vec3& eb) {
  Mat3 abs_r;
  double in_a = 0.0;  // squared gap of B's bounding box (in A's frame) to A
  for (int i = 0; i < 3; ++i) {
    abs_r(i, 0) = std::abs(r(i, 0)) + kSatEpsilon;
    abs_r(i, 1) = std::abs(r(i, 1)) + kSatEpsilon;
    abs_r(i, 2) = std::abs(r(i, 2)) + kSatEpsilon;
    const double rb = eb[0] * abs_r(i, 0) + eb[1] * abs_r(i, 1) + eb[2] * abs_r(i, 2);
    const double gap = std::abs(t[i]) - ea[i] - rb;
    if (gap > 0.0) in_a += gap * gap;
  }
  double in_b = 0.0;  // squared gap of A's bounding box (in B's frame) to B
  for (int j = 0; j < 3; ++j) {
    const double ra = ea[0] * abs_r(0, j) + ea[1] * abs_r(1, j) + ea[2] * abs_r(2, j);
    const double tj = t[0] * r(0, j) + t[1] * r(1, j) + t[2] * r(2, j);
    const double gap = std::abs(tj) - ra - eb[j];
    if (gap > 0.0) in_b += gap * gap;
  }
  // The edge axes compete in squared form (gap^2 / |axis|^2 against best^2), so that only the
  // winner pays for a square root and a division.
  double best_squared = std::max(in_a, in_b), winner_gap = 0.0, winner_axis = 1.0;
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double ra = ea[i1] * abs_r(i2, j) + ea[i2] * abs_r(i1, j);
      const double rb = eb[j1] * abs_r(i, j2) + eb[j2] * abs_r(i, j1);
      const double gap = std::abs(t[i2] * r(i1, j) - t[i1] * r(i2, j)) - ra - rb;
      if (gap <= 0.0) continue;
      // |A_i x B_j|^2 = 1 - r_ij^2; nearly parallel edges (short axis) keep the unnormalised gap.
      double axis_squared = 1.0 - r(i, j) * r(i, j);
      if (axis_squared <= 1e-6) axis_squared = 1.0;
      if (gap * gap > best_squared * axis_squared) {
        best_squared = gap * gap / axis_squared;
        winner_gap = gap, winner_axis = axis_squared;
      }
    }
  }
  const double best = winner_gap > 0.0 ? winner_gap / std::sqrt(winner_axis) : std::sqrt(best_squared);
  return best;
}

/// Two boxes given in the same frame.
[[nodiscard]] inline double obb_distance_lower_bound(const Obb& a, const Obb& b) {
  const Mat3 r = a.axes.transpose() * b.axes;
  const Vec3 t = a.axes.transpose() * (b.center - a.center);
  return obb_distance_lower_bound(r, t, a.half_extents, b.half_extents);
}

}  // namespace tightbvh
