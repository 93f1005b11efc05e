#pragma once
// Internal: the box kernels over a lane type, with no dependency but <cmath>, so that a
// translation unit compiled for other instructions (box_bounds_avx2.cpp) can instantiate them
// without compiling any shared inline function (Eigen's included) for those instructions: a
// linker may keep any one copy of an inline function, and an AVX2 copy would then run on every
// machine. box_test.hpp loads boxes into lanes and instantiates them for one double and for
// two (SSE2); box_bounds_avx2.cpp for four (AVX2).
#include <cmath>
#include <type_traits>

namespace tightbvh::query_detail {

// One box as the kernel reads it: axes[3 * i + k] = component k of axis i; A's boxes as stored,
// B's mapped into A's frame (MappedBox).
template <class V>
struct LaneBox {
  V axes[9];
  V center[3];
  V half[3];
};

// Lane operations for a plain double (one pair).
inline double lane_abs(double x) { return std::abs(x); }
inline bool lane_gt(double x, double y) { return x > y; }
inline bool all_lanes(bool m) { return m; }
template <class V>
V lane_splat(double x);
template <>
inline double lane_splat<double>(double x) {
  return x;
}
inline double lane_max(double x, double y) { return x > y ? x : y; }
inline double lane_sqrt(double x) { return std::sqrt(x); }
// x <= y ? p : q, lane by lane.
inline double lane_select_le(double x, double y, double p, double q) { return x <= y ? p : q; }

// r = Aa^T Mb, t = Aa^T (cb - ca), lane by lane: in_box_frame(), written out.
template <class V>
inline void lane_relative_frame(const LaneBox<V>& a, const LaneBox<V>& b, V (&r)[3][3], V (&t)[3]) {
  const V diff[3] = {b.center[0] - a.center[0], b.center[1] - a.center[1], b.center[2] - a.center[2]};
  for (int i = 0; i < 3; ++i) {
    const V* ai = &a.axes[3 * i];
    for (int j = 0; j < 3; ++j) {
      const V* bj = &b.axes[3 * j];
      r[i][j] = ai[0] * bj[0] + ai[1] * bj[1] + ai[2] * bj[2];
    }
    t[i] = ai[0] * diff[0] + ai[1] * diff[1] + ai[2] * diff[2];
  }
}

// The edge axis A_i x B_j (unnormalised; r = Aa^T Mb, abs_r = |r| + eps, t as above): the two
// boxes' projected radii and the centers' offset along it, the SAT's table of Gottschalk, Lin &
// Manocha (1996), shared by the box test and the distance bound.
template <class V>
struct EdgeAxis {
  V ra, rb, t;
};
template <class V>
[[nodiscard]] inline EdgeAxis<V> edge_axis(const V* ea, const V* eb, const V (&r)[3][3], const V (&abs_r)[3][3],
                                           const V (&t)[3], int i, int j) {
  const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
  return {ea[i1] * abs_r[i2][j] + ea[i2] * abs_r[i1][j], eb[j1] * abs_r[i][j2] + eb[j2] * abs_r[i][j1],
          t[i2] * r[i1][j] - t[i1] * r[i2][j]};
}

// box_separated: the lanes whose boxes some axis separates by more than `margin` (obb_overlap()'s
// negation, lane by lane). Stops once every lane is separated: the one-pair test (M = bool) checks
// after each axis unless kEachAxis is false; lanes check after A's three face axes, B's three and
// each three edge axes, since with several lanes an early stop is rare and each check is a branch
// that mispredicts. Where it stops does not change the result (more axes only add separated lanes
// to a full mask).
template <class V, class M, bool kEachAxis = std::is_same_v<M, bool>>
[[nodiscard]] inline M box_separated(const LaneBox<V>& a, const LaneBox<V>& b, V margin, V eps) {
  V r[3][3], abs_r[3][3], t[3];
  lane_relative_frame(a, b, r, t);
  const V* ea = a.half;
  const V* eb = b.half;
  M sep;
  // A's face normals.
  for (int i = 0; i < 3; ++i) {
    abs_r[i][0] = lane_abs(r[i][0]) + eps;
    abs_r[i][1] = lane_abs(r[i][1]) + eps;
    abs_r[i][2] = lane_abs(r[i][2]) + eps;
    const V rb = eb[0] * abs_r[i][0] + eb[1] * abs_r[i][1] + eb[2] * abs_r[i][2];
    const M s = lane_gt(lane_abs(t[i]), ea[i] + rb + margin);
    sep = i == 0 ? s : M(sep | s);
    if ((kEachAxis || i == 2) && all_lanes(sep)) return sep;
  }
  // B's face normals.
  for (int j = 0; j < 3; ++j) {
    const V ra = ea[0] * abs_r[0][j] + ea[1] * abs_r[1][j] + ea[2] * abs_r[2][j];
    const V tj = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
    sep = sep | lane_gt(lane_abs(tj), ra + eb[j] + margin);
    if ((kEachAxis || j == 2) && all_lanes(sep)) return sep;
  }
  // Edge-edge axes A_i x B_j.
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const EdgeAxis<V> e = edge_axis(ea, eb, r, abs_r, t, i, j);
      sep = sep | lane_gt(lane_abs(e.t), e.ra + e.rb + margin);
      if ((kEachAxis || j == 2) && all_lanes(sep)) return sep;
    }
  return sep;
}

// ---- Distance lower bound, in lanes ----------------------------------------------------------
// obb_distance_lower_bound() (obb_distance.hpp) written out over the lane type, without branches:
// the per-axis gaps clamped at 0 by max, the edge axes' squared gaps divided by their squared
// lengths and the largest kept. The same bound up to rounding (the root and the division come in
// another order: a relative ~1e-16, far inside the kCompactBoxSlack the caller shrinks it by).
// Branch-free, because in a distance descent whether each axis separates is close to a coin
// toss: a scalar kernel's branches are mispredicted often. Two lanes compute the two child
// pairs of a split at once, as boxes_overlap2 does for collide.
template <class V>
[[nodiscard]] inline V box_distance_bound(const LaneBox<V>& a, const LaneBox<V>& b, V eps) {
  V r[3][3], abs_r[3][3], t[3];
  lane_relative_frame(a, b, r, t);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) abs_r[i][j] = lane_abs(r[i][j]) + eps;
  const V* ea = a.half;
  const V* eb = b.half;
  const V zero = lane_splat<V>(0.0);
  V in_a = zero, in_b = zero;
  for (int i = 0; i < 3; ++i) {
    const V rb = eb[0] * abs_r[i][0] + eb[1] * abs_r[i][1] + eb[2] * abs_r[i][2];
    const V gap = lane_max(lane_abs(t[i]) - ea[i] - rb, zero);
    in_a = in_a + gap * gap;
  }
  for (int j = 0; j < 3; ++j) {
    const V ra = ea[0] * abs_r[0][j] + ea[1] * abs_r[1][j] + ea[2] * abs_r[2][j];
    const V tj = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
    const V gap = lane_max(lane_abs(tj) - ra - eb[j], zero);
    in_b = in_b + gap * gap;
  }
  V best = lane_max(in_a, in_b);
  const V one = lane_splat<V>(1.0), short_axis = lane_splat<V>(1e-6);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const EdgeAxis<V> e = edge_axis(ea, eb, r, abs_r, t, i, j);
      const V gap = lane_max(lane_abs(e.t) - e.ra - e.rb, zero);
      // |A_i x B_j|^2 = 1 - r_ij^2; nearly parallel edges (short axis) keep the unnormalised gap.
      const V axis = one - r[i][j] * r[i][j];
      best = lane_max(best, gap * gap / lane_select_le(axis, short_axis, one, axis));
    }
  }
  return lane_sqrt(best);
}

}  // namespace tightbvh::query_detail
