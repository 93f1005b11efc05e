// collide_trace() is collide()'s real descent: same answer, same first hit, same test counts, on
// shipped meshes, for both modes, both descent rules, margins and leaves wider than one chunk,
// with splits of one node (two child pairs tested at once) and of both (four).
#include "tightbvh/collide_trace.hpp"

#include <gtest/gtest.h>

#include <numeric>
#include <string>

#include "collide/traverse.hpp"
#include "query_fixtures.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/error.hpp"

namespace tightbvh {
namespace {

using namespace query_test;

std::uint64_t count(const CollideTrace& trace, PairOutcome outcome) {
  std::uint64_t n = 0;
  for (const auto& level : trace.per_level) n += level[static_cast<std::size_t>(outcome)];
  return n;
}

// Returns the number of poses with a hit.
int expect_trace_is_the_descent(const Mesh& ma, const Mesh& mb, const Fitter& fitter, std::uint32_t leaf_size,
                                std::uint64_t seed, double margin = 0.0) {
  const Tree ta = build(ma, {.fitter = fitter, .leaf_size = leaf_size, .threads = 1});
  const Tree tb = build(mb, {.fitter = fitter, .leaf_size = leaf_size, .threads = 1});
  int hits = 0;
  std::uint64_t splits_of_both = 0;
  const auto poses = random_poses(ma, mb, seed, {0.0, 0.3, 0.6, 0.8, 1.1});
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto& [pa, pb] = poses[i];
    for (const QueryMode mode : {QueryMode::first_hit, QueryMode::all_pairs})
      for (const DescendRule rule : {DescendRule::larger_volume, DescendRule::larger_extent}) {
        SCOPED_TRACE("pose " + std::to_string(i) + (mode == QueryMode::first_hit ? " first_hit" : " all_pairs") +
                     (rule == DescendRule::larger_volume ? " volume" : " extent"));
        const QueryOptions options{.mode = mode, .descend = rule, .margin = margin};
        const QueryResult expected = collide(ta, ma, pa, tb, mb, pb, options);
        const CollideTrace trace = collide_trace(ta, ma, pa, tb, mb, pb, options);
        EXPECT_EQ(trace.result.hit, expected.hit);
        EXPECT_EQ(trace.result.pairs, expected.pairs);  // first_hit: the same first pair
        EXPECT_EQ(trace.result.stats, expected.stats);
        // Every box test is one visited pair, all recorded here (fewer than max_pairs).
        EXPECT_EQ(trace.visited, expected.stats.box_tests);
        EXPECT_EQ(trace.pairs.size(), trace.visited);
        std::uint64_t per_level = 0;
        for (const auto& level : trace.per_level) per_level += std::accumulate(level.begin(), level.end(), 0ull);
        EXPECT_EQ(per_level, trace.visited);
        if (trace.pairs.empty()) {
          ADD_FAILURE() << "no pair recorded";
          continue;
        }
        EXPECT_EQ(trace.pairs[0].a, 0u);
        EXPECT_EQ(trace.pairs[0].b, 0u);
        EXPECT_EQ(trace.pairs[0].level, 0u);
        EXPECT_EQ(count(trace, PairOutcome::hit) > 0, expected.hit);
        if (mode == QueryMode::all_pairs) {
          // Each descended pair pushes its two children, or four when both nodes split (nodes of
          // about one size), and every pushed pair is visited.
          std::uint64_t pushed = 0, both = 0;
          for (const VisitedPair& p : trace.pairs) {
            if (p.outcome != PairOutcome::descended) continue;
            const bool split_both =
                query_detail::splits_both(query_detail::choose_split(ta.nodes[p.a], tb.nodes[p.b], rule));
            pushed += split_both ? 4 : 2;
            both += split_both;
          }
          EXPECT_EQ(trace.visited, 1 + pushed);
          splits_of_both += both;
        } else if (expected.hit) {
          EXPECT_EQ(trace.pairs.back().outcome, PairOutcome::hit);  // the descent stopped there
          EXPECT_EQ(count(trace, PairOutcome::hit), 1u);
        }
        // Outcomes agree with the nodes: leaf pairs are leaves/hit, others descended.
        for (const VisitedPair& p : trace.pairs) {
          const bool leaves = ta.nodes[p.a].is_leaf() && tb.nodes[p.b].is_leaf();
          if (p.outcome == PairOutcome::descended) EXPECT_FALSE(leaves);
          if (p.outcome == PairOutcome::leaves || p.outcome == PairOutcome::hit) EXPECT_TRUE(leaves);
        }
        hits += expected.hit && mode == QueryMode::first_hit && rule == DescendRule::larger_volume;
      }
  }
  EXPECT_GT(splits_of_both, 0u) << "no pair split both nodes: the four-lane path went untested";
  return hits;
}

TEST(CollideTrace, IsTheDescentOfCollideOnShippedMeshes) {
  const Mesh knot = subset(shipped("meshes/knot1.off"), 2);
  const Mesh elephant = subset(shipped("meshes/elephant.off"), 2);
  EXPECT_GE(expect_trace_is_the_descent(knot, elephant, FitMethod::pca, 1, 31), 2);
  EXPECT_GE(expect_trace_is_the_descent(elephant, knot, AutoFit{}, 1, 32), 2);
  // Leaves wider than collide's 32-triangle chunk: the order of the triangle tests matters.
  EXPECT_GE(expect_trace_is_the_descent(knot, elephant, FitMethod::aabb, 80, 33), 2);
  // Margin: the same box inflation and triangle predicate.
  EXPECT_GE(expect_trace_is_the_descent(knot, elephant, FitMethod::pca, 4, 34, 0.02), 2);
}

TEST(CollideTrace, MaxPairsKeepsThePrefixAndCountsEverything) {
  const Mesh knot = subset(shipped("meshes/knot1.off"), 4);
  const Mesh sphere = uv_sphere(10, 16, 0.3);
  const Tree ta = build(knot, {.fitter = FitMethod::pca, .threads = 1});
  const Tree tb = build(sphere, {.fitter = FitMethod::pca, .threads = 1});
  const Pose pb{Mat3::Identity(), knot.vertices[knot.triangles[0][0]]};  // on the knot's surface
  const QueryOptions options{.mode = QueryMode::all_pairs};
  const CollideTrace full = collide_trace(ta, knot, Pose{}, tb, sphere, pb, options);
  ASSERT_TRUE(full.result.hit);
  ASSERT_GT(full.visited, 20u);
  const CollideTrace capped = collide_trace(ta, knot, Pose{}, tb, sphere, pb, options, {.max_pairs = 20});
  EXPECT_EQ(capped.visited, full.visited);
  EXPECT_EQ(capped.per_level, full.per_level);
  EXPECT_EQ(capped.result.pairs, full.result.pairs);
  ASSERT_EQ(capped.pairs.size(), 20u);
  for (std::size_t i = 0; i < 20; ++i) {
    EXPECT_EQ(capped.pairs[i].a, full.pairs[i].a);
    EXPECT_EQ(capped.pairs[i].b, full.pairs[i].b);
    EXPECT_EQ(capped.pairs[i].outcome, full.pairs[i].outcome);
  }
}

TEST(CollideTrace, EmptyTreesAndBadInput) {
  const Mesh sphere = uv_sphere(6, 8);
  const Tree tree = build(sphere, {.fitter = FitMethod::pca, .threads = 1});
  const CollideTrace none = collide_trace(Tree{}, Mesh{}, Pose{}, tree, sphere, Pose{});
  EXPECT_FALSE(none.result.hit);
  EXPECT_EQ(none.visited, 0u);
  EXPECT_THROW((void)collide_trace(tree, sphere, Pose{}, tree, sphere, Pose{}, {.margin = -1.0}), InputError);
  EXPECT_THROW((void)collide_trace(tree, uv_sphere(5, 8), Pose{}, tree, sphere, Pose{}), InputError);
}

}  // namespace
}  // namespace tightbvh
