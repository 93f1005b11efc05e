#pragma once
// Internal: the query-time node layout in single precision (issue 38) and its box-pair kernel.
//
// Layout. A WideNode holds up to four child boxes, each field an array of four floats (one lane
// per child, structure of arrays), so that one box of A is tested against the four children of a
// node of B from contiguous loads (the W-wide nodes of Embree's BVH4 and Jolt's quad-tree). It is
// built from a binary Tree by collapsing levels: a node's children are its binary descendants
// found by opening the largest internal box until there are four (build_wide). A child reference
// > 0 names a wide node; < 0 is a leaf whose triangles' range in Tree::triangle_order is packed
// into the reference (WideTree::leaf), so no leaf lookup sits in the descent and a node is 256
// bytes, four cache lines; 0 is an empty lane.
//
// Coordinates. Each node has a reference point `ref` (double, in the mesh frame), and its
// children's centers are stored relative to it, so the float offsets stay small far from the
// origin. The root's ref is its box center; a child node's ref is child_ref(parent ref, offset),
// one double addition that the builder and the descent make alike.
//
// Boxes. A stored child box is the parallelepiped
//   P = { ref + c + sum_k t_k a_k : |t_k| <= e_k }        (a_k, c, e_k floats as stored)
// with the float axes a_k orthonormal only to a few float ulps (eta below). It contains the box it
// was built from (widen_box, wide_nodes.cpp, derives the widening). The kernel's separating-axis
// test is sound for parallelepipeds: along any axis n, |n.(cb - ca)| > sum_k ea_k |n.a_k| +
// sum_l eb_l |n.b_l| proves them disjoint. It evaluates the usual orthonormal formulas in float
// and adds an allowance that bounds (1) the formulas' error for axes that are not quite
// orthonormal and (2) the rounding of every float operation, so it never separates two boxes that
// share a point; the derivation is in the allowance section below.
//
// The kernel itself is a template over the lane type (wide_kernel.hpp): four SSE lanes (or four
// plain floats) here, eight AVX2 lanes in wide_avx2.cpp (wide_overlap2, two boxes of A at once).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#if (defined(__SSE2__) || defined(_M_X64)) && !defined(TIGHTBVH_WIDE_PORTABLE)
#include <xmmintrin.h>
#define TIGHTBVH_WIDE_SSE 1
#endif

#include "tightbvh/math.hpp"
#include "tightbvh/obb.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/tree.hpp"
#include "wide_kernel.hpp"

namespace tightbvh::query_detail {

/// A tree in wide nodes; nodes[0] is the root (a root that is itself a leaf gets a node with that
/// one leaf as its only child).
struct WideTree {
  /// A leaf's triangles: triangle_order[first, first + count).
  struct LeafRange {
    std::uint32_t first;
    std::uint32_t count;
  };
  std::vector<WideNode> nodes;
  // A leaf's reference is ~v with v = first << leaf_bits | (count - 1): leaf_bits is the fewest
  // bits that hold the largest leaf's count - 1, unless the first indices need them (then larger
  // leaves are split over lanes holding the same box: build_wide).
  int leaf_bits = 0;
  Vec3 root_ref = Vec3::Zero();  // ref of nodes[0]
  double eta = 0.0;              // max |a_i . a_k - delta_ik| over every stored box's float axes (a bound)
  double ref_bound = 0.0;        // >= |ref|_1 of every node: bounds the rounding of child_ref
  double reach_bound = 0.0;      // >= |ref + c|_inf + 1.01 sum e of every stored box (swap_error's |s|_inf)
  // What bounds a descent's float error in advance (wide_collide.cpp, descent_bounds):
  int depth = 0;              // the most nodes above any node (moves down this tree on any path)
  double path_bound = 0.0;    // >= the sum of |c|_1 over the offsets leading to any node
  double spread = 0.0;        // >= |ref - root_ref|_1 of every node
  double offset_bound = 0.0;  // >= |c|_1 of every stored box's offset

  /// The triangles of the leaf whose child reference is `ref` (< 0).
  [[nodiscard]] LeafRange leaf(std::int32_t ref) const {
    const auto v = static_cast<std::uint32_t>(~ref);
    return {v >> leaf_bits, (v & ((1u << leaf_bits) - 1u)) + 1u};
  }
};

// The ref of child `lane` of a node whose ref is `ref` (the builder and the descent alike).
[[nodiscard]] inline Vec3 child_ref(const Vec3& ref, const WideNode& n, int lane) {
  return {ref[0] + static_cast<double>(n.center[0][lane]), ref[1] + static_cast<double>(n.center[1][lane]),
          ref[2] + static_cast<double>(n.center[2][lane])};
}

/// One box in a node's frame, as the kernel's A side reads it (a lane of a WideNode).
struct WideBox {
  float axes[9];    // axes[3 * i + k]: component k of axis i
  float center[3];  // relative to the node's ref
  float half[3];
};

[[nodiscard]] inline WideBox lane_box(const WideNode& n, int lane) {
  WideBox b;
  for (int r = 0; r < 9; ++r) b.axes[r] = n.axes[r][lane];
  for (int k = 0; k < 3; ++k) {
    b.center[k] = n.center[k][lane];
    b.half[k] = n.half[k][lane];
  }
  return b;
}

/// The float box that contains `box` (double center, axes taken as the generators of the box
/// { c + sum_k s_k a_k : |s_k| <= e_k }), relative to `ref`. `eta` gets max(eta, the stored axes'
/// orthonormality bound). Throws InputError on non-finite input or axes far from orthonormal.
[[nodiscard]] WideBox widen_box(const Obb& box, const Vec3& ref, double& eta);
/// The float box that contains the slab box of `box` ({ x : |a_i . (x - c)| <= e_i }, what a Tree
/// node's box contains its triangles as), relative to `ref`; `eta` as above.
[[nodiscard]] WideBox widen_box(const CompactBox& box, const Vec3& ref, double& eta);

/// The wide tree of `tree` (empty for an empty tree). `sources`, when given, gets for each lane
/// (4 per node) the index of the Tree node whose box it holds (0 for an empty lane).
/// `max_leaf_bits` caps leaf_bits (tests use it to exercise the split of large leaves).
[[nodiscard]] WideTree build_wide(const Tree& tree, std::vector<std::uint32_t>* sources = nullptr,
                                  int max_leaf_bits = 31);

/// Bytes of wide nodes per triangle of `tree`'s mesh (the node array only).
[[nodiscard]] double wide_bytes_per_triangle(const WideTree& wide, std::size_t triangles);

// ---- The query's frame ------------------------------------------------------------------------

/// The relative pose as the kernel reads it: B's mesh frame into A's, x_A = R0 x_B + t0.
struct WideFrame {
  float r0[9];   // R0 rounded to float, r0[3 * l + k] = R0(l, k)
  Mat3 r0_d;     // R0 (double)
  Vec3 t0_d;     // t0 (double)
  float kappa;   // the allowance's relative factor (the allowance section): 8 eta + 24 u
  float margin;  // the query's box margin, rounded up
  // The swapped frame only (wide_frame_swapped; 0 otherwise): what its pose misses of the exact
  // inverse, as an error of B's ref in the hoisted box's frame: swap_rel |p|_inf + swap_abs for a
  // shared point p of the hoisted box (fresh, wide_collide.cpp, adds it to t_err).
  double swap_rel = 0.0;
  double swap_abs = 0.0;
};

/// `rel` maps B's mesh frame into A's; `eta_a`, `eta_b` the trees' eta; `margin` >= 0.
[[nodiscard]] WideFrame wide_frame(const Pose& rel, double eta_a, double eta_b, double margin);

/// The frame with the roles swapped (B's boxes hoisted, A's nodes in the lanes): the pose
/// x_B = R0^T x_A - R0^T t0 and eta over the same axes. Its pose is not R0's exact inverse when
/// R0 is orthonormal only to |R0^T R0 - I|; swap_rel and swap_abs bound what that moves (the
/// derivation is in wide_nodes.cpp).
[[nodiscard]] WideFrame wide_frame_swapped(const Pose& rel, double eta_a, double eta_b, double margin);

/// What the swapped frame's pose adds to t_err for the hoisted box `a` of a node whose ref is
/// `ref` (wide_frame_swapped): swap_rel |s|_inf + swap_abs, with |s|_inf <= |ref|_inf + |c|_inf +
/// 1.01 sum e for any point s of the box; 0 in a forward frame.
[[nodiscard]] inline double swap_error(const WideFrame& f, const Vec3& ref, const WideBox& a) {
  double s_inf = 0.0;
  for (int k = 0; k < 3; ++k) s_inf = std::max(s_inf, std::abs(ref[k]) + std::abs(static_cast<double>(a.center[k])));
  s_inf += 1.01 * (static_cast<double>(a.half[0]) + a.half[1] + a.half[2]);
  return (f.swap_rel * s_inf + f.swap_abs) * (1.0 + 0x1p-50);
}

/// Both frames of a query at once (one |R0^T R0 - I| for the two): the same as wide_frame and
/// wide_frame_swapped.
struct WideFrames {
  WideFrame forward;
  WideFrame swapped;
};
[[nodiscard]] WideFrames wide_frames(const Pose& rel, double eta_a, double eta_b, double margin);

/// One node pair: B's node ref in A's node frame, rounded to float, and a bound on that rounding.
struct WidePair {
  float t[3];
  float t_err;  // >= |t - (R0 ref_b + t0 - ref_a)| in each component
};

[[nodiscard]] WidePair wide_pair(const WideFrame& f, const Vec3& ref_a, const Vec3& ref_b);

// ---- The allowance ----------------------------------------------------------------------------
//
// u = 2^-24 (float's unit roundoff), gamma_n = n u / (1 - n u) (Higham, Accuracy and Stability of
// Numerical Algorithms, §3.1; Handbook of Floating-Point Arithmetic ch. 6; PBRT §6.8): a float sum
// of n products, in any order and with or without fused multiply-adds, is within
// gamma_n sum |a_i b_i| of the exact one. eta bounds |a_i . a_k - delta_ik| for A's stored axes,
// for B's, and for B's axes mapped by R0 (wide_frame: eta_b + 3.1 |R0^T R0 - I|). All vectors
// have components <= 1 + eta, so |a|_1 <= sqrt(3)(1 + eta) < 1.75.
//
// Exact quantities, in A's node frame: D_j = t + R0 cb_j - ca, T_j = A^T D_j, R_j = A^T R0 B_j.
// (1) Formulas for near-orthonormal axes (with G = A^T A = I + E, |E_ik| <= eta):
//   - A's face a_i: true radius of A is sum_k ea_k |G_ik| <= ea_i + eta sum ea; the rest is exact.
//   - B's face R0 b_j: the kernel's offset sum_i T_ij R_ij = D^T A A^T R0 b_j differs from D.R0 b_j
//     by |D^T (A A^T - I) R0 b_j| <= 3 eta |D|_2 (1 + eta) <= 3.1 eta |T|_1 (|D|_2 <=
//     |T|_2 / sqrt(1 - 3 eta)); B's radius as for A's face.
//   - Edge a_i x R0 b_j: the kernel's offset T_i2 R_i1j - T_i1 R_i2j is (a_i1 x a_i2).(R0 b_j x D)
//     (Lagrange's identity), and a_i1 x a_i2 = det(A) A^-T e_i lies within 7 eta of +-a_i
//     (|det A - 1| <= 4.5 eta, |A^-T e_i - a_i| <= |E e_i| / sqrt(1 - 3 eta)); likewise each radius
//     term's cross product: errors <= 7.1 eta (|T|_1 + sum ea + sum eb).
//   So the formulas are off by at most 7.2 eta (|T|_1 + sum ea + sum eb) on any axis.
// (2) Rounding. M = A^T fl(R0): each entry within gamma_4 (1 + eta)^2 < 4.1 u of exact, |M_ik| <=
//   1.02; R_ij = sum_k M_ik b_jk: within delta_R = 13 u. tn = A^T fl(t - ca): within 4.8 u |d|_1 +
//   1.75 t_err; T_j = tn + M cb_j: within err_T = 4.8 u |d|_1 + 1.75 t_err + 7.3 u |cb_j|_1 +
//   u |T_j|_inf. Each axis' offset L combines T with weights sum |R| <= 1.8: within
//   1.8 err_T + (gamma_3 + delta_R) 1.02 |T|_1; each radius (<= 1.02 (sum ea + sum eb), nonnegative
//   terms) within gamma_6 of its value plus delta_R (sum ea + sum eb), the final additions of the
//   allowance and the margin included.
// Together, with margins for the rounding of the allowance itself (a float sum of nonnegative
// terms, low by at most gamma_8 < 1e-6 relative, covered by rounding each constant up):
//   allowance_j = kappa (|T_j|_1 + sum eb_j + sum ea + margin) + 16 u |cb_j|_1 + 10 u |d|_1
//                 + 4 t_err,     kappa = 8 eta + 24 u,
// and a lane is separated only when some axis has |L| > radius + margin + allowance_j. (kappa
// margin: the axes' lengths are 1 +- 3 eta, and margin is a distance.) The kSatEpsilon of
// obb_overlap is not needed: near-parallel edges give a near-zero axis, on which L and the radii
// are near zero and the allowance keeps the pair.
[[nodiscard]] inline WideHoisted hoist(const WideFrame& f, const WidePair& p, const WideBox& a) {
  WideHoisted h;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      h.m[3 * i + k] = a.axes[3 * i] * f.r0[k] + a.axes[3 * i + 1] * f.r0[3 + k] + a.axes[3 * i + 2] * f.r0[6 + k];
  const float d[3] = {p.t[0] - a.center[0], p.t[1] - a.center[1], p.t[2] - a.center[2]};
  for (int i = 0; i < 3; ++i) {
    h.tn[i] = a.axes[3 * i] * d[0] + a.axes[3 * i + 1] * d[1] + a.axes[3 * i + 2] * d[2];
    h.ea[i] = a.half[i];
  }
  const float d1 = std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2]);
  h.kappa = f.kappa;
  h.base =
      f.kappa * (a.half[0] + a.half[1] + a.half[2] + f.margin) + 10.0f * kUnitRoundoff * d1 + 4.0f * p.t_err + f.margin;
  return h;
}

// ---- Lanes ------------------------------------------------------------------------------------

// Portable lanes: four floats, each operation lane by lane (compilers vectorize these loops). They
// are the build's lanes on other architectures than x86-64 or with TIGHTBVH_WIDE_PORTABLE, and
// are always compiled, so that the tests check them against the SSE lanes bit for bit.
struct P4 {
  float v[4];
};
#define TIGHTBVH_WIDE_LANEWISE(op)                         \
  inline P4 operator op(P4 x, P4 y) {                      \
    P4 r;                                                  \
    for (int l = 0; l < 4; ++l) r.v[l] = x.v[l] op y.v[l]; \
    return r;                                              \
  }
TIGHTBVH_WIDE_LANEWISE(+)
TIGHTBVH_WIDE_LANEWISE(-)
TIGHTBVH_WIDE_LANEWISE(*)
TIGHTBVH_WIDE_LANEWISE(/)
#undef TIGHTBVH_WIDE_LANEWISE
inline P4 lane_max(P4 x, P4 y) {
  for (int l = 0; l < 4; ++l) x.v[l] = x.v[l] > y.v[l] ? x.v[l] : y.v[l];
  return x;
}
inline P4 lane_sqrt(P4 x) {
  for (float& f : x.v) f = std::sqrt(f);
  return x;
}
struct PM4 {
  unsigned v;
};
inline PM4 operator|(PM4 x, PM4 y) { return {x.v | y.v}; }
inline P4 lane_abs(P4 x) {
  for (float& f : x.v) f = std::abs(f);
  return x;
}
inline PM4 lane_gt(P4 x, P4 y) {
  unsigned m = 0;
  for (int l = 0; l < 4; ++l) m |= static_cast<unsigned>(x.v[l] > y.v[l]) << l;
  return {m};
}
inline bool all_lanes(PM4 m) { return m.v == 0xFu; }

// What the kernel needs of a lane type besides wide_separated's operations: loads, splats and the
// mask's bits.
template <class V>
struct LaneOps;
template <>
struct LaneOps<P4> {
  using Mask = PM4;
  static P4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
  static P4 splat(float x) { return {{x, x, x, x}}; }
  static void store(float* p, P4 x) {
    for (int l = 0; l < 4; ++l) p[l] = x.v[l];
  }
  static unsigned bits(PM4 m) { return m.v; }
};

#ifdef TIGHTBVH_WIDE_SSE
struct F4 {
  __m128 v;
};
inline F4 operator+(F4 x, F4 y) { return {_mm_add_ps(x.v, y.v)}; }
inline F4 operator-(F4 x, F4 y) { return {_mm_sub_ps(x.v, y.v)}; }
inline F4 operator*(F4 x, F4 y) { return {_mm_mul_ps(x.v, y.v)}; }
inline F4 operator/(F4 x, F4 y) { return {_mm_div_ps(x.v, y.v)}; }
inline F4 lane_max(F4 x, F4 y) { return {_mm_max_ps(x.v, y.v)}; }
inline F4 lane_sqrt(F4 x) { return {_mm_sqrt_ps(x.v)}; }
struct M4 {
  __m128 v;
};
inline M4 operator|(M4 x, M4 y) { return {_mm_or_ps(x.v, y.v)}; }
inline F4 lane_abs(F4 x) { return {_mm_andnot_ps(_mm_set1_ps(-0.0f), x.v)}; }
inline M4 lane_gt(F4 x, F4 y) { return {_mm_cmpgt_ps(x.v, y.v)}; }
inline bool all_lanes(M4 m) { return _mm_movemask_ps(m.v) == 0xF; }
template <>
struct LaneOps<F4> {
  using Mask = M4;
  static F4 load(const float* p) { return {_mm_load_ps(p)}; }
  static F4 splat(float x) { return {_mm_set1_ps(x)}; }
  static void store(float* p, F4 x) { _mm_store_ps(p, x.v); }
  static unsigned bits(M4 m) { return static_cast<unsigned>(_mm_movemask_ps(m.v)); }
};
#else
using F4 = P4;
using M4 = PM4;
#endif

// The build's four lanes (F4) as the descent uses them.
inline F4 splat4(float x) { return LaneOps<F4>::splat(x); }
inline F4 load4(const float* p) { return LaneOps<F4>::load(p); }
inline void store4(float* p, F4 x) { LaneOps<F4>::store(p, x); }

// The kernel's A side: one hoisted box in every lane (WideHoisted, or a box of a node hoisted in
// lanes: WideBoxView).
template <class V>
inline void a_side(WideLanes<V>& l, const WideHoisted& h) {
  using Ops = LaneOps<V>;
  for (int r = 0; r < 9; ++r) l.m[r] = Ops::splat(h.m[r]);
  for (int k = 0; k < 3; ++k) {
    l.tn[k] = Ops::splat(h.tn[k]);
    l.ea[k] = Ops::splat(h.ea[k]);
  }
  l.kappa = Ops::splat(h.kappa);
  l.base = Ops::splat(h.base);
}
template <class V>
inline void a_side(WideLanes<V>& l, const WideBoxView& a) {
  using Ops = LaneOps<V>;
  for (int r = 0; r < 9; ++r) l.m[r] = Ops::splat(a.node->m[r][a.lane]);
  for (int k = 0; k < 3; ++k) {
    l.tn[k] = Ops::splat(a.tn[k]);
    l.ea[k] = Ops::splat(a.node->ea[k][a.lane]);
  }
  l.kappa = Ops::splat(a.node->kappa);
  l.base = Ops::splat(a.base);
}
// The kernel's B side: the four children of `b`, one a lane.
template <class V>
inline void b_side(WideLanes<V>& l, const WideNode& b) {
  using Ops = LaneOps<V>;
  for (int r = 0; r < 9; ++r) l.bx[r] = Ops::load(b.axes[r]);
  for (int k = 0; k < 3; ++k) {
    l.cb[k] = Ops::load(b.center[k]);
    l.eb[k] = Ops::load(b.half[k]);
  }
  l.center_factor = Ops::splat(16.0f * kUnitRoundoff);
}

/// The kernel: A's hoisted box `h` (WideHoisted, or WideBoxView: a box of a node of A hoisted in
/// lanes, bit for bit the same) against the four children of B's node `b`. Returns the mask of
/// lanes kept (bit l: child l may overlap A's box within the margin); empty lanes are never kept.
/// V: the lanes, the build's (F4) or the portable ones (P4), which decide alike bit for bit.
template <WideTier kTier = WideTier::full, class V = F4, class H>
[[nodiscard]] inline unsigned wide_overlap(const H& h, const WideNode& b) {
  using Ops = LaneOps<V>;
  WideLanes<V> l;
  a_side(l, h);
  b_side(l, b);
  return ~Ops::bits(wide_separated<kTier, V, typename Ops::Mask>(l)) & 0xFu;
}

// ---- The distance bound -----------------------------------------------------------------------
//
// The distance search over wide nodes (distance_wide, distance.cpp) bounds the distance between a
// hoisted box of A (hoist, margin 0) and the four children of a node of B from below (wide_bound,
// wide_kernel.hpp). Why it is a lower bound:
//   - On each axis n of the 15, the test's derivation (the allowance section) bounds the error of
//     the offset L and of the radius r against the exact offset and radii of the stored boxes (the
//     parallelepipeds that contain the triangles): g = |L| - (r + allowance) <= the exact gap
//     between their projections on n, whatever n's length; so |n . (y - x)| >= g for every x of A's
//     box and y of B's. The float subtraction |L| - (r + allowance) rounds g up by at most u g.
//   - Faces: with A's axes a_i as the rows of A^T, |A^T v|^2 <= lambda_max(A^T A) |v|^2 <=
//     (1 + 3 eta) |v|^2 (Gershgorin on G = I + E), so |v| >= sqrt(sum g_i^2) / (1 + 1.5 eta); B's
//     mapped axes R0 b_j likewise (eta covers them: wide_frame).
//   - Edges a_i x R0 b_j: |v| >= g / |n|, and |n|^2 = |a_i|^2 |R0 b_j|^2 - (a_i . R0 b_j)^2 <=
//     (1 + eta)^2 - (|R_ij| - 13 u)^2 for the computed R_ij (within delta_R = 13 u of exact, the
//     allowance section); the kernel's len_sq - max(|R_ij| - 16 u, 0)^2 (1 - 4 u) is above that
//     after its own roundings (each product and difference of terms <= 1.1 rounds by <= 1.1 u,
//     which the 8 u in len_sq and the 3 u in delta cover).
//   - The squares, sums, division and root round the result up by at most (1 + u)^8 < 1 + 9 u.
// So bound (1 - kappa), kappa = 8 eta + 24 u >= 1.5 eta + 9 u + the product's own rounding, never
// exceeds the distance between the boxes, and so between the triangles they contain. In the
// swapped frame the swap's shift |E0 s|_inf is in t_err (swap_error) and moves the distance by a
// relative 1.5 e0 at most, inside eta (wide_frame_swapped's eta includes 3.1 e0).
struct WideBoundConstants {
  float len_sq;  // (1 + eta)^2 + 8 u rounded up, eta = kappa / 8 >= the frame's eta
  float factor;  // 1 - kappa
};
[[nodiscard]] inline WideBoundConstants wide_bound_constants(const WideFrame& f) {
  const double eta = static_cast<double>(f.kappa) / 8.0;
  const double len_sq = (1.0 + eta) * (1.0 + eta) + 8.0 * 0x1p-24;
  return {static_cast<float>(len_sq * (1.0 + 0x1p-20)), static_cast<float>(1.0 - static_cast<double>(f.kappa))};
}


/// Lower bounds on the distance between A's hoisted box `h` (hoisted with margin 0; WideHoisted
/// or WideBoxView) and each of the four children of B's node `b`, already multiplied by
/// 1 - kappa: `bounds[l]` never exceeds the distance between the boxes (the derivation above).
/// Empty lanes get a huge bound or +inf.
template <class V = F4, class H>
inline void wide_distance_bounds(const H& h, const WideNode& b, const WideBoundConstants& c,
                                 float (&bounds)[kWideLanes]) {
  using Ops = LaneOps<V>;
  WideLanes<V> l;
  a_side(l, h);
  b_side(l, b);
  const V bound = wide_bound(l, Ops::splat(c.len_sq), Ops::splat(16.0f * kUnitRoundoff),
                             Ops::splat(1.0f - 4.0f * kUnitRoundoff), Ops::splat(0.0f));
  alignas(16) float raw[kWideLanes];
  Ops::store(raw, bound * Ops::splat(c.factor));
  for (int k = 0; k < kWideLanes; ++k) bounds[k] = raw[k];
}

/// wide_overlap for a hoisted box whose M is the signed permutation `a` (wide_relative_permuted):
/// the same mask, bit for bit.
template <class V = F4>
[[nodiscard]] inline unsigned wide_overlap_permuted(const WideHoisted& h, const WidePermutation& a, const WideNode& b) {
  using Ops = LaneOps<V>;
  WideLanes<V> l;
  a_side(l, h);
  b_side(l, b);
  const V signs[3] = {Ops::splat(a.s[0]), Ops::splat(a.s[1]), Ops::splat(a.s[2])};
  return ~Ops::bits(wide_separated_given<WideTier::full, V, typename Ops::Mask>(l, wide_relative_permuted(l, a, signs))) &
         0xFu;
}

/// Lower bounds on the distance from a hoisted point (a box of half extents 0 whose M is the
/// signed permutation `a`, hoisted with margin 0) to each of the four children of `b`
/// (wide_point_bound, times 1 - kappa: `c` of the frame), in `bounds`; empty lanes get a huge
/// bound or +inf.
template <class V = F4>
inline void wide_point_bounds(const WideHoisted& h, const WidePermutation& a, const WideNode& b,
                              const WideBoundConstants& c, float (&bounds)[kWideLanes]) {
  using Ops = LaneOps<V>;
  WideLanes<V> l;
  a_side(l, h);
  b_side(l, b);
  const V signs[3] = {Ops::splat(a.s[0]), Ops::splat(a.s[1]), Ops::splat(a.s[2])};
  const V bound = wide_point_bound(l, wide_relative_permuted(l, a, signs), Ops::splat(0.0f));
  alignas(16) float raw[kWideLanes];
  Ops::store(raw, bound * Ops::splat(c.factor));
  for (int k = 0; k < kWideLanes; ++k) bounds[k] = raw[k];
}

/// hoist(f, wide_pair(f, ref_a, ref_b), a) for a frame `f` that is the identity (wide_frame of
/// Pose::identity()) and a box `a` centered at its ref (center 0), from `hoisted` =
/// hoist(f, {0, 0, 0, 0}, a) (its M, half extents and kappa): wide_pair's t and t_err written out
/// for R0 = I and t0 = 0 (its products by 1 and 0 and additions of 0 are exact, so the same
/// values bit for bit) and hoist's tn and base operation for operation.
[[nodiscard]] inline WideHoisted hoist_identity(const WideFrame& f, const WideHoisted& hoisted, const WideBox& a,
                                               const Vec3& ref_a, const Vec3& ref_b) {
  WideHoisted h = hoisted;
  double err = 0.0;
  float t[3];
  for (int i = 0; i < 3; ++i) {
    const double x = ref_b[i] - ref_a[i];
    t[i] = static_cast<float>(x);
    err = std::max(err, std::abs(x - static_cast<double>(t[i])) +
                            0x1p-50 * (std::abs(ref_b[i]) + std::abs(ref_a[i])) * (1.0 + 0x1p-50));
  }
  const float t_err = static_cast<float>(err * (1.0 + 0x1p-20) + 1e-30);
  const float d[3] = {t[0] - a.center[0], t[1] - a.center[1], t[2] - a.center[2]};
  for (int i = 0; i < 3; ++i) h.tn[i] = a.axes[3 * i] * d[0] + a.axes[3 * i + 1] * d[1] + a.axes[3 * i + 2] * d[2];
  const float d1 = std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2]);
  h.base = f.kappa * (a.half[0] + a.half[1] + a.half[2] + f.margin) + 10.0f * kUnitRoundoff * d1 + 4.0f * t_err + f.margin;
  return h;
}

#ifdef TIGHTBVH_WIDE_AVX2
/// wide_overlap2_avx2 for two hoisted boxes whose M is the signed permutation `a`
/// (wide_overlap_permuted in eight lanes), bit for bit.
[[nodiscard]] unsigned wide_overlap2_permuted_avx2(const WideHoisted& h0, const WideNode& b0, const WideHoisted& h1,
                                                   const WideNode& b1, const WidePermutation& a);
/// Two boxes of A against the four children of a node of B each, in eight AVX2 lanes (wide_avx2.cpp):
/// bits 0-3 are wide_overlap(h0, b0), bits 4-7 wide_overlap(h1, b1), bit for bit (same operations,
/// no FMA). Only where avx2_bounds_available() (box_bounds4.hpp).
[[nodiscard]] unsigned wide_overlap2_avx2(const WideHoisted& h0, const WideNode& b0, const WideHoisted& h1,
                                          const WideNode& b1);
#endif

#ifdef TIGHTBVH_WIDE_AVX2
[[nodiscard]] unsigned wide_overlap2_avx2(const WideBoxView& a0, const WideNode& b0, const WideBoxView& a1,
                                          const WideNode& b1);
#endif

/// wide_overlap(h0, b0) | wide_overlap(h1, b1) << 4: eight AVX2 lanes when `avx2`, else two calls.
/// H is WideHoisted or WideBoxView.
template <class H>
[[nodiscard]] inline unsigned wide_overlap2(const H& h0, const WideNode& b0, const H& h1, const WideNode& b1,
                                            bool avx2) {
#ifdef TIGHTBVH_WIDE_AVX2
  if (avx2) return wide_overlap2_avx2(h0, b0, h1, b1);
#endif
  (void)avx2;
  return wide_overlap(h0, b0) | wide_overlap(h1, b1) << 4;
}
/// wide_overlap2 of two hoisted boxes whose M is the signed permutation `a`.
[[nodiscard]] inline unsigned wide_overlap2_permuted(const WideHoisted& h0, const WideNode& b0, const WideHoisted& h1,
                                                     const WideNode& b1, const WidePermutation& a, bool avx2) {
#ifdef TIGHTBVH_WIDE_AVX2
  if (avx2) return wide_overlap2_permuted_avx2(h0, b0, h1, b1, a);
#endif
  (void)avx2;
  return wide_overlap_permuted(h0, a, b0) | wide_overlap_permuted(h1, a, b1) << 4;
}

}  // namespace tightbvh::query_detail
