// Tree-vs-tree minimum distance: collide's first_hit walk for touching meshes, then PQP's descent
// (Larsen, Gottschalk, Lin & Manocha 2000, "Fast distance queries with rectangular swept sphere
// volumes") on our boxes, with the separating-axis lower bound of obb_distance.hpp (in lanes:
// box_test.hpp). See include/tightbvh/distance.hpp.
#include "tightbvh/distance.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "batch.hpp"
#include "box_test.hpp"
#include "query_common.hpp"
#include "query_workspace.hpp"
#include "solid.hpp"
#include "tightbvh/point_query.hpp"
#include "tightbvh/tri_distance.hpp"
#include "tightbvh/tri_tri.hpp"
#include "traverse.hpp"
#include "tri_distance_disjoint.hpp"
#include "wide_collide.hpp"
#include "wide_nodes.hpp"

namespace tightbvh {
namespace {

using query_detail::BoundedPair;
using query_detail::map_point;

// The best triangle pair so far, in A's frame.
struct Best {
  double distance = std::numeric_limits<double>::infinity();
  bool found = false;
  TrianglePair pair;
  Vec3 point_a = Vec3::Zero();  // on A's triangle, A's frame
  Vec3 point_b = Vec3::Zero();  // on B's mapped triangle, A's frame
};

// The allowance of a gap measured along a unit direction, relative to the coordinates' scale:
// each dot product rounds by ~1e-16 of it, the exact triangle distance by little more.
constexpr double kDirectionSlack = 1e-12;

// split_both's limit on the ratio of the two nodes' sizes (the search's; collide's descent and
// the touching phase use traverse.hpp's kSplitBothRatio). Measured on the shipped pair's gap and
// separated poses (approx trees): ratios 2, 4 and 8 took 8%, 11% and 10% less time than never
// splitting both; splitting both at any ratio about the same time as never (5% more bounds, 10%
// more triangle pairs).
constexpr double kSearchSplitBothRatio = 4.0;

// The same on wide nodes (volume ratio of the two boxes whose nodes both split).
constexpr float kWideSplitBothRatio = 4.0f;

// One distance query in two phases. Phase 1 (touching) is collide's first_hit walk: the SAT box
// test with collide's allowance, both child pairs of a split at once, the touching triangle
// test; it stops at the first touching pair, so distance 0 costs about what collide costs and is
// found exactly when collide hits. It sets aside what it does not descend: node pairs whose boxes
// are separated and leaf pairs whose triangles do not touch. Phase 2 is PQP's bound-and-prune
// search (Larsen et al. 2000) from those pairs, best first instead of PQP's depth first. Every pair with overlapping boxes has
// bound 0 and so would be descended by phase 2 too: phase 1 only replaces the full bound by the
// cheaper SAT test (early exit) there, and nothing is visited twice but the leaf pairs.
class DistanceSearch {
 public:
  DistanceSearch(const Tree& ta, const Mesh& ma, const Tree& tb, const Mesh& mb, const Pose& rel,
                 const DistanceOptions& options, QueryWorkspace::Scratch& ws)
      : ta_(ta), ma_(ma), tb_(tb), mb_(mb), rel_(rel), options_(options), ws_(ws) {
    margin_ = query_detail::box_allowance(ta, tb, rel);
  }

  void run() {
    ws_.mapped_b.begin(tb_.nodes.size());
    std::vector<BoundedPair>& pairs = ws_.distance_stack;
    pairs.clear();
    if (!(options_.upper_bound > 0.0)) return;  // only pairs closer than 0 would count: none
    if (touching(pairs)) return;
    direction_slack_ = kDirectionSlack * coordinate_scale();
    bound_all(pairs);
    // The pairs set aside; those at or beyond the upper bound are dropped.
    std::erase_if(pairs, [&](const BoundedPair& p) { return p.bound >= options_.upper_bound; });
    best_first(pairs);
  }

  // The same search over the models' wide nodes (wa of ta, wb of tb): the touching phase is
  // collide's wide first_hit descent, then the best-first search splits one box's node at a time
  // and bounds its four children in float lanes (wide_distance_bounds). The same distance as
  // run() (both find the least triangle distance, each pair measured alike); the pair and points
  // may differ where several pairs share that distance, and the stats count the wide steps.
  void run_wide(const query_detail::WideTree& wa, const query_detail::WideTree& wb) {
    ws_.mapped_b.begin(tb_.nodes.size());
    if (!(options_.upper_bound > 0.0)) return;
    if (touching_wide(wa, wb)) return;
    direction_slack_ = kDirectionSlack * coordinate_scale();
    best_first_wide(wa, wb);
  }

  [[nodiscard]] const Best& best() const { return best_; }
  [[nodiscard]] const DistanceStats& stats() const { return stats_; }

 private:
  const query_detail::MappedBox& mapped(std::uint32_t ib) { return ws_.mapped_b.mapped(ib, tb_.nodes[ib].box, rel_); }

  // Phase 1. Returns whether a touching pair was found (then best_ holds it, at distance 0);
  // otherwise `aside` holds the pairs for phase 2 (bounds not yet computed).
  bool touching(std::vector<BoundedPair>& aside) {
    using query_detail::NodePair;
    query_detail::PairStack& stack = ws_.stack;
    stack.clear();
    ++stats_.node_pairs;
    if (!query_detail::box_overlap(ta_.nodes[0].box, mapped(0), tb_.nodes[0].box.half_extents, margin_)) {
      aside.push_back({0, 0, 0.0});
      return false;
    }
    stack.push({0, 0});
    while (!stack.empty()) {
      const NodePair np = stack.pop();
      const Node& na = ta_.nodes[np.a];
      const Node& nb = tb_.nodes[np.b];
      if (na.is_leaf() && nb.is_leaf()) {
        if (touching_leaves(np.a, np.b)) return true;
        aside.push_back({np.a, np.b, 0.0});
        continue;
      }
      const query_detail::Split split = query_detail::choose_split(na, nb, options_.descend);
      if (query_detail::splits_both(split)) {
        const std::array<NodePair, 4> kids = query_detail::both_children(na, nb, split);
        const bool a_major = split == query_detail::Split::both_a_first;
        const std::array<bool, 4> overlap = query_detail::boxes_overlap_cross(child_boxes(na, nb), a_major, margin_, avx2_);
        stats_.node_pairs += 4;
        for (int k = 3; k >= 0; --k)  // collide's order: the first child pair is visited first
          if (overlap[k]) stack.push(kids[k]);
          else aside.push_back({kids[k].a, kids[k].b, 0.0});
        continue;
      }
      NodePair first, second;
      std::array<bool, 2> overlap;
      if (split == query_detail::Split::a) {
        first = {na.first, np.b}, second = {na.first + 1, np.b};
        const query_detail::MappedBox& m = mapped(np.b);
        const Eigen::Vector3f& eb = nb.box.half_extents;
        overlap = query_detail::boxes_overlap2(ta_.nodes[first.a].box, m, eb, ta_.nodes[second.a].box, m, eb, margin_);
      } else {
        first = {np.a, nb.first}, second = {np.a, nb.first + 1};
        overlap = query_detail::boxes_overlap2(na.box, mapped(first.b), tb_.nodes[first.b].box.half_extents, na.box,
                                               mapped(second.b), tb_.nodes[second.b].box.half_extents, margin_);
      }
      stats_.node_pairs += 2;
      // collide's order: the first child pair is visited first.
      if (overlap[1]) stack.push(second); else aside.push_back({second.a, second.b, 0.0});
      if (overlap[0]) stack.push(first); else aside.push_back({first.a, first.b, 0.0});
    }
    return false;
  }

  // Phase 1 on wide nodes: collide's first_hit descent over them (the same yes/no as collide());
  // on a hit, best_ is its pair at distance 0, its points from the triangle distance.
  bool touching_wide(const query_detail::WideTree& wa, const query_detail::WideTree& wb) {
    const QueryResult hit = query_detail::collide_wide(ta_, wa, ma_, tb_, wb, mb_, rel_, QueryMode::first_hit);
    stats_.node_pairs += hit.stats.box_tests;
    stats_.triangle_pairs += hit.stats.triangle_tests;
    if (!hit.hit) return false;
    const TrianglePair pair = hit.pairs.front();
    const auto [p0, p1, p2] = ma_.corners(pair.a);
    const Triangle& tb = mb_.triangles[pair.b];
    const TriangleDistance d =
        tri_tri_distance(p0, p1, p2, map_point(rel_, mb_.vertices[tb[0]]), map_point(rel_, mb_.vertices[tb[1]]),
                         map_point(rel_, mb_.vertices[tb[2]]));
    best_ = {0.0, true, pair, d.point_p, d.point_q};
    prune_at_ = 0.0;
    return true;
  }

  // Phase 2 on wide nodes. A queued pair is a box of A and a box of B, each a lane of a wide node:
  // the queue's entry holds the index of the two nodes' record (WideSearchItem: the nodes and
  // their reference points, one per split) and the two lanes. Splitting a pair bounds boxes
  // against the four children of a node in one kernel call: A's box hoisted against B's child
  // node (the forward frame), or B's box hoisted against A's child node (the swapped frame, its
  // pose's shift in t_err as collide's descent adds it), or, when both boxes are internal and
  // of about one volume, the four boxes of A's child node against B's child node (16 pairs, two
  // boxes of A a call of the eight-lane kernel where the CPU has AVX2). Otherwise the larger box
  // by volume is split (B's on a tie), a leaf never. As best_first: bounds raised to the
  // parent's, pairs of two leaves measured at once but for the best child, which is taken next
  // without the queue when no queued pair can be below it.
  void best_first_wide(const query_detail::WideTree& wa, const query_detail::WideTree& wb) {
    using query_detail::WideNode;
    using query_detail::WideSearchItem;
    constexpr int kLanes = query_detail::kWideLanes;
    const query_detail::WideFrames frames = query_detail::wide_frames(rel_, wa.eta, wb.eta, 0.0);
    const query_detail::WideBoundConstants cf = query_detail::wide_bound_constants(frames.forward);
    const query_detail::WideBoundConstants cs = query_detail::wide_bound_constants(frames.swapped);
    std::vector<WideSearchItem>& records = ws_.wide_items;
    records.clear();
    query_detail::RadixQueue& queue = ws_.distance_queue;
    queue.clear();
    // A split's children: lanes of the record `record`, with their bounds.
    std::uint32_t record = 0;
    int lane_a[kLanes * kLanes], lane_b[kLanes * kLanes];
    float bounds[kLanes * kLanes];
    float raw[kLanes * kLanes];
    const auto add_record = [&](const Vec3& ref_a, const Vec3& ref_b, std::uint32_t na, std::uint32_t nb) {
      records.push_back({ref_a, ref_b, na, nb});
      record = static_cast<std::uint32_t>(records.size() - 1);
    };
    // The children of one box split against `node`'s four (A's node when `node_is_a`): each
    // non-empty lane l of `node` with the other box's lane `fixed`, bound raw[l].
    const auto collect = [&](const WideNode& node, bool node_is_a, int fixed) {
      int count = 0;
      for (int l = 0; l < kLanes; ++l) {
        if (query_detail::is_empty_lane(node, l)) continue;
        lane_a[count] = node_is_a ? l : fixed;
        lane_b[count] = node_is_a ? fixed : l;
        bounds[count++] = raw[l];
      }
      return count;
    };
    // A's box (node na, lane la, node ref ref_a) against the children of B's node nb (ref ref_nb).
    const auto split_b = [&](std::uint32_t na, int la, const Vec3& ref_a, std::uint32_t nb, const Vec3& ref_nb) {
      const query_detail::WideHoisted h =
          query_detail::hoist(frames.forward, query_detail::wide_pair(frames.forward, ref_a, ref_nb),
                              query_detail::lane_box(wa.nodes[na], la));
      const WideNode& node = wb.nodes[nb];
      query_detail::wide_distance_bounds(h, node, cf, *reinterpret_cast<float(*)[kLanes]>(raw));
      add_record(ref_a, ref_nb, na, nb);
      return collect(node, false, la);
    };
    // B's box (node nb, lane lb, node ref ref_b) against the children of A's node na (ref ref_na).
    const auto split_a = [&](std::uint32_t na, const Vec3& ref_na, std::uint32_t nb, int lb, const Vec3& ref_b) {
      const query_detail::WideBox b = query_detail::lane_box(wb.nodes[nb], lb);
      query_detail::WidePair p = query_detail::wide_pair(frames.swapped, ref_b, ref_na);
      p.t_err = static_cast<float>((static_cast<double>(p.t_err) + query_detail::swap_error(frames.swapped, ref_b, b)) *
                                   (1.0 + 0x1p-20));
      const query_detail::WideHoisted h = query_detail::hoist(frames.swapped, p, b);
      const WideNode& node = wa.nodes[na];
      query_detail::wide_distance_bounds(h, node, cs, *reinterpret_cast<float(*)[kLanes]>(raw));
      add_record(ref_na, ref_b, na, nb);
      return collect(node, true, lb);
    };
    // The boxes of A's node na against the children of B's node nb.
    const auto split_both = [&](std::uint32_t na, const Vec3& ref_na, std::uint32_t nb, const Vec3& ref_nb) {
      const WideNode& node_a = wa.nodes[na];
      const WideNode& node_b = wb.nodes[nb];
      const query_detail::WidePair p = query_detail::wide_pair(frames.forward, ref_na, ref_nb);
      // The four boxes hoisted at once (hoist_node: each lane as hoist computes it).
      const query_detail::HoistedNode hn =
          query_detail::hoist_node(frames.forward, node_a, p.t, static_cast<double>(p.t_err));
      float tn[kLanes][3];
      query_detail::WideBoxView h[kLanes];
      for (int i = 0; i < kLanes; ++i) {
        for (int k = 0; k < 3; ++k) tn[i][k] = hn.tn[k][i];
        h[i] = {&hn.k, i, tn[i], hn.base[i]};
      }
      for (int i = 0; i < kLanes; i += 2) {
        float* two = raw + kLanes * i;
#ifdef TIGHTBVH_WIDE_AVX2
        if (avx2_) {
          query_detail::wide_distance_bounds2_avx2(h[i], node_b, h[i + 1], node_b, cf.len_sq, cf.factor,
                                                   *reinterpret_cast<float(*)[2 * kLanes]>(two));
          continue;
        }
#endif
        query_detail::wide_distance_bounds(h[i], node_b, cf, *reinterpret_cast<float(*)[kLanes]>(two));
        query_detail::wide_distance_bounds(h[i + 1], node_b, cf, *reinterpret_cast<float(*)[kLanes]>(two + kLanes));
      }
      add_record(ref_na, ref_nb, na, nb);
      int count = 0;
      for (int i = 0; i < kLanes; ++i) {
        if (query_detail::is_empty_lane(node_a, i)) continue;
        for (int l = 0; l < kLanes; ++l) {
          if (query_detail::is_empty_lane(node_b, l)) continue;
          lane_a[count] = i, lane_b[count] = l;
          bounds[count++] = raw[kLanes * i + l];
        }
      }
      return count;
    };
    const auto entry = [](std::uint32_t rec, int la, int lb, double bound) {
      return BoundedPair{rec, static_cast<std::uint32_t>(la | lb << 8), bound};
    };
    // The children (child references) of an entry's two boxes.
    const auto children = [&](const BoundedPair& e) {
      const WideSearchItem& r = records[e.a];
      return std::pair{wa.nodes[r.a_node].child[e.b & 0xFF], wb.nodes[r.b_node].child[e.b >> 8]};
    };
    const auto measure = [&](std::int32_t ca, std::int32_t cb) { leaves(wa.leaf(ca), wb.leaf(cb)); };
    // The roots: each box of A's root node against B's root node's children.
    const WideNode& root_a = wa.nodes[0];
    for (int l = 0; l < kLanes; ++l) {
      if (query_detail::is_empty_lane(root_a, l)) continue;
      const int count = split_b(0, l, wa.root_ref, 0, wb.root_ref);
      stats_.node_pairs += static_cast<std::uint64_t>(count);
      for (int k = 0; k < count; ++k)
        if (!prunable(bounds[k])) queue.push(entry(record, lane_a[k], lane_b[k], bounds[k]));
    }
    if (queue.empty()) return;
    BoundedPair np = queue.pop();
    for (;;) {
      if (prunable(np.bound)) break;
      const auto [ca, cb] = children(np);
      if (ca < 0 && cb < 0) {
        measure(ca, cb);
        if (queue.empty()) break;
        np = queue.pop();
        continue;
      }
      const WideSearchItem it = records[np.a];
      const int la = static_cast<int>(np.b & 0xFF), lb = static_cast<int>(np.b >> 8);
      bool on_b = ca < 0, both = false;
      if (!on_b && cb > 0) {
        const WideNode& na = wa.nodes[it.a_node];
        const WideNode& nb = wb.nodes[it.b_node];
        const float va = na.half[0][la] * na.half[1][la] * na.half[2][la];
        const float vb = nb.half[0][lb] * nb.half[1][lb] * nb.half[2][lb];
        on_b = vb >= va;
        both = vb <= kWideSplitBothRatio * va && va <= kWideSplitBothRatio * vb;
      }
      int count = 0;
      if (both)
        count = split_both(static_cast<std::uint32_t>(ca), query_detail::child_ref(it.ref_a, wa.nodes[it.a_node], la),
                           static_cast<std::uint32_t>(cb), query_detail::child_ref(it.ref_b, wb.nodes[it.b_node], lb));
      else if (on_b)
        count = split_b(it.a_node, la, it.ref_a, static_cast<std::uint32_t>(cb),
                        query_detail::child_ref(it.ref_b, wb.nodes[it.b_node], lb));
      else
        count = split_a(static_cast<std::uint32_t>(ca), query_detail::child_ref(it.ref_a, wa.nodes[it.a_node], la),
                        it.b_node, lb, it.ref_b);
      stats_.node_pairs += static_cast<std::uint64_t>(count);
      if (count == 0) {  // a node of empty lanes only: nothing below
        if (queue.empty()) break;
        np = queue.pop();
        continue;
      }
      const WideNode& kid_a = wa.nodes[records[record].a_node];
      const WideNode& kid_b = wb.nodes[records[record].b_node];
      int lo_index = 0;
      double kid_bound[kLanes * kLanes];
      kid_bound[0] = std::max(static_cast<double>(bounds[0]), np.bound);
      for (int k = 1; k < count; ++k) {
        kid_bound[k] = std::max(static_cast<double>(bounds[k]), np.bound);
        if (kid_bound[k] < kid_bound[lo_index]) lo_index = k;
      }
      for (int k = 0; k < count; ++k) {
        if (k == lo_index || prunable(kid_bound[k])) continue;
        const std::int32_t ka = kid_a.child[lane_a[k]], kb = kid_b.child[lane_b[k]];
        if (ka < 0 && kb < 0)
          measure(ka, kb);
        else
          queue.push(entry(record, lane_a[k], lane_b[k], kid_bound[k]));
      }
      const BoundedPair lo = entry(record, lane_a[lo_index], lane_b[lo_index], kid_bound[lo_index]);
      if (prunable(lo.bound)) {  // then so are the others
        if (queue.empty()) break;
        np = queue.pop();
      } else if (queue.empty() || lo.bound <= np.bound) {
        // No queued pair is below it: every queued bound is at least np.bound (the queue is
        // monotone and np was its least), and the other children are at least lo's.
        np = lo;
      } else {
        queue.push(lo);
        np = queue.pop();
      }
    }
  }

  // collide's touching test on a leaf pair; on a hit, best_ is that pair at distance 0 (its points
  // from the triangle distance, which also starts with the touching test).
  bool touching_leaves(std::uint32_t ia_node, std::uint32_t ib_node) {
    const Node& na = ta_.nodes[ia_node];
    const Node& nb = tb_.nodes[ib_node];
    query_detail::MappedChunk& chunk = chunk_;
    for (std::uint32_t cb = 0; cb < nb.count; cb += query_detail::kLeafChunk) {
      const std::uint32_t nbc = query_detail::map_leaf_chunk(rel_, mb_, tb_, nb, cb, chunk);
      for (std::uint32_t i = 0; i < na.count; ++i) {
        const std::uint32_t ia = ta_.triangle_order[na.first + i];
        const auto [p0, p1, p2] = ma_.corners(ia);
        for (std::uint32_t j = 0; j < nbc; ++j) {
          ++stats_.triangle_pairs;
          if (!tri_tri_overlap(p0, p1, p2, chunk[j][0], chunk[j][1], chunk[j][2])) continue;
          const TriangleDistance d = tri_tri_distance(p0, p1, p2, chunk[j][0], chunk[j][1], chunk[j][2]);
          best_ = {0.0, true, {ia, tb_.triangle_order[nb.first + cb + j]}, d.point_p, d.point_q};
          prune_at_ = 0.0;
          return true;
        }
      }
    }
    return false;
  }

  // Phase 2's bounds of every pair set aside, four at a time (the four-lane bound), the rest two
  // at a time.
  void bound_all(std::vector<BoundedPair>& pairs) {
    std::size_t i = 0;
    for (; i + 3 < pairs.size(); i += 4) {
      BoundedPair four[4] = {pairs[i], pairs[i + 1], pairs[i + 2], pairs[i + 3]};
      lower_bounds4(four);
      for (int k = 0; k < 4; ++k) pairs[i + k].bound = four[k].bound;
    }
    for (; i + 1 < pairs.size(); i += 2) {
      const auto b = lower_bounds(pairs[i].a, pairs[i].b, pairs[i + 1].a, pairs[i + 1].b);
      pairs[i].bound = b[0], pairs[i + 1].bound = b[1];
    }
    if (i < pairs.size()) pairs[i].bound = lower_bounds(pairs[i].a, pairs[i].b, pairs[i].a, pairs[i].b)[0];
  }

  // Never more than the distance between the two nodes' triangles: the box bound minus the
  // allowance for rounding in the transform and the float boxes' axes (as collide's box test).
  // Two pairs at once (box_distance_bounds2, box_test.hpp).
  std::array<double, 2> lower_bounds(std::uint32_t ia0, std::uint32_t ib0, std::uint32_t ia1, std::uint32_t ib1) {
    stats_.node_pairs += ia0 == ia1 && ib0 == ib1 ? 1 : 2;
    const auto raw = query_detail::box_distance_bounds2(ta_.nodes[ia0].box, mapped(ib0), tb_.nodes[ib0].box.half_extents,
                                                        ta_.nodes[ia1].box, mapped(ib1), tb_.nodes[ib1].box.half_extents);
    return {adjust(raw[0]), adjust(raw[1])};
  }

  // The box bound as a bound on the triangles' distance. It combines gaps along A's float axes as
  // if orthonormal: off by a relative ~1e-6 of itself (compact_box.hpp), hence the factor; the
  // allowance covers the projected radii.
  [[nodiscard]] double adjust(double bound) const { return std::max(0.0, bound * (1.0 - kCompactBoxSlack) - margin_); }

  // The boxes of the four child pairs of internal nodes na and nb.
  [[nodiscard]] query_detail::ChildBoxes child_boxes(const Node& na, const Node& nb) {
    return query_detail::child_boxes(ta_, tb_, na, nb, [&](std::uint32_t ib) -> const auto& { return mapped(ib); });
  }

  // The bounds of the four child pairs of na and nb at once (AVX2 lanes where the CPU has them),
  // `pairs` in both_children's A-major order: two boxes a side (box_distance_bounds_cross).
  void lower_bounds_both(const Node& na, const Node& nb, BoundedPair (&pairs)[4]) {
    stats_.node_pairs += 4;
    const auto raw = query_detail::box_distance_bounds_cross(child_boxes(na, nb), true, avx2_);
    for (int k = 0; k < 4; ++k) pairs[k].bound = adjust(raw[k]);
  }

  // Three or four pairs' bounds at once (box_distance_bounds4: AVX2 lanes where the CPU has
  // them); with three, the last lane repeats the third pair.
  void lower_bounds4(BoundedPair (&pairs)[4], int count = 4) {
    stats_.node_pairs += count;
    if (count == 3) pairs[3] = pairs[2];
    const CompactBox* a[4];
    const query_detail::MappedBox* m[4];
    const Eigen::Vector3f* eb[4];
    for (int k = 0; k < 4; ++k) {
      a[k] = &ta_.nodes[pairs[k].a].box;
      m[k] = &mapped(pairs[k].b);
      eb[k] = &tb_.nodes[pairs[k].b].box.half_extents;
    }
    const auto raw = query_detail::box_distance_bounds4(a, m, eb, avx2_);
    for (int k = 0; k < 4; ++k) pairs[k].bound = adjust(raw[k]);
  }

  // Both nodes split at once when neither is a leaf and they are of about one size (by the
  // descend rule's measure): the four child pairs are about the pairs two single splits would
  // bound next anyway (0.4% more bounds on the shipped pair's gap and separated poses), for one
  // call of the four-lane bound and fewer queue operations.
  [[nodiscard]] bool split_both(const Node& na, const Node& nb) const {
    return query_detail::splits_both(query_detail::choose_split(na, nb, options_.descend, kSearchSplitBothRatio));
  }

  // The children of `n`, the node a single split splits, each replaced by its own two children
  // when the descend rule would split it again next (it is not a leaf and not smaller than
  // `other`, or `other` is a leaf): three or four pairs for one call of the four-lane bound, and
  // one step of the search, instead of two calls of the two-lane bound and up to three steps.
  // Returns how many pairs it put in `kids` (2 to 4).
  template <class MakePair>
  int deep_children(const Tree& t, const Node& n, const Node& other, BoundedPair (&kids)[4], MakePair&& make) const {
    int count = 0;
    const double other_size = other.is_leaf() ? -1.0 : query_detail::descend_size(other.box, options_.descend);
    for (std::uint32_t c = n.first; c < n.first + 2; ++c) {
      const Node& child = t.nodes[c];
      if (!child.is_leaf() && query_detail::descend_size(child.box, options_.descend) >= other_size) {
        kids[count++] = make(child.first);
        kids[count++] = make(child.first + 1);
      } else {
        kids[count++] = make(c);
      }
    }
    return count;
  }

  // Phase 2: best first (a queue of node pairs by bound, RadixQueue), so that only pairs whose
  // bound is below the final distance are split: 37% fewer bounds and 57% fewer triangle pairs
  // than PQP's depth-first order on the shipped pair's gap poses. A popped pair that is prunable
  // ends the search (every pair left has a larger bound). The best child of a split (two to four
  // child pairs) goes through the queue, whose push is cheap (the other children are pushed or
  // measured at once). A child's bound is raised to its parent's (its triangles are among the parent's, so that is a
  // lower bound too), which makes the queue monotone.
  void best_first(std::vector<BoundedPair>& aside) {
    query_detail::RadixQueue& queue = ws_.distance_queue;
    queue.clear();
    for (const BoundedPair& p : aside) queue.push(p);
    if (queue.empty()) return;
    BoundedPair np = queue.pop();
    for (;;) {
      if (prunable(np.bound)) break;
      const Node& na = ta_.nodes[np.a];
      const Node& nb = tb_.nodes[np.b];
      if (na.is_leaf() && nb.is_leaf()) {
        leaves(np.a, np.b);
        if (queue.empty()) break;
        np = queue.pop();
        continue;
      }
      // The children: all four pairs when both nodes split (one call of the four-lane bound),
      // else those of the node the descend rule splits, two levels down where it would split
      // them again (deep_children).
      BoundedPair kids[4];
      int count = 2;
      if (split_both(na, nb)) {
        kids[0] = {na.first, nb.first, 0.0}, kids[1] = {na.first, nb.first + 1, 0.0};
        kids[2] = {na.first + 1, nb.first, 0.0}, kids[3] = {na.first + 1, nb.first + 1, 0.0};
        count = 4;
        lower_bounds_both(na, nb, kids);
      } else {
        const bool split_a = query_detail::splits_a(na, nb, options_.descend);
        count = split_a ? deep_children(ta_, na, nb, kids, [&](std::uint32_t c) { return BoundedPair{c, np.b, 0.0}; })
                        : deep_children(tb_, nb, na, kids, [&](std::uint32_t c) { return BoundedPair{np.a, c, 0.0}; });
        if (count == 2) {
          const auto bounds = lower_bounds(kids[0].a, kids[0].b, kids[1].a, kids[1].b);
          kids[0].bound = bounds[0], kids[1].bound = bounds[1];
        } else {
          lower_bounds4(kids, count);
        }
      }
      for (int k = 0; k < count; ++k) kids[k].bound = std::max(kids[k].bound, np.bound);
      // The best child (the first on a tie); the others wait, but for pairs of two leaves,
      // measured at once: their triangle tests rule most of them out cheaply (leaves()), for
      // less than a push and a later pop, and a closer pair found early prunes more. The same
      // distance (any order finds the least); 1-13% more triangle pairs measured, medians of
      // 0.93-1.03x the time on the four bench pairs' separated and gap poses, 12 of 14 faster
      // (docs/design-notes/distance-margin-solid.md, "Best first, with a monotone radix queue").
      int lo_index = 0;
      for (int k = 1; k < count; ++k)
        if (kids[k].bound < kids[lo_index].bound) lo_index = k;
      for (int k = 0; k < count; ++k) {
        if (k == lo_index || prunable(kids[k].bound)) continue;
        if (ta_.nodes[kids[k].a].is_leaf() && tb_.nodes[kids[k].b].is_leaf())
          leaves(kids[k].a, kids[k].b);
        else
          queue.push(kids[k]);
      }
      const BoundedPair& lo = kids[lo_index];
      if (prunable(lo.bound)) {  // then so are the others
        if (queue.empty()) break;
        np = queue.pop();
      } else if (queue.empty()) {
        np = lo;
      } else {
        // Through the queue: it yields the least of `lo` and its pairs. (Peeking at its least
        // first would settle the queue on a key that `lo`'s children may be below.)
        queue.push(lo);
        np = queue.pop();
      }
    }
  }

  // The pair cannot hold a triangle pair that beats the best so far by more than the allowed
  // error (PQP's test), or one closer than the upper bound.
  // With no error allowed (the default) that is bound >= min(upper bound, best), kept in
  // prune_at_: the same decision, as bound * 1 + 0 == bound.
  [[nodiscard]] bool prunable(double bound) const {
    if (exact_) return bound >= prune_at_;
    return bound >= options_.upper_bound ||
           bound * (1.0 + options_.relative_error) + options_.absolute_error >= best_.distance;
  }

  // A bound on every coordinate of both meshes in A's frame: the root boxes contain them.
  [[nodiscard]] double coordinate_scale() {
    const CompactBox& ra = ta_.nodes[0].box;
    return ra.center_d().cwiseAbs().maxCoeff() + ra.half_extents_d().sum() + mapped(0).center.cwiseAbs().maxCoeff() +
           tb_.nodes[0].box.half_extents_d().sum();
  }

  // The triangle pairs of two leaves. Most pairs the search reaches lose to the best pair so far
  // (about 95% on the shipped pair's gap and separated poses), so each is first projected on the
  // best pair's direction: where the two triangles' intervals there are at least the best
  // distance apart (plus the rounding allowance), no point of one is closer to the other, and the
  // exact distance is skipped. That rules out 50-65% of the pairs for 6 dot products each; the
  // answer is the same bit for bit, as a skipped pair could not have replaced the best.
  // Whether the triangles are at least `threshold` apart along one of their separating axes: the
  // two normals, the nine vectors from a corner of one to a corner of the other, and the nine
  // cross products of an edge of each (the closest pair of disjoint triangles is vertex-face,
  // along a normal, vertex-vertex, along the corners' difference, or edge-edge, along a cross
  // product, unless it ends at an edge's end). Any direction would do for correctness: the
  // projections of two sets are never farther apart than the sets. Of the pairs the best pair's
  // direction does not rule out, the normals and cross products rule out about a third, at a
  // tenth of an exact distance; the corner-to-corner vectors (before the cross products: they
  // need no product) then 26-51% of the exact distances left, for 0.91-1.02x the time per query
  // (median 0.97x; docs/design-notes/distance-margin-solid.md,
  // "Rule triangle pairs out before measuring them"). Each axis n is unnormalised: the gap g
  // between the projections is compared with threshold |n| squared, so there is no root and no
  // division. Rounding in the dot products is relative to |n| and the coordinates, which the
  // caller's allowance in `threshold` covers as for the best pair's direction.
  static bool apart_by_sat(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& q0, const Vec3& q1,
                           const Vec3& q2, double threshold) {
    // Squares kept within the normal range, where each product rounds by a relative 2^-53 at
    // most: below it (a threshold or an axis of ~1e-154) or at infinity the pair is kept.
    constexpr double kLeast = std::numeric_limits<double>::min();
    const double t2 = threshold * threshold;
    if (!(t2 >= kLeast)) return false;
    // All six corners are projected, none assumed on a plane or edge: a rounded normal or cross
    // product of nearly parallel vectors is not quite orthogonal to them.
    const auto apart = [&](const Vec3& n) {
      const double a0 = p0.dot(n), a1 = p1.dot(n), a2 = p2.dot(n);
      const double b0 = q0.dot(n), b1 = q1.dot(n), b2 = q2.dot(n);
      const double gap = std::max(std::min({b0, b1, b2}) - std::max({a0, a1, a2}),
                                  std::min({a0, a1, a2}) - std::max({b0, b1, b2}));
      const double rhs = t2 * n.squaredNorm();
      return gap > 0.0 && rhs >= kLeast && rhs <= std::numeric_limits<double>::max() && gap * gap >= rhs;
    };
    const Vec3 ep[3] = {p1 - p0, p2 - p1, p0 - p2}, eq[3] = {q1 - q0, q2 - q1, q0 - q2};
    if (apart(ep[0].cross(ep[1])) || apart(eq[0].cross(eq[1]))) return true;
    const Vec3* pp[3] = {&p0, &p1, &p2};
    const Vec3* qq[3] = {&q0, &q1, &q2};
    for (const Vec3* p : pp)
      for (const Vec3* q : qq)
        if (apart(*q - *p)) return true;
    for (const Vec3& e : ep)
      for (const Vec3& f : eq)
        if (apart(e.cross(f))) return true;
    return false;
  }
  void leaves(std::uint32_t ia_node, std::uint32_t ib_node) {
    const Node& na = ta_.nodes[ia_node];
    const Node& nb = tb_.nodes[ib_node];
    leaves({na.first, na.count}, {nb.first, nb.count});
  }
  // The same for two leaves given as ranges of the trees' triangle_order.
  void leaves(query_detail::WideTree::LeafRange na, query_detail::WideTree::LeafRange nb) {
    for (std::uint32_t j = 0; j < nb.count; ++j) {
      const std::uint32_t ib = tb_.triangle_order[nb.first + j];
      const Triangle& tri_b = mb_.triangles[ib];
      const Vec3 q0 = map_point(rel_, mb_.vertices[tri_b[0]]);
      const Vec3 q1 = map_point(rel_, mb_.vertices[tri_b[1]]);
      const Vec3 q2 = map_point(rel_, mb_.vertices[tri_b[2]]);
      const double qv[3] = {q0.dot(toward_b_), q1.dot(toward_b_), q2.dot(toward_b_)};
      const double q_low = std::min({qv[0], qv[1], qv[2]}), q_high = std::max({qv[0], qv[1], qv[2]});
      for (std::uint32_t i = 0; i < na.count; ++i) {
        const std::uint32_t ia = ta_.triangle_order[na.first + i];
        const Triangle& tri_a = ma_.triangles[ia];
        if (best_.found) {
          const double pv[3] = {ma_.vertices[tri_a[0]].dot(toward_b_), ma_.vertices[tri_a[1]].dot(toward_b_),
                                ma_.vertices[tri_a[2]].dot(toward_b_)};
          const double gap = std::max(q_low - std::max({pv[0], pv[1], pv[2]}), std::min({pv[0], pv[1], pv[2]}) - q_high);
          if (gap >= best_.distance + direction_slack_) continue;
          if (apart_by_sat(ma_.vertices[tri_a[0]], ma_.vertices[tri_a[1]], ma_.vertices[tri_a[2]], q0, q1, q2,
                           best_.distance + direction_slack_))
            continue;  // the same answer bit for bit, as for the direction above
        }
        ++stats_.triangle_pairs;
        // No pair here touches (touching() tested every pair whose boxes overlap): the touching
        // test is skipped, the same distance bit for bit.
        const TriangleDistance d = query_detail::tri_tri_distance_disjoint(
            ma_.vertices[tri_a[0]], ma_.vertices[tri_a[1]], ma_.vertices[tri_a[2]], q0, q1, q2);
        if (d.distance < best_.distance && d.distance < options_.upper_bound) {
          best_ = {d.distance, true, {ia, ib}, d.point_p, d.point_q};
          prune_at_ = std::min(prune_at_, d.distance);
          const Vec3 v = d.point_q - d.point_p;
          const double length = v.norm();
          toward_b_ = length > 0.0 ? Vec3(v / length) : Vec3::Zero();
        }
      }
    }
  }

  const Tree& ta_;
  const Mesh& ma_;
  const Tree& tb_;
  const Mesh& mb_;
  const Pose& rel_;
  const DistanceOptions& options_;
  QueryWorkspace::Scratch& ws_;
  double margin_ = 0.0;
  // prunable()'s threshold when no error is allowed: min(upper bound, best distance).
  bool exact_ = options_.relative_error == 0.0 && options_.absolute_error == 0.0;
  double prune_at_ = options_.upper_bound;
  bool avx2_ = query_detail::avx2_bounds_available();
  // The unit direction from the best pair's point on A to its point on B (zero until there is
  // one), and the rounding allowance of a gap measured along it (run()).
  Vec3 toward_b_ = Vec3::Zero();
  double direction_slack_ = 0.0;
  query_detail::MappedChunk chunk_;
  Best best_;
  DistanceStats stats_;
};

void check_options(const DistanceOptions& options) {
  const auto bad = [](double x) { return !(x >= 0.0); };  // negative or NaN
  if (bad(options.absolute_error) || !std::isfinite(options.absolute_error))
    throw InputError("distance: absolute_error must be finite and >= 0, got " + std::to_string(options.absolute_error));
  if (bad(options.relative_error) || !std::isfinite(options.relative_error))
    throw InputError("distance: relative_error must be finite and >= 0, got " + std::to_string(options.relative_error));
  if (bad(options.upper_bound))
    throw InputError("distance: upper_bound must be >= 0 (or infinity), got " + std::to_string(options.upper_bound));
}

// The answer in the frames the caller wants: A's frame -> world by pa, -> B's frame by rel^-1.
DistanceResult make_result(const Best& best, const Pose& pa, const Pose& rel, double upper_bound) {
  DistanceResult result;
  if (!best.found) {
    result.distance = upper_bound;
    result.beyond_upper_bound = true;
    return result;
  }
  result.distance = best.distance;
  result.pair = best.pair;
  result.point_a_local = best.point_a;
  result.point_b_local = rel.inverse().apply(best.point_b);
  result.point_a = pa.apply(best.point_a);
  result.point_b = pa.apply(best.point_b);
  return result;
}

// Solid and the surfaces apart (or only known to be at least the upper bound apart): a piece
// inside the other solid makes the distance 0, with that piece's vertex as both points.
void apply_solid(const query_detail::SolidHit& hit, const Pose& pa, DistanceResult& result) {
  if (hit.inside == Inside::none) return;
  const DistanceStats stats = result.stats;
  result = {};
  result.distance = 0.0;
  result.inside = hit.inside;
  result.point_a = result.point_b = pa.apply(hit.point_a_frame);
  result.point_a_local = hit.point_a_frame;
  result.point_b_local = hit.point_b_frame;
  result.stats = stats;
}

// Penetration (DistanceOptions::signed_distance): the deepest vertex of one mesh inside the
// other solid. The vertices of `from` are mapped into the frame of `into` by `map` (map_point,
// as every triangle test of the query) and classified exactly against `into`'s solid; those
// strictly inside are measured to `into`'s surface.
struct Deepest {
  bool found = false;
  double depth = 0.0;
  std::uint32_t vertex = 0;
  Vec3 vertex_frame = Vec3::Zero();   // the vertex, in `into`'s frame
  Vec3 closest_frame = Vec3::Zero();  // its closest point on `into`'s surface, `into`'s frame
};

// The vertices of `from` (mapped by `map`) strictly inside `into`'s solid, in index order.
// `classify(p)` is the exact classification against `into`; `root` (or null: none) is
// `into`'s root box, a cheap cull: a point outside it by more than the rounding allowance
// (query_common.hpp's box margin and the float axes' slack) is outside the solid.
template <class Classify>
void inside_vertices(const Mesh& from, const Pose& map, const CompactBox* root, Classify&& classify,
                     std::vector<Vec3>& points, std::vector<std::uint32_t>& indices) {
  points.clear();
  indices.clear();
  for (std::uint32_t v = 0; v < from.vertices.size(); ++v) {
    const Vec3 p = map_point(map, from.vertices[v]);
    if (root != nullptr) {
      const Vec3 d = p - root->center_d();
      const double margin = kBoxMargin * (query_detail::box_scale(*root) + p.cwiseAbs().maxCoeff()) +
                            kCompactBoxSlack * root->half_extents_d().maxCoeff();
      bool outside = false;
      for (int i = 0; i < 3 && !outside; ++i)
        outside = std::abs(root->axes.col(i).cast<double>().dot(d)) > root->half_extents[i] + margin;
      if (outside) continue;
    }
    if (classify(p) != Containment::inside) continue;
    points.push_back(p);
    indices.push_back(v);
  }
}

// The deepest of `points` (indices[k] the vertex of points[k]) given their closest points on the
// other surface; on a tie the lower index (the first in order).
Deepest deepest_of(std::span<const Vec3> points, std::span<const std::uint32_t> indices,
                   std::span<const ClosestPoint> closest) {
  Deepest best;
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!best.found || closest[k].distance > best.depth)
      best = {true, closest[k].distance, indices[k], points[k], closest[k].point};
  return best;
}

// The penetration answer from the deepest vertex of A inside B (da, B's frame) and of B inside
// A (db, A's frame): the deeper, A's on a tie. False when neither has a vertex inside.
bool apply_penetration(const Deepest& da, const Deepest& db, const Mesh& ma, const Mesh& mb, const Pose& pa,
                       const Pose& pb, DistanceResult& result) {
  if (!da.found && !db.found) return false;
  const DistanceStats stats = result.stats;
  result = {};
  result.stats = stats;
  if (da.found && (!db.found || da.depth >= db.depth)) {
    result.distance = -da.depth;
    result.deepest = Inside::a_in_b;
    result.deepest_vertex = da.vertex;
    result.point_a_local = ma.vertices[da.vertex];
    result.point_b_local = da.closest_frame;
    result.point_a = pb.apply(da.vertex_frame);  // both witnesses through B's pose, as measured
    result.point_b = pb.apply(da.closest_frame);
  } else {
    result.distance = -db.depth;
    result.deepest = Inside::b_in_a;
    result.deepest_vertex = db.vertex;
    result.point_a_local = db.closest_frame;
    result.point_b_local = mb.vertices[db.vertex];
    result.point_a = pa.apply(db.closest_frame);  // both witnesses through A's pose, as measured
    result.point_b = pa.apply(db.vertex_frame);
  }
  return true;
}

// The deepest vertex of `from` inside `into`'s solid, `map` taking `from`'s frame to `into`'s.
// With a tree: classify_point and closest_points on the tree, the root box as a cull; without
// (the brute-force reference): their brute-force versions, no cull. The same frames and the same
// point–triangle distance, so both give the same answer bit for bit.
// With `into_wide` (the wide nodes of into_tree, on models) the points are classified by
// classify_point_wide, the same answers.
Deepest deepest_vertex(const Mesh& from, const Pose& map, const Tree* into_tree, const query_detail::WideTree* into_wide,
                       const Mesh& into, const Closedness& closed) {
  std::vector<Vec3> points;
  std::vector<std::uint32_t> indices;
  PointQueryOptions sequential;
  sequential.threads = 1;  // one query; distance_batch runs the queries in parallel
  if (into_tree != nullptr && into_wide != nullptr) {
    const query_detail::WideRays rays(*into_tree, *into_wide);
    std::vector<query_detail::WideRayItem> wide_stack;
    std::vector<std::uint32_t> stack;
    const auto classify = [&](const Vec3& p) {
      return query_detail::classify_point_wide(*into_tree, *into_wide, rays, into, p, wide_stack, stack);
    };
    inside_vertices(from, map, &into_tree->nodes[0].box, classify, points, indices);
    const std::vector<ClosestPoint> closest = closest_points(*into_tree, into, Pose::identity(), points, sequential);
    return deepest_of(points, indices, closest);
  }
  if (into_tree != nullptr) {
    inside_vertices(from, map, &into_tree->nodes[0].box,
                    [&](const Vec3& p) { return classify_point(*into_tree, into, closed, p); }, points, indices);
    const std::vector<ClosestPoint> closest = closest_points(*into_tree, into, Pose::identity(), points, sequential);
    return deepest_of(points, indices, closest);
  }
  inside_vertices(from, map, nullptr, [&](const Vec3& p) { return classify_point_brute_force(into, closed, p); },
                  points, indices);
  const std::vector<ClosestPoint> closest = closest_points_brute_force(into, Pose::identity(), points, sequential);
  return deepest_of(points, indices, closest);
}

// signed_distance: `result` is the unsigned answer. Surfaces apart (or at least a positive upper
// bound apart) and neither solid nested in the other: unchanged. Otherwise every vertex is
// classified: the deepest inside gives the negative answer; none inside, with the surfaces
// touching, leaves the answer 0 and flags it (the solids touch or cross along edges). With the
// trees when `ta` and `tb` are given, else brute force.
void apply_signed(const Tree* ta, const Mesh& ma, const Pose& pa, const Tree* tb, const Mesh& mb, const Pose& pb,
                  const Pose& rel, const query_detail::SolidMeshes& solid, double upper_bound, DistanceResult& result,
                  const query_detail::WideTree* wa = nullptr, const query_detail::WideTree* wb = nullptr) {
  const bool apart = result.beyond_upper_bound ? upper_bound > 0.0 : result.distance > 0.0;
  if (apart) {
    const query_detail::SolidHit hit =
        ta != nullptr ? solid.overlap(*ta, ma, *tb, mb, rel) : solid.overlap_brute_force(ma, mb, rel);
    if (hit.inside == Inside::none) return;
  }
  const Deepest da = deepest_vertex(ma, rel.inverse(), tb, wb, mb, solid.b());
  const Deepest db = deepest_vertex(mb, rel, ta, wa, ma, solid.a());
  if (apply_penetration(da, db, ma, mb, pa, pb, result) || result.beyond_upper_bound) return;
  result.penetration_lower_bound_is_zero = true;
  // The bound says nothing of how far the surfaces cross: measure their intersection curve.
  const QueryOptions curve{.mode = QueryMode::all_pairs, .contacts = true};
  result.curve_length = ta != nullptr ? collide(*ta, ma, pa, *tb, mb, pb, curve).curve_length
                                      : collide_brute_force(ma, pa, mb, pb, curve).curve_length;
}

}  // namespace

namespace {

// distance() over the binary trees, or over their wide nodes when wa and wb are given.
DistanceResult distance_on(const Tree& a, const query_detail::WideTree* wa, const Mesh& ma, const Pose& pa,
                           const Tree& b, const query_detail::WideTree* wb, const Mesh& mb, const Pose& pb,
                           const DistanceOptions& options, QueryWorkspace& workspace,
                           const query_detail::WideTree* classify_a = nullptr,
                           const query_detail::WideTree* classify_b = nullptr) {
  check_options(options);
  if (a.nodes.empty() || b.nodes.empty()) {
    DistanceResult empty;
    empty.beyond_upper_bound = true;
    return empty;
  }
  query_detail::check_tree_fits_mesh("distance", a, ma, "A");
  query_detail::check_tree_fits_mesh("distance", b, mb, "B");
  std::optional<query_detail::SolidMeshes> solid;  // checked before the descent: open meshes always throw
  if (options.solid || options.signed_distance) solid.emplace("distance", ma, options.closed_a, mb, options.closed_b);
  const Pose rel = relative_pose(pa, pb);
  DistanceSearch search(a, ma, b, mb, rel, options, workspace.scratch());
  if (wa != nullptr && wb != nullptr)
    search.run_wide(*wa, *wb);
  else
    search.run();
  DistanceResult result = make_result(search.best(), pa, rel, options.upper_bound);
  result.stats = search.stats();
  if (options.signed_distance) {
    apply_signed(&a, ma, pa, &b, mb, pb, rel, *solid, options.upper_bound, result, classify_a, classify_b);
    return result;
  }
  if (solid && result.distance > 0.0) apply_solid(solid->overlap(a, ma, b, mb, rel), pa, result);
  return result;
}

}  // namespace

DistanceResult distance(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb, const Pose& pb,
                        const DistanceOptions& options, QueryWorkspace& workspace) {
  return distance_on(a, nullptr, ma, pa, b, nullptr, mb, pb, options, workspace);
}

DistanceResult query_detail::distance_wide(const Tree& a, const WideTree& wa, const Mesh& ma, const Pose& pa,
                                           const Tree& b, const WideTree& wb, const Mesh& mb, const Pose& pb,
                                           const DistanceOptions& options, QueryWorkspace& workspace) {
  return distance_on(a, &wa, ma, pa, b, &wb, mb, pb, options, workspace);
}

DistanceResult query_detail::distance_models(const Tree& a, const WideTree& wa, const Mesh& ma, const Pose& pa,
                                             const Tree& b, const WideTree& wb, const Mesh& mb, const Pose& pb,
                                             const DistanceOptions& options, QueryWorkspace& workspace) {
  return distance_on(a, nullptr, ma, pa, b, nullptr, mb, pb, options, workspace, &wa, &wb);
}

DistanceResult distance(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb, const Pose& pb,
                        const DistanceOptions& options) {
  QueryWorkspace workspace;
  return distance(a, ma, pa, b, mb, pb, options, workspace);
}

std::vector<DistanceResult> distance_batch(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb,
                                           std::span<const Pose> poses_b, const DistanceOptions& options,
                                           unsigned threads) {
  DistanceOptions batch = options;
  batch.solid = options.solid || options.signed_distance;  // the closedness checked once for all poses
  return query_detail::run_batch<DistanceResult>(
      "distance", ma, mb, poses_b, batch, threads,
      [&](const Pose& pose, const DistanceOptions& per_pose, QueryWorkspace& workspace) {
        return distance(a, ma, pa, b, mb, pose, per_pose, workspace);
      });
}

DistanceResult distance_brute_force(const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb,
                                    const DistanceOptions& options) {
  std::optional<query_detail::SolidMeshes> solid;
  if (options.solid || options.signed_distance)
    solid.emplace("distance_brute_force", ma, options.closed_a, mb, options.closed_b);
  const Pose rel = relative_pose(pa, pb);
  std::vector<Vec3> mapped(mb.vertices.size());
  for (std::size_t i = 0; i < mb.vertices.size(); ++i) mapped[i] = map_point(rel, mb.vertices[i]);
  Best best;
  std::uint64_t pairs = 0;
  for (std::uint32_t ia = 0; ia < ma.triangles.size() && best.distance > 0.0; ++ia) {
    const auto [p0, p1, p2] = ma.corners(ia);
    for (std::uint32_t ib = 0; ib < mb.triangles.size(); ++ib) {
      const Triangle& t = mb.triangles[ib];
      ++pairs;
      const TriangleDistance d = tri_tri_distance(p0, p1, p2, mapped[t[0]], mapped[t[1]], mapped[t[2]]);
      if (d.distance < best.distance) {
        best = {d.distance, true, {ia, ib}, d.point_p, d.point_q};
        if (d.distance == 0.0) break;
      }
    }
  }
  DistanceResult result = make_result(best, pa, rel, std::numeric_limits<double>::infinity());
  result.stats.triangle_pairs = pairs;
  if (options.signed_distance) {
    apply_signed(nullptr, ma, pa, nullptr, mb, pb, rel, *solid, std::numeric_limits<double>::infinity(), result);
    return result;
  }
  if (solid && result.distance > 0.0) apply_solid(solid->overlap_brute_force(ma, mb, rel), pa, result);
  return result;
}

}  // namespace tightbvh
