#pragma once
/// @file
/// Separating-axis test for two oriented boxes (Gottschalk, Lin & Manocha 1996, "OBBTree: A
/// Hierarchical Structure for Rapid Interference Detection", Section 5): the boxes are disjoint
/// iff one of 15 axes separates them: the 3 face normals of each box and the 9 cross products
/// of an edge direction of one with an edge direction of the other.
///
/// Boxes are closed: touching boxes overlap. `margin` (>= 0) is added to the projected radii, so
/// boxes are reported disjoint only if they are separated by more than `margin` along an axis;
/// queries use it to absorb rounding in the transform and the fitters' containment tolerance.
/// kSatEpsilon is added to |R| (Gottschalk et al.): when two edges are (nearly) parallel their
/// cross product is (nearly) zero and the axis test would be decided by rounding noise.
#include <cmath>

#include "tightbvh/obb.hpp"

namespace tightbvh {

/// Added to every |R_ij| of the separating-axis tests (see the file comment).
inline constexpr double kSatEpsilon = 1e-9;

/// The kernel. Box A is axis-aligned at the origin with half extents `ea`; box B has half extents
/// `eb`, its axes are the columns of `r` and its center is `t` (both in A's box frame).
/// Returns true iff the boxes overlap (no axis separates them by more than `margin`).
[[nodiscard]] inline bool obb_overlap(const Mat3& r, const Vec3& t, const Vec3& ea, const Vec3& eb,
                                      double margin = 0.0) {
  Mat3 abs_r;
  // A's face normals.
  for (int i = 0; i < 3; ++i) {
    abs_r(i, 0) = std::abs(r(i, 0)) + kSatEpsilon;
    abs_r(i, 1) = std::abs(r(i, 1)) + kSatEpsilon;
    abs_r(i, 2) = std::abs(r(i, 2)) + kSatEpsilon;
    const double rb = eb[0] * abs_r(i, 0) + eb[1] * abs_r(i, 1) + eb[2] * abs_r(i, 2);
    if (std::abs(t[i]) > ea[i] + rb + margin) return false;
  }
  // B's face normals.
  for (int j = 0; j < 3; ++j) {
    const double ra = ea[0] * abs_r(0, j) + ea[1] * abs_r(1, j) + ea[2] * abs_r(2, j);
    const double tj = t[0] * r(0, j) + t[1] * r(1, j) + t[2] * r(2, j);
    if (std::abs(tj) > ra + eb[j] + margin) return false;
  }
  // Edge-edge axes A_i x B_j.
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double ra = ea[i1] * abs_r(i2, j) + ea[i2] * abs_r(i1, j);
      const double rb = eb[j1] * abs_r(i, j2) + eb[j2] * abs_r(i, j1);
      const double tl = t[i2] * r(i1, j) - t[i1] * r(i2, j);
      if (std::abs(tl) > ra + rb + margin) return false;
    }
  }
  return true;
}

/// Two boxes given in the same frame.
[[nodiscard]] inline bool obb_overlap(const Obb& a, const Obb& b, double margin = 0.0) {
  const Mat3 r = a.axes.transpose() * b.axes;
  const Vec3 t = a.axes.transpose() * (b.center - a.center);
  return obb_overlap(r, t, a.half_extents, b.half_extents, margin);
}

}  // namespace tightbvh
