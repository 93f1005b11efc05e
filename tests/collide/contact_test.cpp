#include "tightbvh/contact.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "query_fixtures.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/closed.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/point_query.hpp"
#include "tightbvh/query_cache.hpp"
#include "tightbvh/tri_tri.hpp"

namespace tightbvh {
namespace {

using Tri = std::array<Vec3, 3>;

double distance_to(const Vec3& p, const Tri& t) { return closest_point_on_triangle(p, t[0], t[1], t[2]).distance; }

// Where the edges of one triangle pierce the other (each edge against the closed triangle, by
// solving p + s (q - p) = t0 + u (t1 - t0) + v (t2 - t0)): in general position these are exactly
// the two ends of the intersection segment. An independent construction from triangle_contact's
// interval intersection.
std::vector<Vec3> piercings(const Tri& a, const Tri& b) {
  std::vector<Vec3> out;
  const auto edges_through = [&](const Tri& e, const Tri& t) {
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = e[k], q = e[(k + 1) % 3];
      Mat3 m;
      m.col(0) = q - p;
      m.col(1) = t[0] - t[1];
      m.col(2) = t[0] - t[2];
      const Vec3 x = m.fullPivLu().solve(t[0] - p);  // (s, u, v)
      if (x[0] >= 0 && x[0] <= 1 && x[1] >= 0 && x[2] >= 0 && x[1] + x[2] <= 1) out.push_back(p + x[0] * (q - p));
    }
  };
  edges_through(a, b);
  edges_through(b, a);
  return out;
}

// The kind must not depend on the order of the pair nor on the order of the corners.
void expect_kind(const Tri& p, const Tri& q, ContactKind kind, bool coplanar = false) {
  static constexpr int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  for (const auto& pp : perms)
    for (const auto& qq : perms) {
      const Tri a{p[pp[0]], p[pp[1]], p[pp[2]]}, b{q[qq[0]], q[qq[1]], q[qq[2]]};
      for (const Contact& c : {triangle_contact(a, b), triangle_contact(b, a)}) {
        ASSERT_EQ(c.kind, kind) << to_string(c.kind) << " for permutation " << pp[0] << pp[1] << pp[2] << " / "
                                << qq[0] << qq[1] << qq[2];
        ASSERT_EQ(c.coplanar, coplanar);
        for (int i = 0; i < c.count; ++i) {
          EXPECT_LE(distance_to(c.points[i], a), 1e-14);
          EXPECT_LE(distance_to(c.points[i], b), 1e-14);
        }
      }
    }
}

const Tri kBase{Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0)};  // in the plane z = 0

TEST(Contact, HandCases) {
  // Apart, and the normals of non-degenerate triangles.
  const Contact apart = triangle_contact(kBase, Tri{Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0, 1, 1)});
  EXPECT_EQ(apart.kind, ContactKind::none);
  EXPECT_EQ(apart.normal_a, Vec3(0, 0, 1));
  EXPECT_FALSE(apart.degenerate_a);
  // Crossing: the segment x = 0.5, z = 0, y in [0, 1.5].
  const Tri cross{Vec3(0.5, -1, -1), Vec3(0.5, 3, -1), Vec3(0.5, 0.5, 2)};
  const Contact c = triangle_contact(kBase, cross);
  ASSERT_EQ(c.kind, ContactKind::segment);
  EXPECT_FALSE(c.coplanar);
  const double lo = std::min(c.points[0].y(), c.points[1].y()), hi = std::max(c.points[0].y(), c.points[1].y());
  EXPECT_DOUBLE_EQ(lo, 0.0);
  EXPECT_DOUBLE_EQ(hi, 1.5);
  EXPECT_DOUBLE_EQ(c.length(), 1.5);
  EXPECT_EQ(c.normal_b, Vec3(1, 0, 0));
  expect_kind(kBase, cross, ContactKind::segment);
  // Touching: a corner on the face, an edge through an edge, a corner on an edge.
  expect_kind(kBase, {Vec3(0.5, 0.5, 0), Vec3(1, 0.5, 1), Vec3(0.5, 1, 1)}, ContactKind::point);
  expect_kind(kBase, {Vec3(1, -1, 1), Vec3(1, 1, -1), Vec3(1, -1, -1)}, ContactKind::point);
  expect_kind(kBase, {Vec3(1, 0, 0), Vec3(1, -1, 1), Vec3(2, -1, 1)}, ContactKind::point);
  expect_kind(kBase, {Vec3(1, 0, 0), Vec3(1, -1, 1), Vec3(1, -1, -1)}, ContactKind::point);
  // An edge lying on the face: a segment; an edge of one lying along an edge of the other.
  expect_kind(kBase, {Vec3(0.25, 0.25, 0), Vec3(1, 0.5, 0), Vec3(0.5, 0.5, 1)}, ContactKind::segment);
  expect_kind(kBase, {Vec3(0.5, 0, 0), Vec3(1.5, 0, 0), Vec3(1, -1, 1)}, ContactKind::segment);
  // Coplanar: overlap polygon, shared edge (segment), shared corner (point).
  expect_kind(kBase, {Vec3(1, 1, 0), Vec3(-1, 1, 0), Vec3(1, -1, 0)}, ContactKind::polygon, true);
  expect_kind(kBase, {Vec3(2, 0, 0), Vec3(0, 2, 0), Vec3(2, 2, 0)}, ContactKind::segment, true);
  expect_kind(kBase, {Vec3(2, 0, 0), Vec3(3, 0, 0), Vec3(3, 1, 0)}, ContactKind::point, true);
  // Degenerate triangles: no normal, flagged; a segment piercing the face meets it in a point.
  const Tri needle{Vec3(0.5, 0.5, -1), Vec3(0.5, 0.5, 1), Vec3(0.5, 0.5, 0.5)};
  const Contact d = triangle_contact(needle, kBase);
  EXPECT_TRUE(d.degenerate_a);
  EXPECT_EQ(d.normal_a, Vec3::Zero());
  ASSERT_EQ(d.kind, ContactKind::point);
  EXPECT_EQ(d.points[0], Vec3(0.5, 0.5, 0));
  expect_kind(needle, kBase, ContactKind::point);
}

TEST(Contact, CoplanarOverlapPolygon) {
  // A hexagon: two triangles of a star of David.
  const Tri up{Vec3(0, 2, 0), Vec3(-std::sqrt(3.0), -1, 0), Vec3(std::sqrt(3.0), -1, 0)};
  const Tri down{Vec3(0, -2, 0), Vec3(std::sqrt(3.0), 1, 0), Vec3(-std::sqrt(3.0), 1, 0)};
  const Contact c = triangle_contact(up, down);
  ASSERT_EQ(c.kind, ContactKind::polygon);
  EXPECT_TRUE(c.coplanar);
  EXPECT_EQ(c.count, 6);
  EXPECT_EQ(c.length(), 0.0);
  for (int i = 0; i < c.count; ++i) EXPECT_NEAR(c.points[i].norm(), std::sqrt(4.0 / 3.0), 1e-14);
}

TEST(Contact, RandomPairsMatchPiercings) {
  std::mt19937_64 rng(39);
  std::uniform_real_distribution<double> u(-1, 1);
  int segments = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Tri a{Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng))};
    const Tri b{Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng))};
    const Contact c = triangle_contact(a, b);
    ASSERT_EQ(c.kind != ContactKind::none, tri_tri_overlap(a, b));
    if (c.kind == ContactKind::none) continue;
    ASSERT_EQ(c.kind, ContactKind::segment) << "general position: a segment";
    ++segments;
    const std::vector<Vec3> ref = piercings(a, b);
    ASSERT_EQ(ref.size(), 2u);
    const bool direct = (c.points[0] - ref[0]).norm() + (c.points[1] - ref[1]).norm() <=
                        (c.points[0] - ref[1]).norm() + (c.points[1] - ref[0]).norm();
    EXPECT_NEAR((c.points[0] - ref[direct ? 0 : 1]).norm(), 0.0, 1e-9);
    EXPECT_NEAR((c.points[1] - ref[direct ? 1 : 0]).norm(), 0.0, 1e-9);
    for (int i = 0; i < 2; ++i) {
      EXPECT_LE(distance_to(c.points[i], a), 1e-12);
      EXPECT_LE(distance_to(c.points[i], b), 1e-12);
    }
  }
  EXPECT_GT(segments, 100);
}

TEST(Contact, RandomTouchingCornersArePoints) {
  // B's corner exactly on A's face (A in the plane z = 0, dyadic coordinates), the other corners
  // strictly above: a point, exactly that corner.
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> k(1, 63);
  for (int trial = 0; trial < 500; ++trial) {
    const Vec3 touch(k(rng) / 256.0, k(rng) / 256.0, 0);  // inside kBase (x + y < 2)
    const Tri b{touch, Vec3(k(rng) / 32.0, k(rng) / 32.0, k(rng) / 64.0),
                Vec3(-k(rng) / 32.0, k(rng) / 32.0, k(rng) / 64.0)};
    const Contact c = triangle_contact(kBase, b);
    ASSERT_EQ(c.kind, ContactKind::point);
    EXPECT_EQ(c.points[0], touch);
  }
}

TEST(Contact, RandomCoplanarOverlapsAreInBoth) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  int polygons = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Tri a{Vec3(u(rng), u(rng), 0), Vec3(u(rng), u(rng), 0), Vec3(u(rng), u(rng), 0)};
    const Tri b{Vec3(u(rng), u(rng), 0), Vec3(u(rng), u(rng), 0), Vec3(u(rng), u(rng), 0)};
    const Contact c = triangle_contact(a, b);
    if (c.kind == ContactKind::none) continue;
    ASSERT_TRUE(c.coplanar);
    polygons += c.kind == ContactKind::polygon;
    // A corner where two edges cross is off by rounding over the sine of their angle (compounded
    // along the clipping for slivers): the tolerance scales with 1 / (the smallest sine between
    // any two of the six edges).
    double min_sine = 1.0;
    for (int i = 0; i < 6; ++i)
      for (int j = i + 1; j < 6; ++j) {
        const Tri& s = i < 3 ? a : b;
        const Tri& t = j < 3 ? a : b;
        const Vec3 e = (s[(i + 1) % 3] - s[i % 3]).normalized(), f = (t[(j + 1) % 3] - t[j % 3]).normalized();
        min_sine = std::min(min_sine, e.cross(f).norm());
      }
    for (int i = 0; i < c.count; ++i) {
      EXPECT_LE(distance_to(c.points[i], a), 1e-13 / min_sine);
      EXPECT_LE(distance_to(c.points[i], b), 1e-13 / min_sine);
    }
  }
  EXPECT_GT(polygons, 100);
}

TEST(Contact, QueryOptionsChecked) {
  const Mesh m = query_test::cube();
  const Tree t = build(m);
  EXPECT_THROW((void)collide(t, m, Pose{}, t, m, Pose{}, {.contacts = true}), InputError);  // first_hit
  try {
    (void)collide(t, m, Pose{}, t, m, Pose{}, {.mode = QueryMode::all_pairs, .margin = 0.1, .contacts = true});
    FAIL() << "margin with contacts";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("contacts"), std::string::npos) << e.what();
  }
}

// Shipped closed meshes posed to intersect: the tree query's contacts equal the brute force's,
// every segment lies on both (world-frame) triangles, and the curve closes: in general position
// each segment end is where an edge of one mesh pierces a triangle of the other, and the edge's
// other triangle gives a segment with the same end.
TEST(Contact, MeshCurvesLieOnBothAndClose) {
  const Mesh ma = query_test::uv_sphere(12, 24), mb = query_test::cube(Vec3(-0.3, -0.4, -0.2), 1.0);
  ASSERT_TRUE(check_closed(ma).closed);
  ASSERT_TRUE(check_closed(mb).closed);
  const Tree ta = build(ma), tb = build(mb);
  std::mt19937_64 rng(3);
  const QueryOptions options{.mode = QueryMode::all_pairs, .contacts = true};
  for (int trial = 0; trial < 4; ++trial) {
    const Pose pa{query_test::random_rotation(rng), Vec3(0.01 * trial, 0, 0)};
    const Pose pb{query_test::random_rotation(rng), Vec3(0, 0.02, 0.03 * trial)};
    const QueryResult r = collide(ta, ma, pa, tb, mb, pb, options);
    const QueryResult brute = collide_brute_force(ma, pa, mb, pb, options);
    ASSERT_EQ(r.pairs, brute.pairs);
    const QueryResult by_model = collide(Model(ma), pa, Model(mb), pb, options);  // passed through
    ASSERT_EQ(by_model.contacts.size(), r.contacts.size());
    EXPECT_EQ(by_model.curve_length, r.curve_length);
    QueryCache cache;
    const QueryResult cached = collide(ta, ma, pa, tb, mb, pb, options, cache);
    ASSERT_EQ(cached.contacts.size(), r.contacts.size());
    EXPECT_EQ(cached.curve_length, r.curve_length);
    ASSERT_EQ(r.contacts.size(), r.pairs.size());
    ASSERT_FALSE(r.pairs.empty());
    EXPECT_EQ(r.curve_length, brute.curve_length);
    double length = 0.0;
    std::vector<Vec3> ends;
    for (std::size_t i = 0; i < r.pairs.size(); ++i) {
      const Contact& c = r.contacts[i];
      ASSERT_EQ(c.kind, brute.contacts[i].kind);
      ASSERT_EQ(c.kind, ContactKind::segment) << "general position";
      Tri a = ma.corners(r.pairs[i].a), b = mb.corners(r.pairs[i].b);
      for (Vec3& p : a) p = pa.apply(p);
      for (Vec3& p : b) p = pb.apply(p);
      EXPECT_NEAR(c.normal_a.dot(a[1] - a[0]), 0.0, 1e-12);
      for (int k = 0; k < 2; ++k) {
        EXPECT_LE(distance_to(c.points[k], a), 1e-12);
        EXPECT_LE(distance_to(c.points[k], b), 1e-12);
        ends.push_back(c.points[k]);
      }
      length += c.length();
    }
    EXPECT_NEAR(r.curve_length, length, 1e-12 * length);
    for (std::size_t i = 0; i < ends.size(); ++i) {
      bool shared = false;
      for (std::size_t j = 0; j < ends.size() && !shared; ++j)
        shared = j / 2 != i / 2 && (ends[i] - ends[j]).norm() <= 1e-12;
      EXPECT_TRUE(shared) << "open curve at segment end " << i;
    }
  }
}

TEST(Contact, ShippedMeshesPosedToIntersect) {
  const Mesh m = query_test::shipped("meshes/knot1.off");
  const Tree t = build(m);
  const bool closed = check_closed(m).closed;
  const QueryOptions options{.mode = QueryMode::all_pairs, .contacts = true};
  const auto poses = query_test::random_poses(m, m, 5, {0.2, 0.5});
  for (const auto& [pa, pb] : poses) {
    const QueryResult r = collide(t, m, pa, t, m, pb, options);
    ASSERT_EQ(r.contacts.size(), r.pairs.size());
    const double scale = query_test::bounding_sphere(m).radius;
    std::vector<Vec3> ends;
    for (std::size_t i = 0; i < r.pairs.size(); ++i) {
      const Contact& c = r.contacts[i];
      Tri a = m.corners(r.pairs[i].a), b = m.corners(r.pairs[i].b);
      for (Vec3& p : a) p = pa.apply(p);
      for (Vec3& p : b) p = pb.apply(p);
      ASSERT_NE(c.kind, ContactKind::none);
      for (int k = 0; k < c.count; ++k) {
        EXPECT_LE(distance_to(c.points[k], a), 1e-11 * scale);
        EXPECT_LE(distance_to(c.points[k], b), 1e-11 * scale);
        if (c.kind == ContactKind::segment) ends.push_back(c.points[k]);
      }
    }
    if (!closed) continue;
    for (std::size_t i = 0; i < ends.size(); ++i) {
      bool shared = false;
      for (std::size_t j = 0; j < ends.size() && !shared; ++j)
        shared = j / 2 != i / 2 && (ends[i] - ends[j]).norm() <= 1e-11 * scale;
      EXPECT_TRUE(shared) << "open curve at segment end " << i;
    }
  }
}

}  // namespace
}  // namespace tightbvh
