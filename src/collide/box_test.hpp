#pragma once
// Internal: the box test of collide() and collide_trace(), one pair at a time (box_overlap) or two
// pairs at once (boxes_overlap2: one node against both children of the other node, the two pairs
// a split pushes), in SIMD lanes of doubles.
//
// Both are one template (box_separated) over the lane type: a plain double for one pair, two
// doubles (SSE2, any x86-64) for two. Every lane performs, operation for operation, the same
// arithmetic: B's mapped box in A's box frame (what in_box_frame() computes with Eigen, here
// written out: C = Aa^T M, d = Aa^T (cm - ca), each sum left to right), then obb_overlap()'s 15
// axes with kSatEpsilon and `margin`, in its order. Lanes
// are IEEE operations in the same order (no FMA: nothing here is compiled with -mfma, and SSE2
// mul/add are not contracted), so each lane decides bit for bit as the scalar test does and the
// descent, its first hit and its counts do not depend on which path ran; the exactness argument
// (box_allowance, kCompactBoxSlack) is the scalar one, unchanged. tests/collide/box_test_test.cpp
// checks this against obb_overlap() on random, touching and near-touching box pairs.
// Without SSE2 (other architectures) boxes_overlap2 runs the scalar test twice.
#include <array>
#include <cmath>
#include <cstdint>

#if defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2)
#include <emmintrin.h>
#define TIGHTBVH_BOX_TEST_SSE2 1
#endif

#include "query_workspace.hpp"
#include "tightbvh/compact_box.hpp"
#include "tightbvh/obb_overlap.hpp"

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

// box_separated: the lanes whose boxes some axis separates by more than `margin` (obb_overlap()'s
// negation, lane by lane). Stops at the first axis after which every lane is separated.
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

template <class V, class M>
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
    if (all_lanes(sep)) return sep;
  }
  // B's face normals.
  for (int j = 0; j < 3; ++j) {
    const V ra = ea[0] * abs_r[0][j] + ea[1] * abs_r[1][j] + ea[2] * abs_r[2][j];
    const V tj = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
    sep = sep | lane_gt(lane_abs(tj), ra + eb[j] + margin);
    if (all_lanes(sep)) return sep;
  }
  // Edge-edge axes A_i x B_j.
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const V ra = ea[i1] * abs_r[i2][j] + ea[i2] * abs_r[i1][j];
      const V rb = eb[j1] * abs_r[i][j2] + eb[j2] * abs_r[i][j1];
      const V tl = t[i2] * r[i1][j] - t[i1] * r[i2][j];
      sep = sep | lane_gt(lane_abs(tl), ra + rb + margin);
      if (all_lanes(sep)) return sep;
    }
  }
  return sep;
}

// Loads of one lane (or a broadcast) of the kernel's box.
inline void load_box(LaneBox<double>& out, const CompactBox& box) {
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) out.axes[3 * i + k] = box.axes(k, i);
  for (int k = 0; k < 3; ++k) {
    out.center[k] = box.center[k];
    out.half[k] = box.half_extents[k];
  }
}
inline void load_box(LaneBox<double>& out, const MappedBox& box, const Eigen::Vector3f& half) {
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) out.axes[3 * i + k] = box.axes(k, i);
  for (int k = 0; k < 3; ++k) {
    out.center[k] = box.center[k];
    out.half[k] = half[k];
  }
}

// One pair: A's box `a`, B's box mapped into A's frame `mb` with B's half extents `eb`.
[[nodiscard]] inline bool box_overlap(const CompactBox& a, const MappedBox& mb, const Eigen::Vector3f& eb,
                                      double margin) {
  LaneBox<double> la, lb;
  load_box(la, a);
  load_box(lb, mb, eb);
  return !box_separated<double, bool>(la, lb, margin, kSatEpsilon);
}

#ifdef TIGHTBVH_BOX_TEST_SSE2
// Two lanes of doubles.
struct F64x2 {
  __m128d v;
};
inline F64x2 operator+(F64x2 x, F64x2 y) { return {_mm_add_pd(x.v, y.v)}; }
inline F64x2 operator-(F64x2 x, F64x2 y) { return {_mm_sub_pd(x.v, y.v)}; }
inline F64x2 operator*(F64x2 x, F64x2 y) { return {_mm_mul_pd(x.v, y.v)}; }
struct Mask2 {
  __m128d v;
};
inline Mask2 operator|(Mask2 x, Mask2 y) { return {_mm_or_pd(x.v, y.v)}; }
inline F64x2 lane_abs(F64x2 x) { return {_mm_andnot_pd(_mm_set1_pd(-0.0), x.v)}; }
inline Mask2 lane_gt(F64x2 x, F64x2 y) { return {_mm_cmpgt_pd(x.v, y.v)}; }
inline bool all_lanes(Mask2 m) { return _mm_movemask_pd(m.v) == 3; }

inline F64x2 lanes(double x0, double x1) { return {_mm_set_pd(x1, x0)}; }
inline F64x2 both(double x) { return {_mm_set1_pd(x)}; }
inline F64x2 operator/(F64x2 x, F64x2 y) { return {_mm_div_pd(x.v, y.v)}; }
template <>
inline F64x2 lane_splat<F64x2>(double x) {
  return both(x);
}
inline F64x2 lane_max(F64x2 x, F64x2 y) { return {_mm_max_pd(x.v, y.v)}; }
inline F64x2 lane_sqrt(F64x2 x) { return {_mm_sqrt_pd(x.v)}; }
inline F64x2 lane_select_le(F64x2 x, F64x2 y, F64x2 p, F64x2 q) {
  const __m128d m = _mm_cmple_pd(x.v, y.v);
  return {_mm_or_pd(_mm_and_pd(m, p.v), _mm_andnot_pd(m, q.v))};
}

// Two pairs' boxes in lanes: A's `a0`, `a1`; B's mapped `mb0`, `mb1` with half extents eb0, eb1.
inline void load_lanes(LaneBox<F64x2>& la, LaneBox<F64x2>& lb, const CompactBox& a0, const MappedBox& mb0,
                       const Eigen::Vector3f& eb0, const CompactBox& a1, const MappedBox& mb1,
                       const Eigen::Vector3f& eb1) {
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      la.axes[3 * i + k] = lanes(a0.axes(k, i), a1.axes(k, i));
      lb.axes[3 * i + k] = lanes(mb0.axes(k, i), mb1.axes(k, i));
    }
  for (int k = 0; k < 3; ++k) {
    la.center[k] = lanes(a0.center[k], a1.center[k]);
    la.half[k] = lanes(a0.half_extents[k], a1.half_extents[k]);
    lb.center[k] = lanes(mb0.center[k], mb1.center[k]);
    lb.half[k] = lanes(eb0[k], eb1[k]);
  }
}
#endif

// Two pairs: `a0` and `a1` against B's mapped `mb0`, `mb1` (half extents eb0, eb1). Returns
// {box_overlap(a0, mb0, eb0), box_overlap(a1, mb1, eb1)}. One side is usually the same box
// (a node against both children of the other node).
[[nodiscard]] inline std::array<bool, 2> boxes_overlap2(const CompactBox& a0, const MappedBox& mb0,
                                                        const Eigen::Vector3f& eb0, const CompactBox& a1,
                                                        const MappedBox& mb1, const Eigen::Vector3f& eb1,
                                                        double margin) {
#ifdef TIGHTBVH_BOX_TEST_SSE2
  LaneBox<F64x2> la, lb;
  load_lanes(la, lb, a0, mb0, eb0, a1, mb1, eb1);
  const Mask2 sep = box_separated<F64x2, Mask2>(la, lb, both(margin), both(kSatEpsilon));
  const int bits = _mm_movemask_pd(sep.v);
  return {(bits & 1) == 0, (bits & 2) == 0};
#else
  return {box_overlap(a0, mb0, eb0, margin), box_overlap(a1, mb1, eb1, margin)};
#endif
}

// ---- Distance lower bound, in lanes ----------------------------------------------------------
// obb_distance_lower_bound() (obb_distance.hpp) written out over the lane type, without branches:
// the per-axis gaps clamped at 0 by max, the edge axes' squared gaps divided by their squared
// lengths and the largest kept. The same bound up to rounding (the root and the division come in
// another order: a relative ~1e-16, far inside the kCompactBoxSlack the caller shrinks it by).
// Branch-free, because in a distance descent whether each axis separates is close to a coin
// toss: the scalar kernel's branches were mispredicted often. Two lanes compute the two child
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
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const V ra = ea[i1] * abs_r[i2][j] + ea[i2] * abs_r[i1][j];
      const V rb = eb[j1] * abs_r[i][j2] + eb[j2] * abs_r[i][j1];
      const V gap = lane_max(lane_abs(t[i2] * r[i1][j] - t[i1] * r[i2][j]) - ra - rb, zero);
      // |A_i x B_j|^2 = 1 - r_ij^2; nearly parallel edges (short axis) keep the unnormalised gap.
      const V axis = one - r[i][j] * r[i][j];
      best = lane_max(best, gap * gap / lane_select_le(axis, short_axis, one, axis));
    }
  }
  return lane_sqrt(best);
}

// The distance bound of one pair (A's box `a`, B's box mapped into A's frame `mb`, B's half
// extents `eb`): obb_distance_lower_bound() up to rounding, before the caller's allowance.
[[nodiscard]] inline double box_distance_bound(const CompactBox& a, const MappedBox& mb, const Eigen::Vector3f& eb) {
  LaneBox<double> la, lb;
  load_box(la, a);
  load_box(lb, mb, eb);
  return box_distance_bound<double>(la, lb, kSatEpsilon);
}

// Two pairs: {box_distance_bound(a0, mb0, eb0), box_distance_bound(a1, mb1, eb1)}, each lane
// the scalar's arithmetic (as boxes_overlap2).
[[nodiscard]] inline std::array<double, 2> box_distance_bounds2(const CompactBox& a0, const MappedBox& mb0,
                                                                const Eigen::Vector3f& eb0, const CompactBox& a1,
                                                                const MappedBox& mb1, const Eigen::Vector3f& eb1) {
#ifdef TIGHTBVH_BOX_TEST_SSE2
  LaneBox<F64x2> la, lb;
  load_lanes(la, lb, a0, mb0, eb0, a1, mb1, eb1);
  const F64x2 bound = box_distance_bound<F64x2>(la, lb, both(kSatEpsilon));
  return {_mm_cvtsd_f64(bound.v), _mm_cvtsd_f64(_mm_unpackhi_pd(bound.v, bound.v))};
#else
  return {box_distance_bound(a0, mb0, eb0), box_distance_bound(a1, mb1, eb1)};
#endif
}

}  // namespace tightbvh::query_detail
