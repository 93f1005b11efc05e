// collide_trace(): collide()'s descent, recorded (include/tightbvh/collide_trace.hpp). Kept apart
// from collide.cpp so that the hot loop there stays as it is; the node test and the leaf test
// below must stay the same computation as collide_trees() (traverse_pairs visits the pairs of
// collide()'s traverse_pairs_tested in the same order; the same box test of box_test.hpp and
// helpers of query_common.hpp and query_workspace.hpp, same triangle order in the leaves), which
// tests/collide/trace_test.cpp checks by comparing first hits and test counts with collide().
#include "tightbvh/collide_trace.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "box_test.hpp"
#include "pair_sort.hpp"
#include "query_common.hpp"
#include "query_workspace.hpp"
#include "tightbvh/obb_overlap.hpp"
#include "tightbvh/tri_tri.hpp"
#include "traverse.hpp"

namespace tightbvh {

using namespace query_detail;

CollideTrace collide_trace(const Tree& ta, const Mesh& ma, const Pose& pa, const Tree& tb, const Mesh& mb,
                           const Pose& pb, const QueryOptions& options, const CollideTraceOptions& trace_options) {
  CollideTrace trace;
  QueryResult& result = trace.result;
  if (ta.nodes.empty() || tb.nodes.empty()) return trace;
  check_tree_fits_mesh("collide", ta, ma, "A");
  check_tree_fits_mesh("collide", tb, mb, "B");
  check_margin("collide", options.margin);
  const bool first_hit = options.mode == QueryMode::first_hit;
  const bool with_margin = options.margin != 0.0;
  const Pose rel = relative_pose(pa, pb);
  double margin = box_allowance(ta, tb, rel);
  if (with_margin) margin += options.margin;
  const std::vector<std::uint32_t> depth_a = node_depths(ta), depth_b = node_depths(tb);

  // Each visited pair, recorded as the node test sees it; a leaf pair's outcome is settled by the
  // leaf test, which traverse_pairs calls right after a passing node test of two leaves.
  bool last_recorded = false;
  const auto record = [&](std::uint32_t ia, std::uint32_t ib, PairOutcome outcome) {
    const std::uint32_t level = depth_a[ia] + depth_b[ib];
    if (trace.per_level.size() <= level) trace.per_level.resize(level + 1, {});
    ++trace.per_level[level][static_cast<std::size_t>(outcome)];
    ++trace.visited;
    last_recorded = trace.pairs.size() < trace_options.max_pairs;
    if (last_recorded) trace.pairs.push_back({ia, ib, level, outcome});
  };
  const auto mark_last_hit = [&](std::uint32_t ia, std::uint32_t ib) {
    auto& counts = trace.per_level[depth_a[ia] + depth_b[ib]];
    --counts[static_cast<std::size_t>(PairOutcome::leaves)];
    ++counts[static_cast<std::size_t>(PairOutcome::hit)];
    if (last_recorded) trace.pairs.back().outcome = PairOutcome::hit;
  };

  BoxCache cache;
  cache.begin(tb.nodes.size());
  const auto boxes_overlap = [&](std::uint32_t ia, std::uint32_t ib) {
    const CompactBox& ba = ta.nodes[ia].box;
    const CompactBox& bb = tb.nodes[ib].box;
    ++result.stats.box_tests;
    const MappedBox& mapped_box = cache.mapped(ib, bb, rel);  // B's box in A's frame, once per query
    // collide() tests a split's two child pairs at once (boxes_overlap2), lane by lane the same
    // arithmetic as this one-pair test, and counts them as they are popped: the same counts.
    const bool overlap = box_overlap(ba, mapped_box, bb.half_extents, margin);
    const bool leaves = ta.nodes[ia].is_leaf() && tb.nodes[ib].is_leaf();
    record(ia, ib, !overlap ? PairOutcome::culled : leaves ? PairOutcome::leaves : PairOutcome::descended);
    return overlap;
  };
  MappedChunk mapped;
  const auto triangles_touch = [&](std::uint32_t ia_node, std::uint32_t ib_node) {
    const Node& na = ta.nodes[ia_node];
    const Node& nb = tb.nodes[ib_node];
    bool reported = false;
    for (std::uint32_t cb = 0; cb < nb.count; cb += kLeafChunk) {
      const std::uint32_t nbc = map_leaf_chunk(rel, mb, tb, nb, cb, mapped);
      for (std::uint32_t i = 0; i < na.count; ++i) {
        const std::uint32_t ia = ta.triangle_order[na.first + i];
        const auto [p0, p1, p2] = ma.corners(ia);
        for (std::uint32_t j = 0; j < nbc; ++j) {
          ++result.stats.triangle_tests;
          const bool report = with_margin
                                  ? within_margin(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2], options.margin)
                                  : tri_tri_overlap(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2]);
          if (!report) continue;
          result.hit = true;
          result.pairs.push_back({ia, tb.triangle_order[nb.first + cb + j]});
          if (!reported) mark_last_hit(ia_node, ib_node);
          reported = true;
          if (first_hit) return Walk::stop;
        }
      }
    }
    return Walk::go_on;
  };
  PairStack stack;
  if (first_hit) {  // collide()'s first_hit order: a split's overlapping child pairs nearest first
    const auto gap = [&](std::uint32_t ia, std::uint32_t ib) {
      return center_gap(ta.nodes[ia].box, cache.mapped(ib, tb.nodes[ib].box, rel));
    };
    const auto overlaps = [&](std::uint32_t ia, std::uint32_t ib) {  // not counted, not recorded
      return box_overlap(ta.nodes[ia].box, cache.mapped(ib, tb.nodes[ib].box, rel), tb.nodes[ib].box.half_extents,
                         margin);
    };
    traverse_pairs(ta, tb, options.descend, stack, boxes_overlap, triangles_touch, NearestFirst{gap, overlaps});
  } else {
    traverse_pairs(ta, tb, options.descend, stack, boxes_overlap, triangles_touch);
  }
  if (!first_hit) {
    query_detail::sort_unique_pairs(result.pairs);
  }
  return trace;
}

}  // namespace tightbvh
