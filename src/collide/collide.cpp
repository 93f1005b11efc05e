// Tree-vs-tree collision queries (Gottschalk, Lin & Manocha 1996 descent; SAT box test;
// Guigue-Devillers triangle test). See include/tightbvh/collide.hpp.
#include "tightbvh/collide.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>

#include "batch.hpp"
#include "box_test.hpp"
#include "pair_sort.hpp"
#include "contact_query.hpp"
#include "query_cache.hpp"
#include "query_common.hpp"
#include "query_workspace.hpp"
#include "solid.hpp"
#include "tightbvh/obb_overlap.hpp"
#include "tightbvh/tri_tri.hpp"
#include "traverse.hpp"
#include "tri_batch.hpp"

namespace tightbvh {
namespace {

using query_detail::map_point;

// The batched box tests of collide_trees for a walk that can use them (traverse_pairs_tested).
template <bool FirstHit, class One, class ChildrenA, class ChildrenB, class ChildrenBoth, class Gap>
struct BatchedTests {
  static constexpr bool first_hit = FirstHit;
  One& one;
  ChildrenA& children_a;
  ChildrenB& children_b;
  ChildrenBoth& children_both;
  Gap& gap;  // first_hit's order of a split's child pairs
  std::uint64_t& box_tests;
};

// WithMargin: pairs within options.margin (boxes inflated by it); without: touching pairs, with
// no margin arithmetic at all. walk(test, leaves, batched) runs the descent:
// traverse_pairs_tested from the roots with the batched tests, or traverse_front from a
// QueryCache's front with the one-pair test.
template <bool FirstHit, bool WithMargin, class Walker>
void collide_trees(const Tree& ta, const Mesh& ma, const Tree& tb, const Mesh& mb, const Pose& rel,
                   const QueryOptions& options, QueryWorkspace::Scratch& ws, QueryResult& result, Walker&& walk) {
  using namespace query_detail;
  double margin = box_allowance(ta, tb, rel);
  if constexpr (WithMargin) margin += options.margin;
  std::uint64_t box_tests = 0, triangle_tests = 0;
  BoxCache& cache = ws.mapped_b;
  cache.begin(tb.nodes.size());
  // B's boxes are mapped into A's frame once per query and node (the cache); box_test.hpp.
  const auto mapped_b = [&](std::uint32_t ib) -> const MappedBox& { return cache.mapped(ib, tb.nodes[ib].box, rel); };
  const auto boxes_overlap = [&](std::uint32_t ia, std::uint32_t ib) {
    ++box_tests;
    return box_overlap(ta.nodes[ia].box, mapped_b(ib), tb.nodes[ib].box.half_extents, margin);
  };
  // A split's two child pairs at once (traverse_pairs_tested counts them when it pops them).
  const auto node_overlaps = [&](std::uint32_t ia, std::uint32_t ib) {
    return box_overlap(ta.nodes[ia].box, mapped_b(ib), tb.nodes[ib].box.half_extents, margin);
  };
  const auto children_of_a = [&](std::uint32_t ia, std::uint32_t ib) {
    const MappedBox& m = mapped_b(ib);
    const Eigen::Vector3f& eb = tb.nodes[ib].box.half_extents;
    return boxes_overlap2(ta.nodes[ia].box, m, eb, ta.nodes[ia + 1].box, m, eb, margin);
  };
  const auto children_of_b = [&](std::uint32_t ia, std::uint32_t ib) {
    const CompactBox& a = ta.nodes[ia].box;
    return boxes_overlap2(a, mapped_b(ib), tb.nodes[ib].box.half_extents, a, mapped_b(ib + 1),
                          tb.nodes[ib + 1].box.half_extents, margin);
  };
  // A split of both nodes: its four child pairs at once (AVX2 lanes where the CPU has them).
  const bool avx2 = avx2_bounds_available();
  const auto children_both = [&](const Node& na, const Node& nb, bool a_major) {
    return boxes_overlap_cross(child_boxes(ta, tb, na, nb, mapped_b), a_major, margin, avx2);
  };
  // first_hit visits a split's overlapping child pairs nearest first (traverse.hpp,
  // sort_nearest_first). Only pairs that a split has just tested are ordered, so B's box is
  // mapped already: read it without the cache's check.
  const auto gap = [&](std::uint32_t ia, std::uint32_t ib) { return center_gap(ta.nodes[ia].box, cache.boxes[ib]); };
  // all_pairs without a margin tests its triangle pairs four at a time where the CPU has AVX2.
  constexpr bool kMayBatch = !FirstHit && !WithMargin;
  [[maybe_unused]] const bool batch_triangles = kMayBatch && avx2;
  [[maybe_unused]] query_detail::TrianglePairBatch batch;
  MappedChunk mapped;
  const auto triangles_touch = [&](std::uint32_t ia_node, std::uint32_t ib_node) {
    const Node& na = ta.nodes[ia_node];
    const Node& nb = tb.nodes[ib_node];
    for (std::uint32_t cb = 0; cb < nb.count; cb += kLeafChunk) {
      const std::uint32_t nbc = map_leaf_chunk(rel, mb, tb, nb, cb, mapped);
      for (std::uint32_t i = 0; i < na.count; ++i) {
        const std::uint32_t ia = ta.triangle_order[na.first + i];
        const Triangle& tri = ma.triangles[ia];
        const Vec3& p0 = ma.vertices[tri[0]];
        const Vec3& p1 = ma.vertices[tri[1]];
        const Vec3& p2 = ma.vertices[tri[2]];
        for (std::uint32_t j = 0; j < nbc; ++j) {
          ++triangle_tests;
          if constexpr (kMayBatch) {
            if (batch_triangles) {
              batch.add(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2],
                        {ia, tb.triangle_order[nb.first + cb + j]}, result);
              continue;
            }
          }
          bool report;
          if constexpr (WithMargin)
            report = within_margin(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2], options.margin);
          else
            report = tri_tri_overlap(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2]);
          if (report) {
            result.hit = true;
            result.pairs.push_back({ia, tb.triangle_order[nb.first + cb + j]});
            if constexpr (FirstHit) return Walk::stop;
          }
        }
      }
    }
    return Walk::go_on;
  };
  walk(boxes_overlap, triangles_touch,
       BatchedTests<FirstHit, decltype(node_overlaps), decltype(children_of_a), decltype(children_of_b),
                    decltype(children_both), decltype(gap)>{node_overlaps, children_of_a, children_of_b, children_both,
                                                            gap, box_tests});
  if constexpr (kMayBatch) batch.flush(result);
  result.stats.box_tests += box_tests;
  result.stats.triangle_tests += triangle_tests;
}

void finish(QueryResult& result) {
  query_detail::sort_unique_pairs(result.pairs);
}

}  // namespace

Pose relative_pose(const Pose& pa, const Pose& pb) {
  // pa^-1 * pb = (Ra^T Rb, Ra^T (tb - ta)), written out: once per pair query, it is a visible share
  // of a near-miss pair (scenes query many of them).
  const Mat3& ra = pa.rotation;
  const Mat3& rb = pb.rotation;
  const Vec3 d = pb.translation - pa.translation;
  Pose rel;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) rel.rotation(i, j) = ra(0, i) * rb(0, j) + ra(1, i) * rb(1, j) + ra(2, i) * rb(2, j);
    rel.translation[i] = ra(0, i) * d.x() + ra(1, i) * d.y() + ra(2, i) * d.z();
  }
  return rel;
}

QueryWorkspace::QueryWorkspace() : scratch_(std::make_unique<Scratch>()) {}
QueryWorkspace::~QueryWorkspace() = default;
QueryWorkspace::QueryWorkspace(QueryWorkspace&&) noexcept = default;
QueryWorkspace& QueryWorkspace::operator=(QueryWorkspace&&) noexcept = default;

namespace {

// The checks and the dispatch on mode and margin shared by the collide overloads. `start` runs
// once the inputs are checked (binding a cache); walk(test, leaves, batched) as in collide_trees.
template <class Start, class Walker>
QueryResult collide_with(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb, const Pose& pb,
                         const QueryOptions& options, QueryWorkspace::Scratch& ws, Start&& start, Walker&& walk) {
  QueryResult result;
  if (a.nodes.empty() || b.nodes.empty()) return result;
  query_detail::check_tree_fits_mesh("collide", a, ma, "A");
  query_detail::check_tree_fits_mesh("collide", b, mb, "B");
  query_detail::check_margin("collide", options.margin);
  query_detail::check_contacts("collide", options);
  std::optional<query_detail::SolidMeshes> solid;  // checked before the descent: open meshes always throw
  if (options.solid) solid.emplace("collide", ma, options.closed_a, mb, options.closed_b);
  start();
  const Pose rel = relative_pose(pa, pb);
  const bool first = options.mode == QueryMode::first_hit;
  if (options.margin == 0.0) {
    if (first)
      collide_trees<true, false>(a, ma, b, mb, rel, options, ws, result, walk);
    else
      collide_trees<false, false>(a, ma, b, mb, rel, options, ws, result, walk);
  } else {
    if (first)
      collide_trees<true, true>(a, ma, b, mb, rel, options, ws, result, walk);
    else
      collide_trees<false, true>(a, ma, b, mb, rel, options, ws, result, walk);
  }
  if (!first) finish(result);
  if (options.contacts) query_detail::add_contacts(result, ma, pa, mb, pb);
  if (solid && !result.hit) {  // no pair: is one solid inside the other?
    result.inside = solid->overlap(a, ma, b, mb, rel).inside;
    result.hit = result.inside != Inside::none;
  }
  return result;
}

}  // namespace

QueryResult collide(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb, const Pose& pb,
                    const QueryOptions& options, QueryWorkspace& workspace) {
  QueryWorkspace::Scratch& ws = workspace.scratch();
  return collide_with(
      a, ma, pa, b, mb, pb, options, ws, [] {},
      [&](auto&, auto& leaves, auto batched) {
        query_detail::traverse_pairs_tested<decltype(batched)::first_hit>(a, b, options.descend, ws.tested_stack, batched.box_tests,
                                            batched.one,
                                            batched.children_a, batched.children_b, batched.children_both, leaves,
                                            batched.gap);
      });
}

QueryResult collide(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb, const Pose& pb,
                    const QueryOptions& options, QueryCache& cache) {
  QueryCache::State& st = cache.state();
  const bool first = options.mode == QueryMode::first_hit;
  return collide_with(
      a, ma, pa, b, mb, pb, options, st.scratch, [&] { st.bind(a, b); },
      [&](auto& test, auto& leaves, auto batched) {
        if (!first) {
          query_detail::traverse_front(a, b, options.descend, st, test, leaves);
          return;
        }
        // first_hit: the leaf pair that touched last time (it usually still does between close
        // poses: one box test), else the cold descent; the front is left to the other modes.
        const auto remember = [&](std::uint32_t ia, std::uint32_t ib) {
          const query_detail::Walk walk = leaves(ia, ib);
          if (walk == query_detail::Walk::stop) st.last_hit = {ia, ib};
          return walk;
        };
        if (st.last_hit && test(st.last_hit->a, st.last_hit->b) &&
            remember(st.last_hit->a, st.last_hit->b) == query_detail::Walk::stop)
          return;
        st.last_hit.reset();
        query_detail::traverse_pairs_tested<true>(a, b, options.descend, st.scratch.tested_stack, batched.box_tests,
                                                  batched.one, batched.children_a, batched.children_b,
                                                  batched.children_both, remember, batched.gap);
      });
}

QueryCache::QueryCache() : state_(std::make_unique<State>()) {}
QueryCache::~QueryCache() = default;
QueryCache::QueryCache(QueryCache&&) noexcept = default;
QueryCache& QueryCache::operator=(QueryCache&&) noexcept = default;
void QueryCache::clear() { state_->clear(); }
std::size_t QueryCache::front_size() const { return state_->front.size(); }
std::uint64_t QueryCache::resets() const { return state_->resets; }

QueryResult collide(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb, const Pose& pb,
                    const QueryOptions& options) {
  QueryWorkspace workspace;
  return collide(a, ma, pa, b, mb, pb, options, workspace);
}

std::vector<QueryResult> collide_batch(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb,
                                       std::span<const Pose> poses_b, const QueryOptions& options, unsigned threads) {
  return query_detail::run_batch<QueryResult>(
      "collide", ma, mb, poses_b, options, threads,
      [&](const Pose& pose, const QueryOptions& per_pose, QueryWorkspace& workspace) {
        return collide(a, ma, pa, b, mb, pose, per_pose, workspace);
      });
}

QueryResult collide_brute_force(const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb,
                                const QueryOptions& options) {
  query_detail::check_margin("collide", options.margin);
  query_detail::check_contacts("collide_brute_force", options);
  std::optional<query_detail::SolidMeshes> solid;
  if (options.solid) solid.emplace("collide_brute_force", ma, options.closed_a, mb, options.closed_b);
  QueryResult result;
  const Pose rel = relative_pose(pa, pb);
  std::vector<Vec3> mapped(mb.vertices.size());
  for (std::size_t i = 0; i < mb.vertices.size(); ++i) mapped[i] = map_point(rel, mb.vertices[i]);
  for (std::uint32_t ia = 0; ia < ma.triangles.size(); ++ia) {
    const auto [p0, p1, p2] = ma.corners(ia);
    for (std::uint32_t ib = 0; ib < mb.triangles.size(); ++ib) {
      const Triangle& t = mb.triangles[ib];
      ++result.stats.triangle_tests;
      const bool report = options.margin == 0.0 ? tri_tri_overlap(p0, p1, p2, mapped[t[0]], mapped[t[1]], mapped[t[2]])
                                                : query_detail::within_margin(p0, p1, p2, mapped[t[0]], mapped[t[1]],
                                                                              mapped[t[2]], options.margin);
      if (report) {
        result.hit = true;
        result.pairs.push_back({ia, ib});
        if (options.mode == QueryMode::first_hit) return result;
      }
    }
  }
  if (options.contacts) query_detail::add_contacts(result, ma, pa, mb, pb);
  if (solid && !result.hit) {
    result.inside = solid->overlap_brute_force(ma, mb, rel).inside;
    result.hit = result.inside != Inside::none;
  }
  return result;  // already sorted and unique
}

}  // namespace tightbvh
