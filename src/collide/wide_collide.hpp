#pragma once
// Internal: collide's descent over two wide trees (issue 38, wide_nodes.hpp), for all_pairs and
// first_hit, with or without a margin (no solid, no contacts: model.cpp adds those after it).
// collide() on two Models runs it for all_pairs
// (model.cpp); tested to report the same pairs as collide() on the trees
// (tests/collide/wide_collide_test.cpp, tests/scene/model_test.cpp) and measured against it
// (bench/collide/collide_bench.cpp, BM_WideCollide).
//
// The roots' boxes are tested first with collide()'s double test (box_test.hpp); where they
// overlap, the descent starts from the children of A's wide root against those of B's.
//
// The descent visits (box of A, node of B) pairs: one box of A, hoisted once (M = A^T R0 and B's
// node reference point in A's box frame, `hoist`), is tested by the float kernel against the
// four children of a node of B. For each child of B that it keeps:
//   - both leaves: the leaf pair's triangle pairs, with tri_tri_overlap (all_pairs: the four-lane
//     batch of tri_batch.hpp where the CPU has AVX2, which decides as tri_tri_overlap does);
//   - B's child internal and at least as large (volume) as A's box, or A's box a leaf: descend B.
//     The same hoisted box is tested against the child's node; only B's reference point moves,
//     updated in float as tn' = tn + M c (c the child's stored float offset); its error is
//     bounded once per query (descent_bounds, which sums the steps' bounds over any path: the
//     derivations are in wide_collide.cpp) and that bound is in every forward box's allowance;
//   - otherwise descend A: the child node of A's box is hoisted, its four boxes at once in lanes
//     (hoist_node, with B's ref in that node's frame carried in float), and each box is tested
//     against the same node of B, restricted to the lanes that chose this branch; where fewer
//     lanes of B chose it than A's node has boxes, those children of B are hoisted in B's frame
//     instead and tested against A's node in lanes (swapped_tests, A's node ref in B's frame from
//     swap_point).
// Two tests go through the kernel at once (wide_overlap2, eight AVX2 lanes), in the visiting order
// (first_hit: nearest first), each pair just before its descents.
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "tightbvh/collide.hpp"
#include "tightbvh/collide_trace.hpp"
#include "tightbvh/distance.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/tree.hpp"
#include "wide_nodes.hpp"

namespace tightbvh::query_detail {

// A node of A hoisted in lanes for a node of B (hoist_node): the kernel's part (M and the half
// extents of each box) and, per box, what descending needs.
struct HoistedNode {
  WideHoistedNode k;
  float tn[3][kWideLanes];  // B's node ref in each box's frame, and base and err for it (DescentBox)
  float base[kWideLanes];
  float err[kWideLanes];
  float core[kWideLanes];    // kappa (sum ea + margin) + margin: the part of base that does not depend on tn
  float volume[kWideLanes];  // ea_0 ea_1 ea_2
  const WideNode* node = nullptr;
};

// A box of A (lane `lane` of a hoisted node) against the nodes of B it meets.
struct DescentBox {
  const HoistedNode* hn = nullptr;
  int lane = 0;
  float tn[3];        // B's node ref in the box's frame: A^T (R0 ref_b + t0 - ref_a - ca), rounded
  float base = 0.0f;  // the kernel's base allowance for this tn
  double err = 0.0;   // >= |tn_i - exact tn_i|, each i
  float t[3];         // B's node ref in the frame of A's node: R0 ref_b + t0 - ref_a, rounded
  double t_err = 0.0;  // >= |t_k - exact|, each k
  [[nodiscard]] const WideNode& node() const { return *hn->node; }
  [[nodiscard]] WideBoxView view() const { return {&hn->k, lane, tn, base}; }
};

// The descent's steps with their error bounds, exposed for the test (wide_collide.cpp derives them;
// descent_bounds sums them over any path, and the descent moves without carrying them).
// The boxes of A's node `n`, hoisted for B's node whose ref is at t (with error t_err) in n's frame.
[[nodiscard]] HoistedNode hoist_node(const WideFrame& f, const WideNode& n, const float (&t)[3], double t_err);
// Box `lane` of a hoisted node, for the node of B it was hoisted for (t, t_err as given to it).
// Inline: built in place in the caller's array, so its fields are not stored and then reloaded
// as a copy.
[[nodiscard]] inline DescentBox fresh(const HoistedNode& hn, int lane, const float (&t)[3], double t_err) {
  DescentBox x;
  x.hn = &hn;
  x.lane = lane;
  for (int k = 0; k < 3; ++k) {
    x.tn[k] = hn.tn[k][lane];
    x.t[k] = t[k];
  }
  x.base = hn.base[lane];
  x.err = static_cast<double>(hn.err[lane]);
  x.t_err = t_err;
  return x;
}
// The same box of A for B's child `lane` of node n: moves tn and t. ref_round: B's tree's.
void move_b(DescentBox& x, const WideNode& n, int lane, double ref_round, const float (&f_r0)[9]);
// B's ref in the frame of the child node of x, for that node's boxes. ref_round: A's tree's.
void move_a(const DescentBox& x, double ref_round, float (&t)[3], double& t_err);
// What the rounding of a child's ref (child_ref) adds to a moved point's error in `tree`:
// 1.1 2^-53 ref_bound, rounded up.
[[nodiscard]] double ref_round(const WideTree& tree);
// A's node ref in B's node frame under the swapped frame (wide_frame_swapped), from t (B's node
// ref in A's node frame, error t_err) and r0 = fl(R0): s with error s_err. `fixed` >=
// swap_rel |ref_b|_inf + swap_abs of that frame (the derivation is in wide_collide.cpp).
void swap_point(const float (&r0)[9], const float (&t)[3], double t_err, double fixed, float (&s)[3], double& s_err);
// Bounds on the descent's float errors that hold for the whole query (derivation in
// wide_collide.cpp): t_err for t (B's node ref in A's node frame) and err for tn (in A's box
// frame), at any node pair the descent reaches from the roots, `root` the roots' wide_pair.
struct DescentBounds {
  double t_err = 0.0;
  double err = 0.0;
};
[[nodiscard]] DescentBounds descent_bounds(const WideTree& wa, const WideTree& wb, const WidePair& root);

/// What the descent did beyond QueryStats, for the benchmark.
struct WideCounters {
  std::uint64_t kernel_calls = 0;  // four-lane kernel calls (wide_overlap2 counts two)
};

/// Mesh A's triangles touching mesh B's, B placed in A's frame by `rel` (x_A = R x_B + t), over the
/// wide trees `wa` of `ta` and `wb` of `tb` (build_wide; the trees give the leaves' triangle order).
/// `mode` all_pairs: result.pairs sorted and unique, the same set as collide()'s with the same
/// `margin` (> 0: the pairs within it, boxes tested inflated by it; 0: touching pairs);
/// first_hit: result.hit as collide()'s, with the one pair found. Stats: box_tests counts box
/// pairs tested (the roots, then one box of A against one child of B: a lane of the kernel),
/// triangle_tests triangle pairs tested. `swap` false: A's side is never tested with the roles swapped (for the benchmark).
/// Throws InputError for a pose that is not finite or not a rotation, or a margin that is
/// negative or not finite.
[[nodiscard]] QueryResult collide_wide(const Tree& ta, const WideTree& wa, const Mesh& ma, const Tree& tb,
                                       const WideTree& wb, const Mesh& mb, const Pose& rel, QueryMode mode,
                                       double margin = 0.0, WideCounters* counters = nullptr, bool swap = true);

/// What collide_wide_traced records: every box pair the descent tests, in testing order.
struct WideTraceSink {
  static constexpr std::uint32_t kRoot = 0xFFFFFFFFu;  // a_node and b_node of the trees' root pair
  struct Test {
    std::uint32_t a_node, b_node;  // wide nodes whose lanes hold the two boxes (kRoot: the roots)
    std::uint8_t a_lane, b_lane;
    PairOutcome outcome;  // culled, descended (kept, one box internal), leaves, hit
  };
  std::vector<Test> tests;
  std::unordered_map<std::uint64_t, std::size_t> leaf_tests;  // kept pairs of two leaves -> tests index

  [[nodiscard]] static std::uint64_t key(std::uint32_t a_node, int a_lane, std::uint32_t b_node, int b_lane) {
    return (std::uint64_t{a_node} * kWideLanes + static_cast<unsigned>(a_lane)) << 32 |
           (b_node * kWideLanes + static_cast<unsigned>(b_lane));
  }
  // The leaves of that pair reported a triangle pair.
  void mark_hit(std::uint32_t a_node, int a_lane, std::uint32_t b_node, int b_lane) {
    const auto it = leaf_tests.find(key(a_node, a_lane, b_node, b_lane));
    if (it != leaf_tests.end()) tests[it->second].outcome = PairOutcome::hit;
  }
};

/// collide_wide (mode and margin as there) with every box test recorded in `sink`: the same
/// descent and answer, the leaves' triangle pairs tested one at a time (no AVX2 batch, which
/// decides alike) so that each leaf pair's outcome is known.
[[nodiscard]] QueryResult collide_wide_traced(const Tree& ta, const WideTree& wa, const Mesh& ma, const Tree& tb,
                                              const WideTree& wb, const Mesh& mb, const Pose& rel, QueryMode mode,
                                              double margin, WideTraceSink& sink);

/// distance() (distance.hpp) with its search over the wide trees `wa` of `a` and `wb` of `b`
/// (distance.cpp, DistanceSearch::run_wide): the same distance; where several triangle pairs
/// share it, the pair and points may be another of them; stats count the wide steps (node_pairs:
/// the touching phase's box tests, then one box against one child per bounded lane).
[[nodiscard]] DistanceResult distance_wide(const Tree& a, const WideTree& wa, const Mesh& ma, const Pose& pa,
                                           const Tree& b, const WideTree& wb, const Mesh& mb, const Pose& pb,
                                           const DistanceOptions& options, QueryWorkspace& workspace);

/// distance() of two models: the search on the binary trees (distance()'s), the vertices that
/// signed_distance classifies through the wide nodes (classify_point_wide): the same answer.
[[nodiscard]] DistanceResult distance_models(const Tree& a, const WideTree& wa, const Mesh& ma, const Pose& pa,
                                             const Tree& b, const WideTree& wb, const Mesh& mb, const Pose& pb,
                                             const DistanceOptions& options, QueryWorkspace& workspace);

}  // namespace tightbvh::query_detail
