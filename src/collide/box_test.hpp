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

#include "box_bounds4.hpp"
#include "box_lanes.hpp"
#include "query_workspace.hpp"
#include "tightbvh/compact_box.hpp"
#include "tightbvh/obb_overlap.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh::query_detail {

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

// box_overlap's decision with the early exits of the lanes (after A's three face axes, B's three
// and each three edge axes): fewer branches where the boxes overlap, dearer by up to two axes'
// arithmetic where one of the first separates. For the roots' test before the wide descent, which
// the rest of the query waits for: 1.03-1.04x on the benchmark's separated poses, the same time
// where the roots are apart (docs/design-notes/query-core.md, "The roots' test: kept in double,
// with fewer exits").
[[nodiscard]] inline bool box_overlap_grouped(const CompactBox& a, const MappedBox& mb, const Eigen::Vector3f& eb,
                                              double margin) {
  LaneBox<double> la, lb;
  load_box(la, a);
  load_box(lb, mb, eb);
  return !box_separated<double, bool, false>(la, lb, margin, kSatEpsilon);
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

// Four pairs (A's a[k] against B's mapped mb[k] with half extents eb[k]): four AVX2 lanes when
// `avx2` (avx2_bounds_available(), box_bounds4.hpp), else box_distance_bounds2 twice. Each value
// equals box_distance_bound(a[k], *mb[k], *eb[k]) bit for bit on either path.
[[nodiscard]] inline std::array<double, 4> box_distance_bounds4(const CompactBox* const (&a)[4],
                                                                const MappedBox* const (&mb)[4],
                                                                const Eigen::Vector3f* const (&eb)[4], bool avx2) {
#ifdef TIGHTBVH_AVX2_BOUNDS
  if (avx2) {
    BoundInput pairs[4];
    for (int k = 0; k < 4; ++k)
      pairs[k] = {a[k]->center.data(), a[k]->axes.data(), a[k]->half_extents.data(),
                  mb[k]->axes.data(),  mb[k]->center.data(), eb[k]->data()};
    std::array<double, 4> bounds;
    double out[4];
    box_distance_bounds4_avx2(pairs, kSatEpsilon, out);
    for (int k = 0; k < 4; ++k) bounds[k] = out[k];
    return bounds;
  }
#endif
  (void)avx2;
  const auto lo = box_distance_bounds2(*a[0], *mb[0], *eb[0], *a[1], *mb[1], *eb[1]);
  const auto hi = box_distance_bounds2(*a[2], *mb[2], *eb[2], *a[3], *mb[3], *eb[3]);
  return {lo[0], lo[1], hi[0], hi[1]};
}

// The boxes of the four child pairs of a split of both nodes: A's children's boxes a[0], a[1] (as
// stored) and B's children's mapped into A's frame, mb[0], mb[1], with half extents eb[0], eb[1].
struct ChildBoxes {
  const CompactBox* a[2];
  const MappedBox* mb[2];
  const Eigen::Vector3f* eb[2];
};

// first_hit's descent order (traverse.hpp, sort_nearest_first): the squared distance between A's
// box center and B's mapped box center, in A's frame. Shared by collide() and collide_trace(), so
// that both visit the pairs in one order.
[[nodiscard]] inline double center_gap(const CompactBox& a, const MappedBox& mb) {
  return (mb.center - a.center_d()).squaredNorm();
}

// Those of nodes `na` of A and `nb` of B (both internal); mapped(b) -> B's const MappedBox&.
template <class Mapped>
[[nodiscard]] inline ChildBoxes child_boxes(const Tree& ta, const Tree& tb, const Node& na, const Node& nb,
                                            Mapped&& mapped) {
  return {{&ta.nodes[na.first].box, &ta.nodes[na.first + 1].box},
          {&mapped(nb.first), &mapped(nb.first + 1)},
          {&tb.nodes[nb.first].box.half_extents, &tb.nodes[nb.first + 1].box.half_extents}};
}

#ifdef TIGHTBVH_AVX2_BOUNDS
[[nodiscard]] inline CrossInput cross_input(const ChildBoxes& c) {
  return {{c.a[0]->center.data(), c.a[1]->center.data()},
          {c.a[0]->axes.data(), c.a[1]->axes.data()},
          {c.a[0]->half_extents.data(), c.a[1]->half_extents.data()},
          {c.mb[0]->axes.data(), c.mb[1]->axes.data()},
          {c.mb[0]->center.data(), c.mb[1]->center.data()},
          {c.eb[0]->data(), c.eb[1]->data()}};
}
#endif

// The four pairs of `c` in both_children's order (traverse.hpp; `a_major`: a0 b0, a0 b1, a1 b0,
// a1 b1, else a0 b0, a1 b0, a0 b1, a1 b1) as two two-lane calls: {(first, second), (third, fourth)}.
template <class TwoPairs>
[[nodiscard]] inline auto two_by_two(const ChildBoxes& c, bool a_major, TwoPairs&& two) {
  const int a1 = a_major ? 0 : 1, b1 = a_major ? 1 : 0;  // pair 1: (a[a1], b[b1]); pair 2 the other
  const auto lo = two(*c.a[0], *c.mb[0], *c.eb[0], *c.a[a1], *c.mb[b1], *c.eb[b1]);
  const auto hi = two(*c.a[1 - a1], *c.mb[1 - b1], *c.eb[1 - b1], *c.a[1], *c.mb[1], *c.eb[1]);
  return std::array{lo[0], lo[1], hi[0], hi[1]};
}

// The four pairs' box tests, {box_overlap(...)} of each in both_children's order: four AVX2 lanes
// when `avx2` (avx2_bounds_available()), else boxes_overlap2 twice; each lane decides as the
// one-pair test bit for bit on either path.
[[nodiscard]] inline std::array<bool, 4> boxes_overlap_cross(const ChildBoxes& c, bool a_major, double margin,
                                                             bool avx2) {
#ifdef TIGHTBVH_AVX2_BOUNDS
  if (avx2) {
    const int separated = boxes_separated_cross_avx2(cross_input(c), a_major, margin, kSatEpsilon);
    return {(separated & 1) == 0, (separated & 2) == 0, (separated & 4) == 0, (separated & 8) == 0};
  }
#endif
  (void)avx2;
  return two_by_two(c, a_major, [&](const auto&... boxes) { return boxes_overlap2(boxes..., margin); });
}

// The four pairs' distance bounds, box_distance_bound(...) of each in both_children's order: four
// AVX2 lanes when `avx2`, else box_distance_bounds2 twice; equal bit for bit on either path.
[[nodiscard]] inline std::array<double, 4> box_distance_bounds_cross(const ChildBoxes& c, bool a_major, bool avx2) {
#ifdef TIGHTBVH_AVX2_BOUNDS
  if (avx2) {
    double bounds[4];
    box_distance_bounds_cross_avx2(cross_input(c), a_major, kSatEpsilon, bounds);
    return {bounds[0], bounds[1], bounds[2], bounds[3]};
  }
#endif
  (void)avx2;
  return two_by_two(c, a_major, [](const auto&... boxes) { return box_distance_bounds2(boxes...); });
}

}  // namespace tightbvh::query_detail
