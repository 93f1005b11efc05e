#include "tightbvh/inside.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "solid_fixtures.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/distance.hpp"

namespace tightbvh {
namespace {

using namespace query_test;
using namespace solid_test;

Tree tree_of(const Mesh& m, FitMethod fitter = FitMethod::pca) { return build(m, {.fitter = fitter, .threads = 1}); }

// The tree's answer, the brute-force one, and the expected one agree.
void expect_point(const Tree& tree, const Mesh& mesh, const Closedness& closed, const Vec3& p, Containment expected) {
  SCOPED_TRACE("point (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " + std::to_string(p.z()) + ")");
  EXPECT_EQ(classify_point(tree, mesh, closed, p), expected);
  EXPECT_EQ(classify_point_brute_force(mesh, closed, p), expected);
}

TEST(Inside, CubeInsideOutsideAndOnTheSurface) {
  const Mesh m = cube();
  const Closedness c = check_closed(m);
  for (const FitMethod fitter : {FitMethod::aabb, FitMethod::pca}) {
    const Tree t = tree_of(m, fitter);
    expect_point(t, m, c, {0.25, 0.5, 0.75}, Containment::inside);
    expect_point(t, m, c, {0.5, 0.5, 0.5}, Containment::inside);  // +x ray through the diagonal of face x = 1
    expect_point(t, m, c, {0.9999999999999999, 0.5, 0.25}, Containment::inside);  // 1 - 2^-53
    expect_point(t, m, c, {1.0000000000000002, 0.5, 0.25}, Containment::outside);  // 1 + 2^-52
    expect_point(t, m, c, {-1, 0.5, 0.5}, Containment::outside);   // through both diagonals
    expect_point(t, m, c, {-1, 0.5, 1.0}, Containment::outside);   // +x ray in the plane of the top face
    expect_point(t, m, c, {-1, 0.2, 0.3}, Containment::outside);
    expect_point(t, m, c, {0.5, 2.0, 0.5}, Containment::outside);  // outside the root box
    expect_point(t, m, c, {1, 0.5, 0.5}, Containment::on_surface);
    expect_point(t, m, c, {0, 0, 0}, Containment::on_surface);
    expect_point(t, m, c, {0.5, 0, 0}, Containment::on_surface);
    expect_point(t, m, c, {0.3, 0.2, 1}, Containment::on_surface);
  }
}

TEST(Inside, RaysThroughVerticesAndEdgesAreReshot) {
  // The first ray (+x) of each of these points passes exactly through a vertex or an edge.
  const Mesh m = octahedron();
  const Closedness c = check_closed(m);
  const Tree t = tree_of(m);
  expect_point(t, m, c, {0, 0, 0}, Containment::inside);       // through the vertex (1, 0, 0)
  expect_point(t, m, c, {-2, 0, 0}, Containment::outside);     // through (-1, 0, 0) and (1, 0, 0)
  expect_point(t, m, c, {0.1, 0.5, 0}, Containment::inside);   // through the edge (1,0,0)-(0,1,0)
  expect_point(t, m, c, {-3, 0.5, 0}, Containment::outside);   // through two edges
  expect_point(t, m, c, {-3, 0.25, 0.25}, Containment::outside);  // generic: two crossings
  expect_point(t, m, c, {0.2, 0.25, 0.25}, Containment::inside);  // generic: one crossing
  expect_point(t, m, c, {0.5, 0.5, 0}, Containment::on_surface);  // on an edge
  // A zero-area triangle (three distinct, collinear vertices) where the +x rays meet the
  // surface: face x = 1's diagonal (3, 5) is split at its midpoint 8 on one side only, and the
  // sliver (5, 3, 8) closes the surface.
  Mesh sliver = cube();
  sliver.vertices.push_back({1, 0.5, 0.5});
  sliver.triangles[11] = {3, 7, 8};
  sliver.triangles.push_back({8, 7, 5});
  sliver.triangles.push_back({5, 3, 8});
  const Closedness cs = check_closed(sliver);
  ASSERT_TRUE(cs.closed) << cs.problem;
  const Tree ts = tree_of(sliver);
  expect_point(ts, sliver, cs, {0.5, 0.5, 0.5}, Containment::inside);    // through the vertex 8
  expect_point(ts, sliver, cs, {0.5, 0.25, 0.75}, Containment::inside);  // through the sliver
  expect_point(ts, sliver, cs, {-1, 0.25, 0.75}, Containment::outside);
  expect_point(ts, sliver, cs, {1, 0.25, 0.75}, Containment::on_surface);
}

// Random points, vertices and grid points (on the coordinate planes of CAD meshes): the tree
// agrees with brute force, and with the winding number where that is decisive.
void expect_random_points(const Mesh& m, int count, std::uint64_t seed) {
  const Closedness c = check_closed(m);
  ASSERT_TRUE(c.closed) << c.problem;
  const Tree t = tree_of(m, FitMethod::approx);
  Aabb box;
  for (const Vec3& v : m.vertices) box.extend(v);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int inside = 0, outside = 0, decisive = 0;
  for (int i = 0; i < count; ++i) {
    Vec3 p;
    const double grow = 0.05 * box.diagonal();
    for (int k = 0; k < 3; ++k) p[k] = box.min[k] - grow + u(rng) * (box.max[k] - box.min[k] + 2 * grow);
    if (i % 4 == 3)
      for (int k = 0; k < 3; ++k) p[k] = std::round(p[k] * 16.0) / 16.0;  // grid points
    const Containment got = classify_point(t, m, c, p);
    ASSERT_EQ(got, classify_point_brute_force(m, c, p)) << i;
    ASSERT_NE(got, Containment::on_surface) << i;
    const double w = winding_number(m, p);
    if (std::abs(w - std::round(w)) < 0.05) {
      ++decisive;
      EXPECT_EQ(got == Containment::inside, std::abs(std::round(w)) == 1.0) << i << " winding " << w;
    }
    (got == Containment::inside ? inside : outside) += 1;
  }
  EXPECT_GT(inside, count / 20);
  EXPECT_GT(outside, count / 20);
  EXPECT_GT(decisive, count * 9 / 10);
  for (std::size_t v = 0; v < m.vertices.size(); v += m.vertices.size() / 7 + 1)
    EXPECT_EQ(classify_point(t, m, c, m.vertices[v]), Containment::on_surface);
}

TEST(Inside, RandomPointsAgreeWithBruteForceAndWindingNumber) {
  expect_random_points(uv_sphere(8, 12), 200, 1);
  expect_random_points(torus(2.0, 0.5, 16, 10), 200, 2);
  expect_random_points(shipped("meshes/knot1.off"), 120, 3);
  expect_random_points(shipped("meshes/fandisk.off"), 120, 4);
}

TEST(Inside, NeedsAClosedMesh) {
  Mesh holed = cube();
  holed.triangles.pop_back();
  const Closedness c = check_closed(holed);
  EXPECT_THROW((void)classify_point(tree_of(holed), holed, c, Vec3(0.5, 0.5, 0.5)), InputError);
  EXPECT_THROW((void)classify_point_brute_force(holed, c, Vec3(0.5, 0.5, 0.5)), InputError);
}

// ---------------------------------------------------------------- solid queries

struct Outcomes {
  int touching = 0, b_in_a = 0, a_in_b = 0, apart = 0;
};

// Random poses of B around A: collide and distance with solid equal their brute-force
// references (every triangle pair, every triangle for the rays), touching poses answer as
// without solid (same pairs and stats), containments are confirmed by the winding number.
Outcomes expect_solid_matches_brute_force(const Mesh& ma, const Mesh& mb, int poses, std::uint64_t seed) {
  const Closedness ca = check_closed(ma), cb = check_closed(mb);
  EXPECT_TRUE(ca.closed && cb.closed);
  const Tree ta = tree_of(ma, FitMethod::approx), tb = tree_of(mb, FitMethod::approx);
  Aabb box, box_b;
  for (const Vec3& v : ma.vertices) box.extend(v);
  for (const Vec3& v : mb.vertices) box_b.extend(v);
  const Sphere sb = bounding_sphere(mb);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  QueryWorkspace ws;
  Outcomes out;
  for (int i = 0; i < poses; ++i) {
    SCOPED_TRACE("pose " + std::to_string(i));
    const Pose pa{random_rotation(rng), Vec3(u(rng), u(rng), u(rng))};
    // B's center anywhere in A's box grown by B's radius, or at a point inside A, or B placed
    // so that a point inside B lands on A's center (thin meshes fill little of their boxes).
    const auto in_box = [&](const Aabb& b, double grow) {
      Vec3 p;
      for (int k = 0; k < 3; ++k) p[k] = b.min[k] - grow + u(rng) * (b.max[k] - b.min[k] + 2 * grow);
      return p;
    };
    const auto inside_of = [&](const Mesh& m, const Closedness& c, const Aabb& b) {
      Vec3 p = in_box(b, 0.0);
      for (int tries = 0; tries < 200 && classify_point_brute_force(m, c, p) != Containment::inside; ++tries)
        p = in_box(b, 0.0);
      return p;
    };
    Pose rel{random_rotation(rng), Vec3::Zero()};
    if (i % 3 == 0) rel.translation = in_box(box, sb.radius) - rel.rotation * sb.center;
    if (i % 3 == 1) rel.translation = inside_of(ma, ca, box) - rel.rotation * sb.center;
    if (i % 3 == 2) rel.translation = box.center() - rel.rotation * inside_of(mb, cb, box_b);
    const Pose pb = pa * rel;
    for (const QueryMode mode : {QueryMode::first_hit, QueryMode::all_pairs}) {
      const QueryOptions solid{.mode = mode, .solid = true, .closed_a = &ca, .closed_b = &cb};
      const QueryResult r = collide(ta, ma, pa, tb, mb, pb, solid, ws);
      const QueryResult ref = collide_brute_force(ma, pa, mb, pb, solid);
      EXPECT_EQ(r.hit, ref.hit);
      EXPECT_EQ(r.inside, ref.inside);
      if (mode == QueryMode::all_pairs) EXPECT_EQ(r.pairs, ref.pairs);
      const QueryResult plain = collide(ta, ma, pa, tb, mb, pb, {.mode = mode}, ws);
      if (plain.hit) {  // touching: solid changes nothing
        EXPECT_EQ(r.pairs, plain.pairs);
        EXPECT_EQ(r.stats, plain.stats);
        EXPECT_EQ(r.inside, Inside::none);
      } else {
        EXPECT_TRUE(r.pairs.empty());
      }
    }
    const DistanceOptions dsolid{.solid = true, .closed_a = &ca, .closed_b = &cb};
    const DistanceResult d = distance(ta, ma, pa, tb, mb, pb, dsolid, ws);
    const DistanceResult dref = distance_brute_force(ma, pa, mb, pb, dsolid);
    const DistanceResult dplain = distance(ta, ma, pa, tb, mb, pb, {}, ws);
    EXPECT_NEAR(d.distance, dref.distance, 1e-12 * dref.distance);
    EXPECT_EQ(d.inside, dref.inside);
    const QueryResult hit = collide(ta, ma, pa, tb, mb, pb, {.solid = true, .closed_a = &ca, .closed_b = &cb}, ws);
    EXPECT_EQ(d.distance == 0.0, hit.hit);
    EXPECT_EQ(d.inside, hit.inside);
    if (d.inside == Inside::none) {
      EXPECT_EQ(d.distance, dplain.distance);
      EXPECT_EQ(d.pair, dplain.pair);
    } else {
      EXPECT_GT(dplain.distance, 0.0);
      EXPECT_EQ(d.distance, 0.0);
      EXPECT_EQ(d.point_a, d.point_b);
      EXPECT_NEAR((pa.apply(d.point_a_local) - d.point_a).norm(), 0.0, 1e-12 * (1 + d.point_a.norm()));
      EXPECT_NEAR((pb.apply(d.point_b_local) - d.point_b).norm(), 0.0, 1e-12 * (1 + d.point_b.norm()));
      // Independently: the witness point is inside the other solid by the winding number.
      const double w = d.inside == Inside::b_in_a ? winding_number(ma, d.point_a_local)
                                                  : winding_number(mb, d.point_b_local);
      EXPECT_NEAR(std::abs(w), 1.0, 0.25);
    }
    if (hit.hit && hit.inside == Inside::none) ++out.touching;
    else if (hit.inside == Inside::b_in_a) ++out.b_in_a;
    else if (hit.inside == Inside::a_in_b) ++out.a_in_b;
    else ++out.apart;
  }
  return out;
}

TEST(Solid, SmallMeshesMatchBruteForce) {
  const Mesh sphere = uv_sphere(10, 16), small_cube = transformed(cube(), 0.3);
  const Outcomes b_in_a = expect_solid_matches_brute_force(sphere, small_cube, 40, 1);
  EXPECT_GT(b_in_a.b_in_a, 3);
  EXPECT_GT(b_in_a.touching, 3);
  const Outcomes a_in_b = expect_solid_matches_brute_force(small_cube, sphere, 40, 2);
  EXPECT_GT(a_in_b.a_in_b, 3);
  // A torus: in its tube, in its hole (apart), across its surface.
  const Outcomes tube =
      expect_solid_matches_brute_force(torus(2.0, 0.5, 24, 12), transformed(octahedron(), 0.2), 40, 3);
  EXPECT_GT(tube.b_in_a, 3);
  EXPECT_GT(tube.apart, 3);
  EXPECT_GT(tube.touching, 3);
}

TEST(Solid, ShippedMeshesMatchBruteForce) {
  // A small octahedron anywhere in the elephant's box: inside its body, across its surface,
  // outside; and the other way round.
  const Mesh elephant = shipped("meshes/elephant.off"), small = transformed(octahedron(), 0.03);
  const Outcomes in = expect_solid_matches_brute_force(elephant, small, 30, 4);
  EXPECT_GT(in.b_in_a, 2);
  EXPECT_GT(in.apart, 2);
  const Outcomes out = expect_solid_matches_brute_force(small, elephant, 30, 5);
  EXPECT_GT(out.a_in_b, 2);
  EXPECT_GT(out.apart, 2);
}

TEST(Solid, PiecesHolesAndCavities) {
  const Mesh sphere = uv_sphere(10, 16);
  const Closedness cs = check_closed(sphere);
  const Tree ts = tree_of(sphere);
  // B in two pieces, the far one first: the near one inside A decides.
  const Mesh two = merged(transformed(cube(), 0.2, Vec3(5, 0, 0)), transformed(cube(), 0.2, Vec3(-0.1, -0.1, -0.1)));
  const Closedness c2 = check_closed(two);
  const QueryResult r =
      collide(ts, sphere, {}, tree_of(two), two, {}, {.solid = true, .closed_a = &cs, .closed_b = &c2});
  EXPECT_TRUE(r.hit);
  EXPECT_EQ(r.inside, Inside::b_in_a);
  EXPECT_TRUE(r.pairs.empty());
  // A hollow sphere (an inward inner surface): a cube in the cavity is apart, one in the shell inside.
  const Mesh hollow = merged(sphere, flipped(transformed(sphere, 0.5)));
  const Closedness ch = check_closed(hollow);
  const Tree th = tree_of(hollow);
  const Mesh in_cavity = transformed(cube(), 0.2, Vec3(-0.1, -0.1, -0.1));
  const Mesh in_shell = transformed(cube(), 0.1, Vec3(0.65, -0.05, -0.05));
  const Closedness cc = check_closed(in_cavity);
  const DistanceOptions dopt{.solid = true, .closed_a = &ch, .closed_b = &cc};
  const DistanceResult cavity = distance(th, hollow, {}, tree_of(in_cavity), in_cavity, {}, dopt);
  EXPECT_EQ(cavity.inside, Inside::none);
  EXPECT_GT(cavity.distance, 0.2);
  const DistanceResult shell = distance(th, hollow, {}, tree_of(in_shell), in_shell, {}, dopt);
  EXPECT_EQ(shell.inside, Inside::b_in_a);
  EXPECT_EQ(shell.distance, 0.0);
  // The hollow sphere inside a big cube: A's outer piece is inside B.
  const Mesh big = transformed(cube(), 4.0, Vec3(-2, -2, -2));
  const Closedness cb = check_closed(big);
  EXPECT_EQ(collide(th, hollow, {}, tree_of(big), big, {}, {.solid = true, .closed_a = &ch, .closed_b = &cb}).inside,
            Inside::a_in_b);
  // Without solid: no hit, distance > 0.
  EXPECT_FALSE(collide(th, hollow, {}, tree_of(big), big, {}).hit);
}

TEST(Solid, OpenMeshesAreInputErrors) {
  const Mesh a = uv_sphere(6, 8);
  Mesh b = cube();
  b.triangles.pop_back();
  const Tree ta = tree_of(a), tb = tree_of(b);
  const auto message = [&](auto&& call) {
    try {
      call();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Touching or not, solid with an open mesh says which mesh and why.
  for (const Vec3 offset : {Vec3(0.5, 0, 0), Vec3(5, 0, 0)}) {
    const Pose pb{Mat3::Identity(), offset};
    EXPECT_EQ(message([&] { (void)collide(ta, a, {}, tb, b, pb, {.solid = true}); }),
              "collide: mesh B is not closed: 3 boundary edges (of one triangle only), e.g. (3, 5)");
    EXPECT_EQ(message([&] { (void)distance(ta, a, {}, tb, b, pb, {.solid = true}); }),
              "distance: mesh B is not closed: 3 boundary edges (of one triangle only), e.g. (3, 5)");
    EXPECT_EQ(message([&] { (void)collide(tb, b, {}, ta, a, pb, {.solid = true}); }),
              "collide: mesh A is not closed: 3 boundary edges (of one triangle only), e.g. (3, 5)");
    EXPECT_EQ(message([&] { (void)collide_brute_force(a, {}, b, pb, {.solid = true}); }),
              "collide_brute_force: mesh B is not closed: 3 boundary edges (of one triangle only), e.g. (3, 5)");
    EXPECT_NO_THROW((void)collide(ta, a, {}, tb, b, pb));  // without solid: fine
  }
  const std::vector<Pose> poses(3);
  EXPECT_THROW((void)collide_batch(ta, a, {}, tb, b, poses, {.solid = true}), InputError);
  EXPECT_THROW((void)distance_batch(ta, a, {}, tb, b, poses, {.solid = true}), InputError);
  // A closedness of another mesh.
  const Closedness other = check_closed(uv_sphere(8, 8));
  EXPECT_THROW((void)collide(ta, a, {}, ta, a, {}, {.solid = true, .closed_a = &other}), InputError);
}

TEST(Solid, BatchesAndWithoutGivenClosedness) {
  const Mesh a = uv_sphere(10, 16), b = transformed(cube(), 0.3, Vec3(-0.15, -0.15, -0.15));
  const Tree ta = tree_of(a), tb = tree_of(b);
  const Closedness ca = check_closed(a), cb = check_closed(b);
  std::vector<Pose> poses;
  for (int i = 0; i < 12; ++i) poses.push_back({Mat3::Identity(), Vec3(0.1 * i, 0.05 * i, 0)});
  const auto batch = collide_batch(ta, a, {}, tb, b, poses, {.solid = true}, 2);
  const auto dbatch = distance_batch(ta, a, {}, tb, b, poses, {.solid = true}, 2);
  int inside = 0, touching = 0, apart = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const QueryResult one = collide(ta, a, {}, tb, b, poses[i], {.solid = true, .closed_a = &ca, .closed_b = &cb});
    EXPECT_EQ(batch[i].hit, one.hit);
    EXPECT_EQ(batch[i].inside, one.inside);
    EXPECT_EQ(batch[i].pairs, one.pairs);
    const DistanceResult d = distance(ta, a, {}, tb, b, poses[i], {.solid = true});
    EXPECT_EQ(dbatch[i].distance, d.distance);
    EXPECT_EQ(dbatch[i].inside, d.inside);
    inside += one.inside != Inside::none;
    touching += one.hit && one.inside == Inside::none;
    apart += !one.hit;
  }
  EXPECT_GT(inside, 0);
  EXPECT_GT(touching, 0);
  EXPECT_GT(apart, 0);
}

}  // namespace
}  // namespace tightbvh
