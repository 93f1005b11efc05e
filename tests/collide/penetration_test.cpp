// distance() with DistanceOptions::signed_distance: the penetration of closed meshes (the deepest
// vertex of either mesh inside the other solid) against an independent brute force over every
// vertex (classify_point_brute_force, closest_points_brute_force), and the unsigned answer kept
// bit for bit when the solids are apart.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "collide/query_common.hpp"
#include "query_fixtures.hpp"
#include "solid_fixtures.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/closed.hpp"
#include "tightbvh/distance.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/inside.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/point_query.hpp"

namespace tightbvh {
namespace {

using namespace query_test;
using namespace solid_test;

// An axis-aligned box [lo, hi], outward.
Mesh box(const Vec3& lo, const Vec3& hi) {
  Mesh m = cube();
  for (Vec3& v : m.vertices) v = lo + v.cwiseProduct(hi - lo);
  return m;
}

// The reference: every vertex of each mesh mapped into the other's frame (map_point: B's by the
// relative pose, A's by its inverse, as the query does), classified against the other solid over
// every triangle, and those strictly inside measured over every triangle. The deepest wins, A's
// on a tie, then the lower index.
struct Reference {
  double depth = 0.0;  // 0 when no vertex is inside
  Inside deepest = Inside::none;
  std::uint32_t vertex = 0;
};

void deepest_into(const Mesh& from, const Pose& map, const Mesh& into, Inside which, Reference& best) {
  const Closedness closed = check_closed(into);
  for (std::uint32_t v = 0; v < from.vertices.size(); ++v) {
    const Vec3 p = query_detail::map_point(map, from.vertices[v]);
    if (classify_point_brute_force(into, closed, p) != Containment::inside) continue;
    const double d = closest_points_brute_force(into, Pose::identity(), std::vector<Vec3>{p})[0].distance;
    if (d > best.depth || (d == best.depth && best.deepest == Inside::none)) best = {d, which, v};
  }
}

Reference reference(const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb) {
  const Pose rel = relative_pose(pa, pb);
  Reference best;
  deepest_into(ma, rel.inverse(), mb, Inside::a_in_b, best);
  Reference of_b;
  deepest_into(mb, rel, ma, Inside::b_in_a, of_b);
  if (of_b.depth > best.depth) best = of_b;
  return best;
}

// The query (trees, models, batch and, for small meshes, the library's brute force: every
// triangle pair) against the reference, and the witnesses: the deepest vertex where it should be
// and the distance between the two points.
// Returns the query's answer.
DistanceResult expect_reference(const ModelPtr& a, const Pose& pa, const ModelPtr& b, const Pose& pb,
                                bool library_brute_force = true) {
  const Mesh& ma = a->mesh();
  const Mesh& mb = b->mesh();
  const DistanceOptions options{.signed_distance = true};
  const DistanceResult got = distance(*a, pa, *b, pb, options);
  const Reference want = reference(ma, pa, mb, pb);
  EXPECT_EQ(got.deepest, want.deepest);
  if (library_brute_force) {
    const DistanceResult brute = distance_brute_force(ma, pa, mb, pb, options);
    EXPECT_EQ(brute.distance, got.distance);
    EXPECT_EQ(brute.deepest, got.deepest);
    EXPECT_EQ(brute.deepest_vertex, got.deepest_vertex);
    EXPECT_EQ(brute.penetration_lower_bound_is_zero, got.penetration_lower_bound_is_zero);
    // The same segments, summed in another order (tree order vs index order).
    EXPECT_NEAR(brute.curve_length, got.curve_length, 1e-12 * (1.0 + got.curve_length));
    if (got.distance < 0.0) {  // the witnesses (touching pairs may differ: the first found)
      EXPECT_EQ(brute.point_a, got.point_a);
      EXPECT_EQ(brute.point_b, got.point_b);
    }
  }
  const std::vector<Pose> poses{pb};
  const std::vector<DistanceResult> batch = distance_batch(a->tree(), ma, pa, b->tree(), mb, poses, options, 2);
  EXPECT_EQ(batch[0].distance, got.distance);
  EXPECT_EQ(batch[0].deepest_vertex, got.deepest_vertex);
  if (want.deepest == Inside::none) {
    EXPECT_GE(got.distance, 0.0);
    return got;
  }
  EXPECT_EQ(got.distance, -want.depth);  // the same frames and point–triangle distance: bit for bit
  EXPECT_EQ(got.deepest_vertex, want.vertex);
  EXPECT_FALSE(got.penetration_lower_bound_is_zero);
  const double scale = 1.0 + got.point_a.cwiseAbs().maxCoeff() + got.point_b.cwiseAbs().maxCoeff();
  EXPECT_NEAR((got.point_a - got.point_b).norm(), -got.distance, 1e-12 * scale);
  if (got.deepest == Inside::a_in_b) {
    EXPECT_LT((got.point_a - pa.apply(ma.vertices[got.deepest_vertex])).norm(), 1e-12 * scale);
    EXPECT_EQ(got.point_a_local, ma.vertices[got.deepest_vertex]);
    EXPECT_LT((got.point_b - pb.apply(got.point_b_local)).norm(), 1e-12 * scale);
  } else {
    EXPECT_LT((got.point_b - pb.apply(mb.vertices[got.deepest_vertex])).norm(), 1e-12 * scale);
    EXPECT_EQ(got.point_b_local, mb.vertices[got.deepest_vertex]);
    EXPECT_LT((got.point_a - pa.apply(got.point_a_local)).norm(), 1e-12 * scale);
  }
  return got;
}

DistanceResult expect_reference(const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb) {
  return expect_reference(make_model(ma), pa, make_model(mb), pb);
}

TEST(Penetration, OverlappingCubes) {
  // B's corners at x = 0.8 lie inside A, 0.1 from A's faces y = 0 and z = 0 (and 0.2 from x = 1).
  const Mesh ma = cube(), mb = box(Vec3(0.8, 0.1, 0.1), Vec3(1.6, 0.9, 0.9));
  const DistanceResult r = distance(*make_model(ma), Pose::identity(), *make_model(mb), Pose::identity(),
                                    {.signed_distance = true});
  EXPECT_NEAR(r.distance, -0.1, 1e-15);
  EXPECT_EQ(r.deepest, Inside::b_in_a);
  EXPECT_FALSE(r.penetration_lower_bound_is_zero);
  expect_reference(ma, Pose::identity(), mb, Pose::identity());
}

TEST(Penetration, NestedSolidsGiveTheDeepestVertex) {
  // A small box inside a large one: the surfaces are apart, every inner corner is inside; the
  // deepest is the inner corner farthest from the outer surface.
  const Mesh outer = box(Vec3(0, 0, 0), Vec3(4, 2, 2)), inner = box(Vec3(0.5, 0.6, 0.7), Vec3(1.5, 1.0, 1.1));
  const DistanceOptions options{.signed_distance = true};
  const ModelPtr mo = make_model(outer), mi = make_model(inner);
  const DistanceResult out_in = distance(*mo, Pose::identity(), *mi, Pose::identity(), options);
  EXPECT_NEAR(out_in.distance, -0.9, 1e-15);  // the corner (1.5, 1.0, 1.1): 0.9 from z = 2
  EXPECT_EQ(out_in.deepest, Inside::b_in_a);
  EXPECT_EQ(inner.vertices[out_in.deepest_vertex], Vec3(1.5, 1.0, 1.1));
  const DistanceResult in_out = distance(*mi, Pose::identity(), *mo, Pose::identity(), options);
  EXPECT_EQ(in_out.distance, out_in.distance);
  EXPECT_EQ(in_out.deepest, Inside::a_in_b);
  expect_reference(outer, Pose::identity(), inner, Pose::identity());
  // Both posed alike, tilted: an octahedron nested in the box.
  std::mt19937_64 rng(5);
  const Pose tilted{random_rotation(rng), Vec3(0.3, -0.2, 0.1)};
  expect_reference(outer, tilted, transformed(octahedron(), 0.3, Vec3(2.0, 1.0, 1.0)), tilted);
}

TEST(Penetration, EdgeCrossingWithNoVertexInsideIsZeroAndFlagged) {
  // Two thin boxes crossed like a plus sign: A's long edges pierce B's side faces, no vertex of
  // either lies inside the other, so the bound is 0.
  const Mesh ma = box(Vec3(-2, -0.1, -0.1), Vec3(2, 0.1, 0.1)), mb = box(Vec3(-0.1, -2, -0.2), Vec3(0.1, 2, 0.2));
  const DistanceResult r = distance(*make_model(ma), Pose::identity(), *make_model(mb), Pose::identity(),
                                    {.signed_distance = true});
  EXPECT_EQ(r.distance, 0.0);
  EXPECT_TRUE(r.penetration_lower_bound_is_zero);
  EXPECT_EQ(r.deepest, Inside::none);
  // The surfaces cross along eight segments of length 0.2: x = ±0.1 on A's four long faces.
  EXPECT_NEAR(r.curve_length, 1.6, 1e-12);
  expect_reference(ma, Pose::identity(), mb, Pose::identity());
  // Touching face to face: 0 and flagged as well (touching and crossing are not told apart).
  const DistanceResult touch = distance(*make_model(cube()), Pose::identity(),
                                        *make_model(cube(Vec3(1.0, 0.2, 0.3), 0.5)), Pose::identity(),
                                        {.signed_distance = true});
  EXPECT_EQ(touch.distance, 0.0);
  EXPECT_TRUE(touch.penetration_lower_bound_is_zero);
}

TEST(Penetration, ApartIsTheUnsignedAnswerBitForBit) {
  const Mesh fandisk = shipped("meshes/fandisk.off"), small = torus(0.5, 0.15, 16, 8);
  const ModelPtr a = make_model(fandisk), b = make_model(small);
  int apart = 0;
  for (const auto& [pa, pb] : random_poses(fandisk, small, 21, {1.05, 1.2, 2.0, 3.0})) {
    const DistanceResult plain = distance(*a, pa, *b, pb);
    const DistanceResult with = distance(*a, pa, *b, pb, {.signed_distance = true});
    if (!(plain.distance > 0.0)) continue;
    ++apart;
    EXPECT_EQ(with.distance, plain.distance);
    EXPECT_EQ(with.pair, plain.pair);
    EXPECT_EQ(with.point_a, plain.point_a);
    EXPECT_EQ(with.point_b, plain.point_b);
    EXPECT_EQ(with.point_a_local, plain.point_a_local);
    EXPECT_EQ(with.point_b_local, plain.point_b_local);
    EXPECT_EQ(with.stats, plain.stats);
    EXPECT_EQ(with.deepest, Inside::none);
    EXPECT_FALSE(with.penetration_lower_bound_is_zero);
    EXPECT_EQ(with.curve_length, 0.0);
  }
  EXPECT_GE(apart, 3);
}

TEST(Penetration, ShippedMeshAgainstBruteForce) {
  // The shipped fandisk (closed) against a torus and a box posed to overlap deeply, shallowly,
  // and to be apart.
  const Mesh fandisk = shipped("meshes/fandisk.off");
  ASSERT_TRUE(check_closed(fandisk).closed);
  const ModelPtr a = make_model(fandisk);
  const ModelPtr ring = make_model(transformed(torus(1.0, 0.3, 12, 6), 0.4));
  const ModelPtr brick = make_model(box(Vec3(0, 0, 0), Vec3(0.6, 0.3, 0.2)));
  int negative = 0;
  for (const ModelPtr& b : {ring, brick})
    for (const auto& [pa, pb] : random_poses(fandisk, b->mesh(), 33, {0.0, 0.3, 0.6, 1.2}))
      negative += expect_reference(a, pa, b, pb, false).distance < 0.0;
  EXPECT_GE(negative, 4);
}

TEST(Penetration, OpenMeshIsAnInputErrorNamingIt) {
  Mesh open = cube();
  open.triangles.pop_back();
  const Tree ta = build(open), tb = build(cube());
  try {
    (void)distance(tb, cube(), Pose::identity(), ta, open, Pose::identity(), {.signed_distance = true});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh B is not closed"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tightbvh
