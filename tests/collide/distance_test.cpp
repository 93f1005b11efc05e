#include "tightbvh/distance.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "collide/query_workspace.hpp"
#include "query_fixtures.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/obb_distance.hpp"
#include "tightbvh/tri_distance.hpp"

namespace tightbvh {
namespace {

using namespace query_test;

constexpr FitMethod kFitters[] = {FitMethod::aabb, FitMethod::pca, FitMethod::approx};

// The result's own consistency: points on the reported triangles at the reported distance, and
// the local points mapped by the poses give the world points.
void expect_consistent(const DistanceResult& r, const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb) {
  const double scale = 1.0 + pa.translation.norm() + pb.translation.norm();
  EXPECT_NEAR((r.point_a - pa.apply(r.point_a_local)).norm(), 0.0, 1e-12 * scale);
  EXPECT_NEAR((r.point_b - pb.apply(r.point_b_local)).norm(), 0.0, 1e-12 * scale);
  if (r.distance > 0.0) {
    EXPECT_NEAR((r.point_a - r.point_b).norm(), r.distance, 1e-12 * scale);
  }
  // The pair's own distance, in the world frame, is the answer.
  std::array<Vec3, 3> ta = ma.corners(r.pair.a), tb = mb.corners(r.pair.b);
  for (Vec3& v : ta) v = pa.apply(v);
  for (Vec3& v : tb) v = pb.apply(v);
  EXPECT_NEAR(tri_tri_distance(ta, tb).distance, r.distance, 1e-12 * scale);
}

// distance() == brute force (relative 1e-12), 0 exactly iff collide() hits, for the fitters
// and poses given. Returns how many cases touched.
int expect_matches_brute_force(const Mesh& ma, const Mesh& mb, std::uint64_t seed, std::uint32_t leaf_size = 1,
                               std::initializer_list<double> gaps = {0.0, 0.5, 0.8, 0.9, 1.0, 1.2, 2.0}) {
  const auto poses = random_poses(ma, mb, seed, gaps);
  int touching = 0;
  std::vector<DistanceResult> reference;
  for (const auto& [pa, pb] : poses) reference.push_back(distance_brute_force(ma, pa, mb, pb));
  QueryWorkspace workspace;
  for (const FitMethod fitter : kFitters) {
    const Tree ta = build(ma, {.fitter = fitter, .leaf_size = leaf_size, .threads = 1});
    const Tree tb = build(mb, {.fitter = fitter, .leaf_size = leaf_size, .threads = 1});
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const auto& [pa, pb] = poses[i];
      SCOPED_TRACE("fitter " + std::string(to_string(fitter)) + ", pose " + std::to_string(i));
      const DistanceResult r = distance(ta, ma, pa, tb, mb, pb, {}, workspace);
      EXPECT_FALSE(r.beyond_upper_bound);
      EXPECT_NEAR(r.distance, reference[i].distance, 1e-12 * reference[i].distance);
      EXPECT_EQ(r.distance == 0.0, collide(ta, ma, pa, tb, mb, pb).hit);
      EXPECT_GT(r.stats.node_pairs, 0u);
      expect_consistent(r, ma, pa, mb, pb);
      const DistanceResult other = distance(ta, ma, pa, tb, mb, pb, {.descend = DescendRule::larger_extent});
      EXPECT_NEAR(other.distance, reference[i].distance, 1e-12 * reference[i].distance);
      touching += r.distance == 0.0;
    }
  }
  return touching;
}

TEST(Distance, MatchesBruteForceSmallSynthetic) {
  const Mesh sphere = uv_sphere(8, 12);
  const Mesh soup = random_soup(120, 1);
  EXPECT_GT(expect_matches_brute_force(sphere, soup, 10), 0);
  EXPECT_GT(expect_matches_brute_force(soup, random_soup(80, 2), 11, 4), 0);  // leaves of 4
  EXPECT_GT(expect_matches_brute_force(cube(), sphere, 12), 0);
  EXPECT_GT(expect_matches_brute_force(cube(Vec3(-0.5, -0.5, -0.5)), random_soup(40, 3), 13, 8), 0);
}

TEST(Distance, MatchesBruteForceAgainstFewTriangles) {
  // One tree a single leaf or a few nodes against a deep one: every split of the search splits
  // the deep tree, two levels at once where a child is not a leaf, and with three triangles the
  // root's children are a leaf and an inner node (three pairs bounded at once).
  const Mesh sphere = uv_sphere(10, 14);
  const Mesh soup = random_soup(150, 4);
  for (const int n : {1, 2, 3, 5}) {
    SCOPED_TRACE(std::to_string(n) + " triangles");
    const Mesh few = random_soup(n, 30 + static_cast<std::uint64_t>(n), 0.6);
    expect_matches_brute_force(sphere, few, 40 + static_cast<std::uint64_t>(n), 1, {0.5, 0.9, 1.1, 1.5, 3.0});
    expect_matches_brute_force(few, soup, 50 + static_cast<std::uint64_t>(n), 1, {0.5, 0.9, 1.1, 1.5, 3.0});
  }
}

TEST(Distance, MatchesBruteForceOnSlivers) {
  // Triangles whose third corner lies within 1e-7..1e-12 of their first edge's line, and pairs
  // of nearly parallel edges: their normals and edge cross products round far from orthogonal
  // to the edges, which the search's separating-axis test of triangle pairs must allow for.
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto slivers = [&](int n) {
    Mesh m;
    for (int i = 0; i < n; ++i) {
      const Vec3 a(u(rng), u(rng), u(rng));
      const Vec3 b = a + 0.5 * Vec3(u(rng), u(rng), u(rng));
      const Vec3 off = Vec3(u(rng), u(rng), u(rng)).cross(b - a);
      const Vec3 c = a + (0.3 + 0.4 * u(rng)) * (b - a) + std::pow(10.0, -7 - i % 6) * off;
      const auto k = static_cast<std::uint32_t>(m.vertices.size());
      m.vertices.insert(m.vertices.end(), {a, b, c});
      m.triangles.push_back({k, k + 1, k + 2});
    }
    return m;
  };
  const Mesh a = slivers(60), b = slivers(40);
  expect_matches_brute_force(a, b, 60, 1, {0.3, 0.6, 0.9, 1.0, 1.1, 1.3});
  expect_matches_brute_force(a, random_soup(50, 5), 61, 1, {0.3, 0.6, 0.9, 1.0, 1.1, 1.3});
}

TEST(Distance, MatchesBruteForceFarApart) {
  // Meshes many times their size apart: the search's separating-axis test of triangle pairs
  // compares gaps along unnormalised axes (corner-to-corner vectors as long as the distance,
  // cross products of edges) with the best distance times the axis length, and a mistake in that
  // scaling rules out the closest pair only where the axes are far from unit length. Corner to
  // corner (cubes), corner to face and edge to edge (random soups) at 1.5-60 radii.
  const Mesh sphere = uv_sphere(8, 12);
  expect_matches_brute_force(sphere, random_soup(60, 6), 70, 1, {1.5, 4.0, 20.0, 60.0});
  expect_matches_brute_force(cube(), cube(Vec3(-0.5, -0.5, -0.5), 0.3), 71, 1, {1.5, 4.0, 20.0, 60.0});
  expect_matches_brute_force(random_soup(40, 7, 0.3), random_soup(50, 8), 72, 1, {1.5, 4.0, 20.0, 60.0});
}

TEST(Distance, MatchesBruteForceShippedMeshes) {
  // knot1 against elephant (every 8th and 6th triangle: brute force stays fast), overlapping,
  // near and far poses.
  const Mesh knot = subset(shipped("meshes/knot1.off"), 8);
  const Mesh elephant = subset(shipped("meshes/elephant.off"), 6);
  EXPECT_GT(expect_matches_brute_force(knot, elephant, 20, 1, {0.0, 0.6, 0.9, 1.05, 1.5}), 0);
}

TEST(Distance, ErrorOptionsAndUpperBound) {
  const Mesh a = subset(shipped("meshes/knot1.off"), 4);
  const Mesh b = uv_sphere(10, 12, 0.2);
  const Tree ta = build(a, {.threads = 1});
  const Tree tb = build(b, {.threads = 1});
  int checked = 0;
  for (const auto& [pa, pb] : random_poses(a, b, 3, {0.3, 0.8, 1.0, 1.3, 3.0})) {
    const DistanceResult exact = distance(ta, a, pa, tb, b, pb);
    EXPECT_EQ(exact.distance, distance_brute_force(a, pa, b, pb).distance);
    if (exact.distance == 0.0) continue;
    ++checked;
    for (const auto& [rel, abs] :
         {std::pair{0.1, 0.0}, std::pair{1.0, 0.0}, std::pair{0.0, 0.05}, std::pair{0.5, 0.01}}) {
      const DistanceResult approx = distance(ta, a, pa, tb, b, pb, {.absolute_error = abs, .relative_error = rel});
      EXPECT_GE(approx.distance, exact.distance);
      EXPECT_LE(approx.distance, exact.distance * (1 + rel) + abs);
      EXPECT_LE(approx.stats.node_pairs, exact.stats.node_pairs);
      expect_consistent(approx, a, pa, b, pb);
    }
    // Below the answer: "farther than", early; above it: the exact answer.
    const DistanceResult beyond = distance(ta, a, pa, tb, b, pb, {.upper_bound = 0.9 * exact.distance});
    EXPECT_TRUE(beyond.beyond_upper_bound);
    EXPECT_EQ(beyond.distance, 0.9 * exact.distance);
    EXPECT_LT(beyond.stats.node_pairs, exact.stats.node_pairs);
    const DistanceResult within = distance(ta, a, pa, tb, b, pb, {.upper_bound = 1.1 * exact.distance});
    EXPECT_FALSE(within.beyond_upper_bound);
    EXPECT_EQ(within.distance, exact.distance);
    EXPECT_TRUE(distance(ta, a, pa, tb, b, pb, {.upper_bound = exact.distance}).beyond_upper_bound);
  }
  EXPECT_GE(checked, 3);
}

// Every triangle under `node` (its leaves' ranges).
void collect(const Tree& tree, std::uint32_t node, std::vector<std::uint32_t>& out) {
  const Node& n = tree.nodes[node];
  if (n.is_leaf()) {
    for (std::uint32_t i = 0; i < n.count; ++i) out.push_back(tree.triangle_order[n.first + i]);
    return;
  }
  collect(tree, n.first, out);
  collect(tree, n.first + 1, out);
}

TEST(Distance, NodeLowerBoundNeverExceedsTheNodesTriangleDistance) {
  const Mesh a = subset(shipped("meshes/knot1.off"), 8);
  const Mesh b = subset(shipped("meshes/elephant.off"), 6);
  std::mt19937_64 rng(4);
  int positive = 0, tight = 0, pairs = 0;
  for (const FitMethod fitter : kFitters) {
    const Tree ta = build(a, {.fitter = fitter, .leaf_size = 2, .threads = 1});
    const Tree tb = build(b, {.fitter = fitter, .leaf_size = 2, .threads = 1});
    for (const auto& [pa, pb] : random_poses(a, b, 5, {0.5, 0.9, 1.2})) {
      const Pose rel = relative_pose(pa, pb);
      std::uniform_int_distribution<std::uint32_t> na(0, ta.nodes.size() - 1), nb(0, tb.nodes.size() - 1);
      for (int k = 0; k < 150; ++k) {
        std::uint32_t ia = na(rng), ib = nb(rng);
        std::vector<std::uint32_t> tris_a, tris_b;
        collect(ta, ia, tris_a);
        collect(tb, ib, tris_b);
        if (tris_a.size() * tris_b.size() > 20000) continue;  // keeps the brute force short
        double truth = std::numeric_limits<double>::infinity();
        for (const std::uint32_t i : tris_a)
          for (const std::uint32_t j : tris_b) {
            auto q = b.corners(j);
            for (Vec3& v : q) v = rel.apply(v);
            truth = std::min(truth, tri_tri_distance(a.corners(i), q).distance);
          }
        const double bound = obb_distance_lower_bound(ta.nodes[ia].box.obb(), tb.nodes[ib].box.obb().transformed(rel));
        EXPECT_LE(bound, truth + 1e-9) << "nodes " << ia << ", " << ib;
        ++pairs;
        positive += bound > 0.0;
        tight += bound > 0.5 * truth;
      }
    }
  }
  EXPECT_GT(pairs, 500);
  EXPECT_GT(positive, pairs / 4);
  EXPECT_GT(tight, positive / 4);
}

TEST(Distance, BoxLowerBoundOnRandomBoxes) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 300; ++k) {
    Obb a, b;
    a.center = Vec3(u(rng), u(rng), u(rng));
    b.center = 2.0 * Vec3(u(rng), u(rng), u(rng));
    a.axes = random_rotation(rng);
    b.axes = random_rotation(rng);
    a.half_extents = 0.5 * Vec3(u(rng), u(rng), u(rng)).cwiseAbs();
    b.half_extents = 0.5 * Vec3(u(rng), u(rng), u(rng)).cwiseAbs();
    // Distance between the boxes from above: sampled points (corners included) of both.
    double sampled = std::numeric_limits<double>::infinity();
    std::vector<Vec3> pa, pb;
    for (int s = 0; s < 400; ++s) {
      const auto point = [&](const Obb& box, int i) {
        Vec3 l;
        for (int c = 0; c < 3; ++c) l[c] = (i < 8 ? ((i >> c) & 1 ? 1.0 : -1.0) : u(rng)) * box.half_extents[c];
        return Vec3(box.center + box.axes * l);
      };
      pa.push_back(point(a, s));
      pb.push_back(point(b, s));
    }
    for (const Vec3& x : pa)
      for (const Vec3& y : pb) sampled = std::min(sampled, (x - y).norm());
    const double bound = obb_distance_lower_bound(a, b);
    EXPECT_LE(bound, sampled + 1e-12);
    EXPECT_GE(bound, 0.0);
  }
  // Axis-aligned boxes apart along a diagonal: the Euclidean combination of the gaps.
  Obb a, b;
  a.half_extents = b.half_extents = Vec3(0.5, 0.5, 0.5);
  b.center = Vec3(2, 3, 1);
  EXPECT_NEAR(obb_distance_lower_bound(a, b), std::sqrt(1 + 4 + 0), 1e-8);
}

TEST(Distance, BatchIsIdenticalForAnyThreadCount) {
  const Mesh a = subset(shipped("meshes/knot1.off"), 4);
  const Mesh b = uv_sphere(10, 16, 0.3);
  const Tree ta = build(a, {.fitter = FitMethod::pca, .threads = 1});
  const Tree tb = build(b, {.fitter = FitMethod::pca, .threads = 1});
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Pose> poses;
  for (int i = 0; i < 30; ++i) poses.push_back({random_rotation(rng), Vec3(u(rng), u(rng), u(rng))});
  const auto serial = distance_batch(ta, a, Pose{}, tb, b, poses, {}, 1);
  ASSERT_EQ(serial.size(), poses.size());
  int touching = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const DistanceResult single = distance(ta, a, Pose{}, tb, b, poses[i]);
    EXPECT_EQ(serial[i].distance, single.distance);
    EXPECT_EQ(serial[i].stats, single.stats);
    touching += serial[i].distance == 0.0;
  }
  EXPECT_GT(touching, 0);
  EXPECT_LT(touching, 30);
  for (const unsigned threads : {2u, 3u, 0u}) {
    const auto parallel = distance_batch(ta, a, Pose{}, tb, b, poses, {}, threads);
    ASSERT_EQ(parallel.size(), poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_EQ(parallel[i].distance, serial[i].distance) << "threads " << threads << " pose " << i;
      EXPECT_EQ(parallel[i].pair, serial[i].pair) << "threads " << threads << " pose " << i;
      EXPECT_EQ(parallel[i].point_a, serial[i].point_a) << "threads " << threads << " pose " << i;
      EXPECT_EQ(parallel[i].stats, serial[i].stats) << "threads " << threads << " pose " << i;
    }
  }
  EXPECT_TRUE(distance_batch(ta, a, Pose{}, tb, b, {}, {}, 2).empty());
}

// The search's radix queue: with every push at least the last pop (the search's monotone use),
// pops come out least first, the same multiset as a sorted reference, over several reuses
// (clear()) and with ties, zeros, infinities and bounds spanning many exponents.
TEST(Distance, RadixQueuePopsLeastFirstUnderMonotonePushes) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  query_detail::RadixQueue queue;
  for (int round = 0; round < 50; ++round) {
    queue.clear();
    std::vector<double> pending;  // the reference: the bounds pushed and not yet popped
    double last = 0.0;
    std::uint32_t id = 0;
    const auto push = [&](double bound) {
      queue.push({id++, 0, bound});
      pending.push_back(bound);
    };
    for (int k = 0; k < 20; ++k) push(std::ldexp(u(rng), -10 + static_cast<int>(rng() % 20)));
    push(0.0), push(0.0), push(std::numeric_limits<double>::infinity());
    while (!queue.empty()) {
      const query_detail::BoundedPair x = queue.pop();
      const auto least = std::min_element(pending.begin(), pending.end());
      ASSERT_EQ(x.bound, *least) << round;
      ASSERT_GE(x.bound, last);
      pending.erase(least);
      last = x.bound;
      if (std::isinf(last)) continue;
      const int children = static_cast<int>(rng() % 4);  // at least the last pop, often equal
      for (int c = 0; c < children; ++c) push(rng() % 3 == 0 ? last : last * (1.0 + u(rng)) + u(rng) * 1e-3);
      if (id > 2000) break;
    }
  }
}

TEST(Distance, BadInputAndEmptyTrees) {
  const Mesh a = cube(), b = cube(Vec3(3, 0, 0));
  const Tree ta = build(a, {.threads = 1}), tb = build(b, {.threads = 1});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)distance(ta, a, {}, tb, b, {}, {.absolute_error = -1.0}), InputError);
  EXPECT_THROW((void)distance(ta, a, {}, tb, b, {}, {.relative_error = nan}), InputError);
  EXPECT_THROW((void)distance(ta, a, {}, tb, b, {}, {.upper_bound = -0.5}), InputError);
  EXPECT_THROW((void)distance(ta, a, {}, tb, b, {}, {.upper_bound = nan}), InputError);
  EXPECT_THROW((void)distance(ta, b, {}, tb, uv_sphere(4, 4), {}), InputError);  // tree B over another mesh
  const DistanceResult apart = distance(ta, a, {}, tb, b, {});
  EXPECT_DOUBLE_EQ(apart.distance, 2.0);
  EXPECT_DOUBLE_EQ(apart.point_a.x(), 1.0);
  EXPECT_DOUBLE_EQ(apart.point_b.x(), 3.0);
  const DistanceResult empty = distance(Tree{}, a, {}, tb, b, {});
  EXPECT_TRUE(empty.beyond_upper_bound);
  EXPECT_EQ(empty.distance, std::numeric_limits<double>::infinity());
  // Face to face: touching, exactly 0.
  EXPECT_EQ(distance(ta, a, {}, build(cube(Vec3(1, 0, 0)), {.threads = 1}), cube(Vec3(1, 0, 0)), {}).distance, 0.0);
}

}  // namespace
}  // namespace tightbvh
