#pragma once
// Internal: the wide nodes' layout and their box kernel over a lane type, with no dependency but
// <cstdint>, so that wide_avx2.cpp (compiled for AVX2) can instantiate it without compiling any
// shared inline function for those instructions (box_lanes.hpp says why). wide_nodes.hpp has the
// layout's description, the allowance's derivation, and the four-lane instantiation.
#include <cstdint>

// x86-64 with GCC or Clang: src/collide/CMakeLists.txt compiles wide_avx2.cpp for AVX2 there.
#if defined(__x86_64__) && defined(__GNUC__)
#define TIGHTBVH_WIDE_AVX2 1
#endif

namespace tightbvh::query_detail {

inline constexpr int kWideLanes = 4;

/// One node: up to four child boxes in lanes (wide_nodes.hpp's file comment describes them), in
/// four cache lines.
struct alignas(64) WideNode {
  float axes[9][kWideLanes];       // axes[3 * i + k][lane]: component k of the child's axis i
  float center[3][kWideLanes];     // the child's center minus the node's ref
  float half[3][kWideLanes];       // half extents, widened (widen_box); empty lane: kEmptyHalf
  std::int32_t child[kWideLanes];  // > 0: wide node; < 0: leaf (WideTree::leaf); 0: empty lane
};
static_assert(sizeof(WideNode) == 256, "a wide node is four cache lines");

// An empty lane's half extents: a box of negative size, which every axis separates from anything
// (its projected radius is hugely negative), so the kernel needs no lane mask. The root is never a
// child, so child == 0 marks an empty lane unambiguously.
inline constexpr float kEmptyHalf = -1e30f;

[[nodiscard]] inline bool is_empty_lane(const WideNode& n, int lane) { return n.child[lane] == 0; }

/// One box of A hoisted for the four children of a node of B: M = A^T R0 (in float), B's node ref
/// in A's box frame (tn = A^T d, d = t - ca) and the lane-independent part of the allowance.
struct WideHoisted {
  float m[9];  // m[3 * i + k] = a_i . R0 e_k
  float tn[3];
  float ea[3];
  float kappa;
  float base;  // kappa (sum ea + margin) + 10 u |d|_1 + 4 t_err + margin
};

/// The four boxes of a node of A hoisted at once, in lanes (the descent's hoist_node): lane l holds
/// what WideHoisted holds for the box in lane l of that node, but for tn and base, which move with
/// B's node and are kept per box (WideBoxView).
struct alignas(16) WideHoistedNode {
  float m[9][kWideLanes];   // m[3 * i + k][lane] = a_i . R0 e_k
  float ea[3][kWideLanes];  // half extents
  float kappa = 0.0f;
};

/// One box of a WideHoistedNode (lane `lane`) with its own tn and base, as the kernel reads it.
struct WideBoxView {
  const WideHoistedNode* node;
  int lane;
  const float* tn;  // three floats
  float base;
};

inline constexpr float kUnitRoundoff = 0x1p-24f;  // float's unit roundoff u = 2^-24

/// How many of the 15 axes the kernel tries.
enum class WideTier {
  faces,  // the 6 face axes only (keeps more pairs: a coarser test, still conservative)
  full,   // all 15, in tiers: A's faces, B's faces, then the 9 edge axes if a lane survives
};

// The kernel's inputs in lanes: A's hoisted box (M, tn, ea, kappa, base: WideHoisted) and B's
// children (axes bx, centers cb, half extents eb), one pair per lane.
template <class V>
struct WideLanes {
  V m[9], tn[3], ea[3], kappa, base, center_factor;
  V bx[9], cb[3], eb[3];
};

// What every axis of the kernels reads: R_j = M B_j, T_j = tn + M cb_j, |R_j| and the allowance.
template <class V>
struct WideRelative {
  V r[3][3], abs_r[3][3], t[3], allow;
};
template <class V>
[[nodiscard]] inline WideRelative<V> wide_relative(const WideLanes<V>& l) {
  WideRelative<V> x;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      x.r[i][j] = l.m[3 * i] * l.bx[3 * j] + l.m[3 * i + 1] * l.bx[3 * j + 1] + l.m[3 * i + 2] * l.bx[3 * j + 2];
    x.t[i] = l.tn[i] + (l.m[3 * i] * l.cb[0] + l.m[3 * i + 1] * l.cb[1] + l.m[3 * i + 2] * l.cb[2]);
  }
  x.allow = l.kappa * (lane_abs(x.t[0]) + lane_abs(x.t[1]) + lane_abs(x.t[2]) + (l.eb[0] + l.eb[1] + l.eb[2])) +
            l.center_factor * (lane_abs(l.cb[0]) + lane_abs(l.cb[1]) + lane_abs(l.cb[2])) + l.base;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) x.abs_r[i][j] = lane_abs(x.r[i][j]);
  return x;
}

// wide_relative when A's hoisted M is a signed permutation (an axis-aligned box of A in an identity
// frame: the rays of classify_point_wide): row i of M is s_i e_(p_i). The products and sums of
// wide_relative then have two exact zero terms each, so reading s_i bx_(j, p_i) and adding
// s_i cb_(p_i) gives the same values (up to the sign of a zero, which only ever meets lane_abs or
// a product summed with others), and the kernel the same decisions, without the 36 products.
struct WidePermutation {
  int p[3];
  float s[3];
};
// `signs`: a.s splatted in V's lanes.
template <class V>
[[nodiscard]] inline WideRelative<V> wide_relative_permuted(const WideLanes<V>& l, const WidePermutation& a,
                                                           const V (&signs)[3]) {
  WideRelative<V> x;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) x.r[i][j] = signs[i] * l.bx[3 * j + a.p[i]];
    x.t[i] = l.tn[i] + signs[i] * l.cb[a.p[i]];
  }
  x.allow = l.kappa * (lane_abs(x.t[0]) + lane_abs(x.t[1]) + lane_abs(x.t[2]) + (l.eb[0] + l.eb[1] + l.eb[2])) +
            l.center_factor * (lane_abs(l.cb[0]) + lane_abs(l.cb[1]) + lane_abs(l.cb[2])) + l.base;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) x.abs_r[i][j] = lane_abs(x.r[i][j]);
  return x;
}

// One axis as both kernels weigh it: |L| (the centers' offset along it) and reach = the two
// radii plus the allowance; the axis separates the boxes when offset > reach. The formulas whose
// error the allowance bounds (wide_nodes.hpp), written once.
template <class V>
struct WideAxis {
  V offset, reach;
};
// A's face normal a_i.
template <class V>
[[nodiscard]] inline WideAxis<V> a_face(const WideLanes<V>& l, const WideRelative<V>& x, int i) {
  return {lane_abs(x.t[i]),
          l.ea[i] + (l.eb[0] * x.abs_r[i][0] + l.eb[1] * x.abs_r[i][1] + l.eb[2] * x.abs_r[i][2]) + x.allow};
}
// B's face normal R0 b_j.
template <class V>
[[nodiscard]] inline WideAxis<V> b_face(const WideLanes<V>& l, const WideRelative<V>& x, int j) {
  const V ra = l.ea[0] * x.abs_r[0][j] + l.ea[1] * x.abs_r[1][j] + l.ea[2] * x.abs_r[2][j];
  const V tj = x.t[0] * x.r[0][j] + x.t[1] * x.r[1][j] + x.t[2] * x.r[2][j];
  return {lane_abs(tj), ra + l.eb[j] + x.allow};
}
// The edge axis a_i x R0 b_j (unnormalised).
template <class V>
[[nodiscard]] inline WideAxis<V> edge(const WideLanes<V>& l, const WideRelative<V>& x, int i, int j) {
  const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
  const V ra = l.ea[i1] * x.abs_r[i2][j] + l.ea[i2] * x.abs_r[i1][j];
  const V rb = l.eb[j1] * x.abs_r[i][j2] + l.eb[j2] * x.abs_r[i][j1];
  const V tl = x.t[i2] * x.r[i1][j] - x.t[i1] * x.r[i2][j];
  return {lane_abs(tl), ra + rb + x.allow};
}

// The lanes that some axis separates by more than radius + margin + allowance (the allowance of
// wide_nodes.hpp): R_j = M B_j and T_j = tn + M cb_j, then A's 3 face axes, B's 3 and, unless
// kTier is faces, the 9 edge axes; stops early when every lane is separated. Needs, for V and
// its mask M: + - *, lane_abs, lane_gt (false on NaN), M | M and all_lanes.
template <WideTier kTier, class V, class M>
[[nodiscard]] inline M wide_separated_given(const WideLanes<V>& l, const WideRelative<V>& x) {
  const auto separates = [](const WideAxis<V>& a) { return lane_gt(a.offset, a.reach); };
  // A's face normals.
  M sep = separates(a_face(l, x, 0));
  sep = sep | separates(a_face(l, x, 1));
  sep = sep | separates(a_face(l, x, 2));
  if (all_lanes(sep)) return sep;
  // B's face normals.
  for (int j = 0; j < 3; ++j) sep = sep | separates(b_face(l, x, j));
  if constexpr (kTier == WideTier::faces) return sep;
  if (all_lanes(sep)) return sep;
  // Edge axes A_i x B_j.
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) sep = sep | separates(edge(l, x, i, j));
  return sep;
}
template <WideTier kTier, class V, class M>
[[nodiscard]] inline M wide_separated(const WideLanes<V>& l) {
  return wide_separated_given<kTier, V, M>(l, wide_relative(l));
}

// A lower bound on the distance between A's hoisted box and each lane's box of B (margin 0 in
// the hoisting), before the final factor 1 - kappa that the caller applies (wide_nodes.hpp,
// "The distance bound", derives both). On each of the 15 axes of wide_separated the gap
// g = |L| - (radius + allowance), clamped at 0, is at most the true gap between the boxes'
// projections on that (unnormalised) axis: the allowance bounds the formulas' and the roundings'
// error exactly as for the test. The bound is the largest of sqrt(sum of A's three face gaps
// squared), the same for B's faces, and each edge axis' gap over an upper bound on that axis'
// length, sqrt(len_sq - max(|R_ij| - delta, 0)^2 shrink) (len_sq >= (1 + eta)^2 + 8 u, delta =
// 16 u as R_ij is within 13 u of exact, shrink = 1 - 4 u: set by the caller). Needs, besides
// wide_separated's operations: /, lane_max and lane_sqrt.
template <class V>
[[nodiscard]] inline V wide_bound(const WideLanes<V>& l, V len_sq, V delta, V shrink, V zero) {
  const WideRelative<V> x = wide_relative(l);
  const auto gap = [&](const WideAxis<V>& a) { return lane_max(a.offset - a.reach, zero); };
  V in_a = zero, in_b = zero;
  for (int i = 0; i < 3; ++i) {
    const V g = gap(a_face(l, x, i));
    in_a = in_a + g * g;
  }
  for (int j = 0; j < 3; ++j) {
    const V g = gap(b_face(l, x, j));
    in_b = in_b + g * g;
  }
  V best = lane_max(in_a, in_b);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const V g = gap(edge(l, x, i, j));
      const V s = lane_max(x.abs_r[i][j] - delta, zero);
      best = lane_max(best, g * g / (len_sq - (s * s) * shrink));
    }
  return lane_sqrt(best);
}

// wide_bound's B faces alone: sqrt of the sum of the squared gaps on B's three face axes, a lower
// bound on its own (wide_nodes.hpp, "The distance bound", bounds each of wide_bound's parts), and
// for a point (A's half extents 0) the distance to B's box itself: the closest-point search's
// bound (point_query.cpp). Before the caller's factor 1 - kappa.
template <class V>
[[nodiscard]] inline V wide_point_bound(const WideLanes<V>& l, const WideRelative<V>& x, V zero) {
  V in_b = zero;
  for (int j = 0; j < 3; ++j) {
    const WideAxis<V> a = b_face(l, x, j);
    const V g = lane_max(a.offset - a.reach, zero);
    in_b = in_b + g * g;
  }
  return lane_sqrt(in_b);
}

#ifdef TIGHTBVH_WIDE_AVX2
/// The distance bounds (wide_distance_bounds, wide_nodes.hpp) of two hoisted boxes against the
/// children of a node each, in eight AVX2 lanes (wide_avx2.cpp): bounds[0-3] for h0 and b0,
/// bounds[4-7] for h1 and b1, each lane the four-lane kernel's operations (no FMA), so the same
/// bounds bit for bit. Only where avx2_bounds_available() (box_bounds4.hpp).
void wide_distance_bounds2_avx2(const WideHoisted& h0, const WideNode& b0, const WideHoisted& h1, const WideNode& b1,
                                float len_sq, float factor, float (&bounds)[2 * kWideLanes]);
/// The same for two boxes of nodes of A hoisted in lanes (WideBoxView), bit for bit.
void wide_distance_bounds2_avx2(const WideBoxView& a0, const WideNode& b0, const WideBoxView& a1, const WideNode& b1,
                                float len_sq, float factor, float (&bounds)[2 * kWideLanes]);
#endif

}  // namespace tightbvh::query_detail
