// QueryCache (front tracking): cached queries along smooth pose sequences give the cold
// queries' answers (all_pairs: the same pairs; first_hit: the same hit flag and a touching pair).
#include "tightbvh/query_cache.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "query_fixtures.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/model.hpp"

namespace tightbvh {
namespace {

using namespace query_test;

// B's poses (A at pa) along a smooth path: B's center from end_gap (rA + rB) from A's center
// (1.15: apart) down to 0.15 (deep overlap) and back to end_gap, along a slowly turning
// direction, B turning slowly about a fixed axis. Consecutive poses are close; `steps` poses.
std::vector<Pose> trajectory(const Mesh& ma, const Pose& pa, const Mesh& mb, int steps, std::uint64_t seed,
                             double end_gap = 1.15) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n;
  const Sphere sa = bounding_sphere(ma), sb = bounding_sphere(mb);
  const Mat3 r0 = random_rotation(rng);
  const Vec3 spin = Vec3(n(rng), n(rng), n(rng)).normalized();
  const Vec3 d0 = Vec3(n(rng), n(rng), n(rng)).normalized();
  const Vec3 turn = d0.cross(Vec3(n(rng), n(rng), n(rng))).normalized();
  std::vector<Pose> poses;
  for (int i = 0; i < steps; ++i) {
    const double t = double(i) / (steps - 1);
    const double gap = end_gap + (0.15 - end_gap) * std::sin(M_PI * t);
    const Vec3 dir = Eigen::AngleAxisd(0.8 * t, turn) * d0;
    Pose pb{Eigen::AngleAxisd(1.5 * t, spin).toRotationMatrix() * r0, Vec3::Zero()};
    pb.translation = pa.apply(sa.center) + gap * (sa.radius + sb.radius) * dir - pb.rotation * sb.center;
    poses.push_back(pb);
  }
  return poses;
}

bool contains(const std::vector<TrianglePair>& sorted, const TrianglePair& p) {
  return std::binary_search(sorted.begin(), sorted.end(), p);
}

// Cached vs cold along a trajectory, both modes, margin 0 and > 0, one cache per mode plus one
// cache shared by every mode, margin and descend rule (interleaved).
struct SequenceSummary {
  int contacts = 0;  // poses with contact
};
SequenceSummary expect_cache_matches_cold(const Tree& ta, const Mesh& ma, const Tree& tb, const Mesh& mb,
                                          const std::vector<Pose>& poses, const Pose& pa, double margin) {
  QueryCache first_cache, all_cache, margin_cache, mixed_cache;
  SequenceSummary summary;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    SCOPED_TRACE("pose " + std::to_string(i));
    const Pose& pb = poses[i];
    const QueryOptions all{.mode = QueryMode::all_pairs};
    const QueryOptions first{.mode = QueryMode::first_hit};
    const QueryOptions within{.mode = QueryMode::all_pairs, .margin = margin};
    const QueryResult cold = collide(ta, ma, pa, tb, mb, pb, all);
    const QueryResult cold_margin = collide(ta, ma, pa, tb, mb, pb, within);

    const QueryResult cached = collide(ta, ma, pa, tb, mb, pb, all, all_cache);
    EXPECT_EQ(cached.hit, cold.hit);
    EXPECT_EQ(cached.pairs, cold.pairs);
    const QueryResult hit = collide(ta, ma, pa, tb, mb, pb, first, first_cache);
    EXPECT_EQ(hit.hit, cold.hit);
    EXPECT_EQ(hit.pairs.size(), hit.hit ? 1u : 0u);
    if (hit.hit && !hit.pairs.empty()) {
      EXPECT_TRUE(contains(cold.pairs, hit.pairs[0]));
    }
    const QueryResult cached_margin = collide(ta, ma, pa, tb, mb, pb, within, margin_cache);
    EXPECT_EQ(cached_margin.pairs, cold_margin.pairs);
    EXPECT_EQ(cached_margin.hit, cold_margin.hit);

    // One cache through every kind of query: the front is valid whatever produced it.
    QueryOptions mixed = i % 3 == 0 ? first : i % 3 == 1 ? all : within;
    if (i % 2) mixed.descend = DescendRule::larger_extent;
    const QueryResult m = collide(ta, ma, pa, tb, mb, pb, mixed, mixed_cache);
    const QueryResult& expected = mixed.margin > 0 ? cold_margin : cold;
    EXPECT_EQ(m.hit, expected.hit);
    if (mixed.mode == QueryMode::all_pairs) {
      EXPECT_EQ(m.pairs, expected.pairs);
    } else if (m.hit) {
      EXPECT_EQ(m.pairs.size(), 1u);
      EXPECT_TRUE(!m.pairs.empty() && contains(expected.pairs, m.pairs[0]));
    }

    summary.contacts += cold.hit;
    EXPECT_EQ(all_cache.resets(), 0u);
    EXPECT_EQ(mixed_cache.resets(), 0u);
  }
  return summary;
}

// Real meshes (halved knot and elephant), poses through apart, near and deep configurations.
TEST(QueryCache, TrajectoryOnShippedMeshesMatchesColdQueries) {
  const Mesh knot = subset(shipped("meshes/knot1.off"), 2);
  const Mesh elephant = subset(shipped("meshes/elephant.off"), 2);
  const Tree ta = build(knot, {.fitter = FitMethod::pca, .threads = 1});
  const Tree tb = build(elephant, {.fitter = FitMethod::aabb, .leaf_size = 2, .threads = 1});
  const Pose pa{Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix(), Vec3(0.5, -1, 2)};
  const double margin = 0.01 * bounding_sphere(knot).radius;
  int contacts = 0;
  for (const std::uint64_t seed : {1, 2}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    contacts += expect_cache_matches_cold(ta, knot, tb, elephant, trajectory(knot, pa, elephant, 30, seed), pa,
                                          margin)
                    .contacts;
  }
  EXPECT_GE(contacts, 20);
  EXPECT_LE(contacts, 56);
}

// The front follows the contact: approaching, then holding one pose with contact, the front is
// lifted back towards the cold descent's cut (it does not only grow) and a query costs fewer box
// tests than a cold one; first_hit answers from the previous hit's leaf pair.
TEST(QueryCache, FrontIsLiftedWhileAPoseIsHeld) {
  const Mesh knot = subset(shipped("meshes/knot1.off"), 2);
  const Mesh elephant = subset(shipped("meshes/elephant.off"), 2);
  const Tree ta = build(knot, {.fitter = FitMethod::pca, .threads = 1});
  const Tree tb = build(elephant, {.fitter = FitMethod::pca, .threads = 1});
  const Pose pa = Pose::identity();
  std::vector<Pose> poses = trajectory(knot, pa, elephant, 60, 1, 0.55);
  const std::size_t held_from = poses.size() - 1;
  for (int k = 0; k < 8; ++k) poses.push_back(poses.back());
  const double margin = 0.01 * bounding_sphere(knot).radius;
  const SequenceSummary s = expect_cache_matches_cold(ta, knot, tb, elephant, poses, pa, margin);
  EXPECT_GT(s.contacts, 20);
  QueryCache all_cache, first_cache;
  std::size_t front_when_held = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const QueryResult all = collide(ta, knot, pa, tb, elephant, poses[i], {.mode = QueryMode::all_pairs}, all_cache);
    const QueryResult first =
        collide(ta, knot, pa, tb, elephant, poses[i], {.mode = QueryMode::first_hit}, first_cache);
    if (i == held_from) front_when_held = all_cache.front_size();
    if (i + 1 == poses.size()) {
      const QueryResult cold = collide(ta, knot, pa, tb, elephant, poses[i], {.mode = QueryMode::all_pairs});
      ASSERT_TRUE(cold.hit);
      EXPECT_EQ(all.pairs, cold.pairs);
      EXPECT_LT(all_cache.front_size() * 5, front_when_held * 4) << front_when_held << " -> " << all_cache.front_size();
      EXPECT_LT(all.stats.box_tests * 4, cold.stats.box_tests * 3) << "cold " << cold.stats.box_tests;
      EXPECT_TRUE(first.hit);
      EXPECT_LE(first.stats.box_tests, 2u);
    }
  }
}

// Small meshes: every pose against brute force (every triangle pair), leaf sizes 1 and 3.
TEST(QueryCache, TrajectoryMatchesBruteForce) {
  const Mesh ma = subset(shipped("meshes/knot1.off"), 40);  // 160 triangles
  const Mesh mb = uv_sphere(6, 10, 0.2);
  const Pose pa = Pose::identity();
  for (const std::uint32_t leaf_size : {1u, 3u}) {
    const Tree ta = build(ma, {.fitter = FitMethod::approx, .leaf_size = leaf_size, .threads = 1});
    const Tree tb = build(mb, {.fitter = FitMethod::pca, .leaf_size = leaf_size, .threads = 1});
    QueryCache all_cache, first_cache;
    int contacts = 0;
    for (const Pose& pb : trajectory(ma, pa, mb, 40, 7 + leaf_size)) {
      const QueryResult reference = collide_brute_force(ma, pa, mb, pb, {.mode = QueryMode::all_pairs});
      const QueryResult all = collide(ta, ma, pa, tb, mb, pb, {.mode = QueryMode::all_pairs}, all_cache);
      EXPECT_EQ(all.pairs, reference.pairs);
      EXPECT_EQ(all.hit, reference.hit);
      const QueryResult first = collide(ta, ma, pa, tb, mb, pb, {.mode = QueryMode::first_hit}, first_cache);
      EXPECT_EQ(first.hit, reference.hit);
      if (first.hit) {
        ASSERT_EQ(first.pairs.size(), 1u);
        EXPECT_TRUE(contains(reference.pairs, first.pairs[0]));
      }
      contacts += reference.hit;
    }
    EXPECT_GT(contacts, 3);
  }
}

// A cache used with other trees (same counts, other topology; swapped order; other sizes)
// restarts from the roots and still answers right; clear() empties it.
TEST(QueryCache, OtherTreesRestartFromTheRoots) {
  const Mesh ma = subset(shipped("meshes/knot1.off"), 20);
  const Mesh mb = uv_sphere(8, 12, 0.3);
  const Tree ta = build(ma, {.fitter = FitMethod::pca, .threads = 1});
  const Tree ta_other = build(ma, {.fitter = FitMethod::aabb, .threads = 1});  // same node count
  ASSERT_EQ(ta.nodes.size(), ta_other.nodes.size());
  const Tree tb = build(mb, {.fitter = FitMethod::pca, .leaf_size = 4, .threads = 1});
  const Pose pa = Pose::identity();
  const std::vector<Pose> poses = trajectory(ma, pa, mb, 12, 3);
  QueryCache cache;
  EXPECT_EQ(cache.front_size(), 0u);
  const QueryOptions all{.mode = QueryMode::all_pairs};
  std::uint64_t expected_resets = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    SCOPED_TRACE("pose " + std::to_string(i));
    const Pose& pb = poses[i];
    // Alternate (ta, tb), (ta_other, tb), (tb, ta): each switch restarts.
    QueryResult r;
    if (i % 3 == 0) {
      r = collide(ta, ma, pa, tb, mb, pb, all, cache);
      EXPECT_EQ(r.pairs, collide(ta, ma, pa, tb, mb, pb, all).pairs);
    } else if (i % 3 == 1) {
      r = collide(ta_other, ma, pa, tb, mb, pb, all, cache);
      EXPECT_EQ(r.pairs, collide(ta_other, ma, pa, tb, mb, pb, all).pairs);
    } else {
      r = collide(tb, mb, pb, ta, ma, pa, all, cache);
      EXPECT_EQ(r.pairs, collide(tb, mb, pb, ta, ma, pa, all).pairs);
    }
    if (i > 0) ++expected_resets;
    EXPECT_EQ(cache.resets(), expected_resets);
    EXPECT_GT(cache.front_size(), 0u);
  }
  cache.clear();
  EXPECT_EQ(cache.front_size(), 0u);
  (void)collide(ta, ma, pa, tb, mb, poses[0], all, cache);
  EXPECT_EQ(cache.resets(), expected_resets);  // after clear() a new fill is not a reset
  // A mesh that does not fit its tree is an error, as without a cache; an empty tree never hits.
  Mesh fewer = ma;
  fewer.triangles.pop_back();
  EXPECT_THROW((void)collide(ta, fewer, pa, tb, mb, poses[0], all, cache), InputError);
  EXPECT_THROW((void)collide(ta, ma, pa, tb, mb, poses[0], {.margin = -1.0}, cache), InputError);
  EXPECT_FALSE(collide(Tree{}, ma, pa, tb, mb, poses[0], all, cache).hit);
}

// Models through a cache (the wide descent, first_hit trying last hit's triangle pair first):
// every mode and a margin give the cold queries' answers on models along trajectories, and most
// first_hit queries in contact are answered by the witness alone (no box test).
TEST(QueryCache, ModelsAlongATrajectoryGiveTheColdAnswers) {
  const Mesh knot = subset(shipped("meshes/knot1.off"), 2);
  const Mesh elephant = subset(shipped("meshes/elephant.off"), 2);
  for (const Fitter& fitter : {Fitter{AutoFit{}}, Fitter{FitMethod::approx}}) {
    const Model a(knot, {.fitter = fitter, .threads = 1});
    const Model b(elephant, {.fitter = fitter, .threads = 1});
    const Pose pa{Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix(), Vec3(0.5, -1, 2)};
    const double margin = 0.01 * bounding_sphere(knot).radius;
    const QueryOptions all{.mode = QueryMode::all_pairs};
    const QueryOptions first{.mode = QueryMode::first_hit};
    const QueryOptions within{.mode = QueryMode::all_pairs, .margin = margin};
    const QueryOptions first_within{.mode = QueryMode::first_hit, .margin = margin};
    QueryCache first_cache, all_cache, margin_cache, first_margin_cache;
    int contacts = 0, witnessed = 0;
    for (const std::uint64_t seed : {1, 2}) {
      const std::vector<Pose> poses = trajectory(knot, pa, elephant, 240, seed, 0.6);
      for (std::size_t i = 0; i < poses.size(); ++i) {
        SCOPED_TRACE("seed " + std::to_string(seed) + " pose " + std::to_string(i));
        const Pose& pb = poses[i];
        const QueryResult cold = collide(a, pa, b, pb, all);
        const QueryResult cold_margin = collide(a, pa, b, pb, within);
        const QueryResult cached = collide(a, pa, b, pb, all, all_cache);
        EXPECT_EQ(cached.pairs, cold.pairs);
        EXPECT_EQ(cached.stats.box_tests, cold.stats.box_tests);  // the same descent
        EXPECT_EQ(collide(a, pa, b, pb, within, margin_cache).pairs, cold_margin.pairs);
        const QueryResult hit = collide(a, pa, b, pb, first, first_cache);
        EXPECT_EQ(hit.hit, cold.hit);
        ASSERT_EQ(hit.pairs.size(), hit.hit ? 1u : 0u);
        if (hit.hit) EXPECT_TRUE(contains(cold.pairs, hit.pairs[0]));
        const QueryResult hit_within = collide(a, pa, b, pb, first_within, first_margin_cache);
        EXPECT_EQ(hit_within.hit, cold_margin.hit);
        if (hit_within.hit) EXPECT_TRUE(contains(cold_margin.pairs, hit_within.pairs.at(0)));
        contacts += cold.hit;
        witnessed += hit.hit && hit.stats.box_tests == 0;
      }
    }
    EXPECT_GE(contacts, 40);
    EXPECT_GT(witnessed * 2, contacts) << witnessed << " of " << contacts;
    EXPECT_EQ(first_cache.resets() + all_cache.resets(), 0u);
  }
}

// Small models against brute force, and solids: a cube inside a closed sphere is reported
// inside through the cache as without it, with the witness of an earlier touching pose.
TEST(QueryCache, ModelsMatchBruteForceAndSolids) {
  const Mesh ma = subset(shipped("meshes/knot1.off"), 40);
  const Mesh mb = uv_sphere(6, 10, 0.2);
  const Model a(ma, {.fitter = FitMethod::approx, .leaf_size = 3, .threads = 1});
  const Model b(mb, {.fitter = FitMethod::pca, .leaf_size = 1, .threads = 1});
  const Pose pa = Pose::identity();
  QueryCache all_cache, first_cache;
  int contacts = 0;
  for (const Pose& pb : trajectory(ma, pa, mb, 40, 9)) {
    const QueryResult reference = collide_brute_force(ma, pa, mb, pb, {.mode = QueryMode::all_pairs});
    EXPECT_EQ(collide(a, pa, b, pb, {.mode = QueryMode::all_pairs}, all_cache).pairs, reference.pairs);
    const QueryResult first = collide(a, pa, b, pb, {.mode = QueryMode::first_hit}, first_cache);
    EXPECT_EQ(first.hit, reference.hit);
    if (first.hit) EXPECT_TRUE(contains(reference.pairs, first.pairs.at(0)));
    contacts += reference.hit;
  }
  EXPECT_GT(contacts, 3);

  const Model sphere(uv_sphere(12, 16, 1.0), {.threads = 1});
  const Model box(cube(Vec3::Constant(-0.25), 0.5), {.threads = 1});
  const QueryOptions solid{.mode = QueryMode::first_hit, .solid = true};
  QueryCache cache;
  // The cube's corners cross the sphere at x = 0.95: a witness pair is stored.
  const Pose touching{Mat3::Identity(), Vec3(0.95, 0, 0)};
  const QueryResult touch = collide(sphere, Pose::identity(), box, touching, solid, cache);
  ASSERT_TRUE(touch.hit);
  EXPECT_EQ(touch.inside, Inside::none);
  // Held still: the witness answers.
  EXPECT_EQ(collide(sphere, Pose::identity(), box, touching, solid, cache).stats.box_tests, 0u);
  // Moved inside: the witness misses, the descent finds no pair, the solid test answers.
  const QueryResult inside = collide(sphere, Pose::identity(), box, Pose::identity(), solid, cache);
  EXPECT_TRUE(inside.hit);
  EXPECT_EQ(inside.inside, Inside::b_in_a);
  EXPECT_TRUE(inside.pairs.empty());
  EXPECT_EQ(inside.inside, collide(sphere, Pose::identity(), box, Pose::identity(), solid).inside);
}

// A cache moved between pairs of models forgets its witness (resets() counts it) and answers
// right; another descend rule goes to the trees' front; bad poses are errors as without it.
TEST(QueryCache, ModelsOtherModelsForgetTheWitness) {
  const Mesh ma = subset(shipped("meshes/knot1.off"), 20);
  const Mesh mb = uv_sphere(8, 12, 0.3);
  const Model a(ma, {.threads = 1});
  const Model b(mb, {.threads = 1});
  const Pose pa = Pose::identity();
  const std::vector<Pose> poses = trajectory(ma, pa, mb, 12, 3, 0.5);
  const QueryOptions first{.mode = QueryMode::first_hit};
  QueryCache cache;
  std::uint64_t hits = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    SCOPED_TRACE("pose " + std::to_string(i));
    const bool swapped = i % 2 == 1;
    const std::uint64_t resets = cache.resets();
    const QueryResult r = swapped ? collide(b, poses[i], a, pa, first, cache) : collide(a, pa, b, poses[i], first, cache);
    const QueryResult cold = swapped ? collide(b, poses[i], a, pa, first) : collide(a, pa, b, poses[i], first);
    EXPECT_EQ(r.hit, cold.hit);
    // A switch resets when the other pair's witness was held (the last query hit).
    EXPECT_EQ(cache.resets(), resets + (i > 0 && hits > 0 ? 1u : 0u));
    hits = r.hit ? 1 : 0;
  }
  EXPECT_EQ(cache.front_size(), 0u);  // the models' route keeps no front
  const QueryResult extent = collide(a, pa, b, poses[6], {.mode = QueryMode::all_pairs,
                                                          .descend = DescendRule::larger_extent}, cache);
  EXPECT_EQ(extent.pairs, collide(a, pa, b, poses[6], {.mode = QueryMode::all_pairs}).pairs);
  EXPECT_GT(cache.front_size(), 0u);
  Pose bad = poses[0];
  bad.translation.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)collide(a, pa, b, bad, first, cache), InputError);
  EXPECT_THROW((void)collide(a, pa, b, poses[0], {.margin = -1.0}, cache), InputError);
}

}  // namespace
}  // namespace tightbvh
