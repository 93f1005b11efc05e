#pragma once
// Internal: collide's descent over two wide trees (issue 38, wide_nodes.hpp), for all_pairs and
// first_hit without margin, solid or contacts. Not yet what collide() runs; tested to report the
// same pairs (tests/collide/wide_collide_test.cpp) and measured against it
// (bench/collide/collide_bench.cpp, BM_WideCollide).
//
// The descent visits (box of A, node of B) pairs: one box of A, hoisted once (M = A^T R0 and B's
// node reference point in A's box frame, `hoist`), is tested by the float kernel against the
// four children of a node of B. For each child of B that it keeps:
//   - both leaves: the leaf pair's triangle pairs, with tri_tri_overlap (all_pairs: the four-lane
//     batch of tri_batch.hpp where the CPU has AVX2, which decides as tri_tri_overlap does);
//   - B's child internal and at least as large (volume) as A's box, or A's box a leaf: descend B.
//     The same hoisted box is tested against the child's node; only B's reference point moves,
//     updated in float as tn' = tn + M c (c the child's stored float offset), with its error bound
//     carried along and added to the kernel's allowance (the derivation is in wide_collide.cpp);
//   - otherwise descend A: each child box of A's box is hoisted afresh (its node's reference point
//     and B's, in double: wide_pair) and tested against the same node of B, restricted to the
//     lanes that chose this branch. Two boxes of A go through the kernel at once (wide_overlap2).
#include "tightbvh/collide.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/tree.hpp"
#include "wide_nodes.hpp"

namespace tightbvh::query_detail {

// A box of A hoisted for the nodes of B it meets (hoist, wide_nodes.hpp), with what moving B's
// reference point and descending A need.
struct DescentBox {
  WideHoisted h;
  double err = 0.0;   // >= |h.tn_i - exact tn_i|, each i (exact: A^T (R0 ref_b + t0 - ref_a - ca))
  float core = 0.0f;  // kappa (sum ea + margin) + margin: the part of h.base that does not depend on tn
  float volume = 0.0f;
  const WideNode* node = nullptr;  // the node of A holding the box, in lane `lane`
  int lane = 0;
  Vec3 ref_a;  // that node's ref
  float t[3];  // B's node ref in the frame of A's node: R0 ref_b + t0 - ref_a, rounded
  double t_err = 0.0;  // >= |t_k - exact|, each k
};

// The descent's steps, exposed for the test of their error bounds (wide_collide.cpp derives them).
// Box `lane` of A's node `n` (ref ref_a), hoisted for B's node whose ref is at t (with error
// t_err) in n's frame.
[[nodiscard]] DescentBox fresh(const WideFrame& f, const WideNode& n, int lane, const Vec3& ref_a, const float (&t)[3],
                               double t_err);
// The same box of A for B's child `lane` of node n, whose ref is ref_c: moves h.tn and t.
void move_b(DescentBox& x, const WideNode& n, int lane, const Vec3& ref_c, const float (&f_r0)[9]);
// B's ref in the frame of the child node of x (whose ref is ref_c), for that node's boxes.
void move_a(const DescentBox& x, const Vec3& ref_c, float (&t)[3], double& t_err);

/// What the descent did beyond QueryStats, for the benchmark.
struct WideCounters {
  std::uint64_t kernel_calls = 0;  // four-lane kernel calls (wide_overlap2 counts two)
};

/// Mesh A's triangles touching mesh B's, B placed in A's frame by `rel` (x_A = R x_B + t), over the
/// wide trees `wa` of `ta` and `wb` of `tb` (build_wide; the trees give the leaves' triangle order).
/// `mode` all_pairs: result.pairs sorted and unique, the same set as collide()'s with margin 0;
/// first_hit: result.hit as collide()'s, with the one pair found. Stats: box_tests counts box
/// pairs (one box of A, one child of B: a lane of the kernel) tested, triangle_tests triangle
/// pairs tested. Throws InputError for a pose that is not finite or not a rotation.
[[nodiscard]] QueryResult collide_wide(const Tree& ta, const WideTree& wa, const Mesh& ma, const Tree& tb,
                                       const WideTree& wb, const Mesh& mb, const Pose& rel, QueryMode mode,
                                       WideCounters* counters = nullptr);

}  // namespace tightbvh::query_detail
