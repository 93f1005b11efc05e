#include "tightbvh/tri_distance.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "tightbvh/tri_tri.hpp"
#include "collide/box_bounds4.hpp"
#include "collide/tri_distance_disjoint.hpp"

namespace tightbvh {
namespace {

using Tri = std::array<Vec3, 3>;

// The closest point of the sampled triangle set: a barycentric grid of n subdivisions per edge,
// so every point of the triangle is within max_edge / n of a sample.
std::vector<Vec3> samples(const Tri& t, int n) {
  std::vector<Vec3> out;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const double u = double(i) / n, v = double(j) / n;
      out.push_back(t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]));
    }
  return out;
}
double max_edge(const Tri& t) { return std::max({(t[1] - t[0]).norm(), (t[2] - t[1]).norm(), (t[0] - t[2]).norm()}); }
double sampled_distance(const Tri& p, const Tri& q, int n) {
  const auto sp = samples(p, n), sq = samples(q, n);
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& a : sp)
    for (const Vec3& b : sq) best = std::min(best, (a - b).squaredNorm());
  return std::sqrt(best);
}

// Distance of x to the closed triangle t, by dense sampling refined around the best sample
// (the distance is convex in the barycentric coordinates): used only to check that a reported
// closest point lies on its triangle.
bool on_triangle(const Vec3& x, const Tri& t, double tolerance) {
  const Vec3 e1 = t[1] - t[0], e2 = t[2] - t[0];
  const Vec3 n = e1.cross(e2);
  if (n.squaredNorm() <= 1e-24 * e1.squaredNorm() * e2.squaredNorm()) {
    // Degenerate: on one of the three edges.
    for (int i = 0; i < 3; ++i) {
      const Vec3 a = t[i], d = t[(i + 1) % 3] - t[i];
      const double s = d.squaredNorm() == 0 ? 0 : std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
      if ((a + s * d - x).norm() <= tolerance) return true;
    }
    return false;
  }
  // Barycentric coordinates of x's projection, and the distance to the plane.
  const double off_plane = std::abs(n.normalized().dot(x - t[0]));
  const Vec3 w = x - t[0];
  const double d00 = e1.dot(e1), d01 = e1.dot(e2), d11 = e2.dot(e2), d20 = w.dot(e1), d21 = w.dot(e2);
  const double den = d00 * d11 - d01 * d01;
  const double v = (d11 * d20 - d01 * d21) / den, u = (d00 * d21 - d01 * d20) / den;
  const double slack = tolerance / std::max(std::sqrt(d00), std::sqrt(d11)) + 1e-9;
  return off_plane <= tolerance && v >= -slack && u >= -slack && u + v <= 1 + slack;
}

Vec3 random_point(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng)};
}

// The contract on one pair: touching <=> 0; points on their triangles and |p - q| == d; the
// swapped call gives the same distance bit for bit.
TriangleDistance checked(const Tri& p, const Tri& q) {
  const TriangleDistance d = tri_tri_distance(p, q);
  const bool touching = tri_tri_overlap(p, q);
  EXPECT_EQ(d.distance == 0.0, touching);
  EXPECT_GT(d.distance, touching ? -1.0 : 0.0);
  const double scale = std::max(max_edge(p), max_edge(q)) + p[0].norm() + q[0].norm();
  const double tol = 1e-12 * scale;
  EXPECT_TRUE(on_triangle(d.point_p, p, tol)) << d.point_p.transpose();
  EXPECT_TRUE(on_triangle(d.point_q, q, tol)) << d.point_q.transpose();
  if (!touching) {
    EXPECT_NEAR((d.point_p - d.point_q).norm(), d.distance, tol);
  }
  if (touching) {
    EXPECT_LE((d.point_p - d.point_q).norm(), 1e-9 * scale);
  }
  const TriangleDistance swapped = tri_tri_distance(q, p);
  EXPECT_EQ(swapped.distance, d.distance);
  EXPECT_EQ(swapped.point_p, d.point_q);
  EXPECT_EQ(swapped.point_q, d.point_p);
  return d;
}

TEST(TriDistance, RandomPairsMatchDenseSampling) {
  std::mt19937_64 rng(1);
  constexpr int kGrid = 40;
  int separated = 0;
  for (int k = 0; k < 60; ++k) {
    const Vec3 cp = random_point(rng, 1.0), cq = random_point(rng, 1.0);
    const double size = k % 3 == 0 ? 0.3 : 1.0;  // some far apart, many close or crossing
    const Tri p{cp + random_point(rng, size), cp + random_point(rng, size), cp + random_point(rng, size)};
    const Tri q{cq + random_point(rng, size), cq + random_point(rng, size), cq + random_point(rng, size)};
    SCOPED_TRACE(k);
    const TriangleDistance d = checked(p, q);
    const double sampled = sampled_distance(p, q, kGrid);
    const double resolution = (max_edge(p) + max_edge(q)) / kGrid;
    EXPECT_LE(d.distance, sampled + 1e-12);               // never worse than a sample pair
    EXPECT_GE(d.distance, sampled - resolution - 1e-12);  // nor better than the true minimum
    separated += d.distance > 0;
  }
  EXPECT_GT(separated, 20);
}

TEST(TriDistance, KnownDistances) {
  const Tri unit{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  // Parallel planes: a smaller triangle 0.5 above the face.
  EXPECT_DOUBLE_EQ(checked(unit, Tri{Vec3(0.1, 0.1, 0.5), Vec3(0.3, 0.1, 0.5), Vec3(0.1, 0.3, 0.5)}).distance, 0.5);
  // Parallel, shifted beyond the hypotenuse: nearest is vertex (0.6, 0.6) to edge x + y = 1 at height 1.
  const double planar = std::sqrt(0.2 * 0.2 / 2);
  EXPECT_NEAR(checked(unit, Tri{Vec3(0.6, 0.6, 1), Vec3(2, 0.6, 1), Vec3(0.6, 2, 1)}).distance,
              std::sqrt(planar * planar + 1.0), 1e-15);
  // Coplanar, separated by 0.25 along x.
  EXPECT_NEAR(checked(unit, Tri{Vec3(1.25, 0, 0), Vec3(2, 0, 0), Vec3(1.25, 1, 0)}).distance, 0.25, 1e-15);
  // Vertex over the face interior.
  const TriangleDistance vf = checked(unit, Tri{Vec3(0.2, 0.2, 0.7), Vec3(0.2, 0.2, 3), Vec3(1, 1, 3)});
  EXPECT_DOUBLE_EQ(vf.distance, 0.7);
  EXPECT_EQ(vf.point_p, Vec3(0.2, 0.2, 0));
  // Skew edges: x axis edge against a segment along y at z = 0.3 over x = 0.5.
  const TriangleDistance ee = checked(unit, Tri{Vec3(0.5, -1, -0.3), Vec3(0.5, -0.5, -0.3), Vec3(0.5, -2, -5)});
  EXPECT_NEAR(ee.distance, std::hypot(0.5, 0.3), 1e-15);
  // Crossing skew edges: (0.5,0,0)-side of the unit triangle and a stick under it.
  EXPECT_NEAR(checked(unit, Tri{Vec3(0.4, -1, -0.25), Vec3(0.4, 1, -0.25), Vec3(0.4, 1, -3)}).distance, 0.25, 1e-15);
}

TEST(TriDistance, DegenerateTriangles) {
  const Tri unit{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Tri point{Vec3(0.25, 0.25, 2), Vec3(0.25, 0.25, 2), Vec3(0.25, 0.25, 2)};
  EXPECT_DOUBLE_EQ(checked(unit, point).distance, 2.0);
  const Tri segment{Vec3(2, 0, 0.5), Vec3(3, 0, 0.5), Vec3(2.5, 0, 0.5)};  // collinear corners
  EXPECT_DOUBLE_EQ(checked(unit, segment).distance, std::hypot(1.0, 0.5));
  // Two points, two segments, point on a segment.
  const Tri other_point{Vec3(1, 2, 2), Vec3(1, 2, 2), Vec3(1, 2, 2)};
  EXPECT_DOUBLE_EQ(checked(point, other_point).distance, std::hypot(0.75, 1.75));
  const Tri parallel_segment{Vec3(2.5, 1, 0.5), Vec3(4, 1, 0.5), Vec3(3, 1, 0.5)};
  EXPECT_DOUBLE_EQ(checked(segment, parallel_segment).distance, 1.0);
  const Tri point_on_segment{Vec3(2.25, 0, 0.5), Vec3(2.25, 0, 0.5), Vec3(2.25, 0, 0.5)};
  EXPECT_EQ(checked(segment, point_on_segment).distance, 0.0);
  // A segment through the face (touching) and one lying in the face's plane outside it.
  EXPECT_EQ(checked(unit, Tri{Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(0.2, 0.2, 0.5)}).distance, 0.0);
  EXPECT_DOUBLE_EQ(checked(unit, Tri{Vec3(-1, -1, 0), Vec3(-2, -1, 0), Vec3(-3, -1, 0)}).distance, std::sqrt(2.0));
}

TEST(TriDistance, TouchingIsExactlyZeroAndNearlyTouchingIsPositive) {
  const Tri unit{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  // Shared vertex, shared edge, vertex on the face, vertex on an edge, piercing, coplanar overlap.
  EXPECT_EQ(checked(unit, Tri{Vec3(0, 0, 0), Vec3(-1, 0, 1), Vec3(0, -1, 1)}).distance, 0.0);
  EXPECT_EQ(checked(unit, Tri{Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 1)}).distance, 0.0);
  EXPECT_EQ(checked(unit, Tri{Vec3(0.25, 0.25, 0), Vec3(0.25, 0.25, 1), Vec3(1, 1, 1)}).distance, 0.0);
  EXPECT_EQ(checked(unit, Tri{Vec3(0.5, 0, 0), Vec3(0.5, -1, 1), Vec3(0.5, -1, -1)}).distance, 0.0);
  const TriangleDistance pierce = checked(unit, Tri{Vec3(0.2, 0.2, -1), Vec3(0.3, 0.2, 1), Vec3(0.2, 0.3, 1)});
  EXPECT_EQ(pierce.distance, 0.0);
  EXPECT_NEAR(pierce.point_p.z(), 0.0, 1e-15);  // a common point, on the face
  EXPECT_EQ(checked(unit, Tri{Vec3(0.1, 0.1, 0), Vec3(2, 0.1, 0), Vec3(0.1, 2, 0)}).distance, 0.0);
  // The same configurations moved off contact by tiny amounts: positive, never 0.
  for (const double eps : {1e-6, 1e-12, 1e-15, 1e-300}) {
    SCOPED_TRACE(eps);
    EXPECT_GT(checked(unit, Tri{Vec3(0.25, 0.25, eps), Vec3(0.25, 0.25, 1), Vec3(1, 1, 1)}).distance, 0.0);
    EXPECT_GT(checked(unit, Tri{Vec3(0, 0, eps), Vec3(-1, 0, 1), Vec3(0, -1, 1)}).distance, 0.0);
    EXPECT_GT(checked(unit, Tri{Vec3(0.1, 0.1, eps), Vec3(2, 0.1, eps), Vec3(0.1, 2, eps)}).distance, 0.0);
    if (1 + eps == 1) continue;  // 1 + 1e-300 rounds to 1: the corner is on the other triangle
    const double d = checked(unit, Tri{Vec3(1 + eps, 0, 0), Vec3(2, 0, 0), Vec3(2, 1, 0)}).distance;
    EXPECT_GT(d, 0.0);
    if (eps >= 1e-12) {
      EXPECT_NEAR(d, eps, 1e-15);
    }
  }
}

TEST(TriDistance, ConsistentWithTheTouchingPredicateOnRandomNearContacts) {
  // Triangles on a coarse integer grid: shared vertices, edges and coplanar faces are common,
  // and many pairs touch exactly.
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> g(0, 3);
  int touching = 0, apart = 0;
  for (int k = 0; k < 3000; ++k) {
    Tri p, q;
    for (Vec3& v : p) v = Vec3(g(rng), g(rng), g(rng) * 0.5);
    for (Vec3& v : q) v = Vec3(g(rng), g(rng), g(rng) * 0.5);
    const double d = checked(p, q).distance;
    (d == 0.0 ? touching : apart) += 1;
    if (::testing::Test::HasFailure()) break;
  }
  EXPECT_GT(touching, 300);
  EXPECT_GT(apart, 300);
}

// distance()'s search skips the touching test (query_detail::tri_tri_distance_disjoint): on
// pairs that do not touch it must give tri_tri_distance's answer bit for bit, points included.
// Grid pairs (shared vertices, edges, coplanar faces, near contacts) and random far pairs.
TEST(TriDistance, DisjointVariantEqualsTheDistanceOnPairsThatDoNotTouch) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> g(0, 3);
  int apart = 0;
  for (int k = 0; k < 4000; ++k) {
    Tri p, q;
    if (k % 2 == 0) {
      for (Vec3& v : p) v = Vec3(g(rng), g(rng), g(rng) * 0.5);
      for (Vec3& v : q) v = Vec3(g(rng), g(rng), g(rng) * 0.5);
    } else {
      for (Vec3& v : p) v = random_point(rng, 1.0);
      const Vec3 shift = random_point(rng, 2.0);
      for (Vec3& v : q) v = random_point(rng, 1.0) + shift;
    }
    if (tri_tri_overlap(p, q)) continue;
    ++apart;
    const TriangleDistance full = tri_tri_distance(p, q);
    const TriangleDistance fast = query_detail::tri_tri_distance_disjoint(p[0], p[1], p[2], q[0], q[1], q[2]);
    ASSERT_EQ(fast.distance, full.distance) << k;
    ASSERT_EQ(fast.point_p, full.point_p) << k;
    ASSERT_EQ(fast.point_q, full.point_q) << k;
  }
  EXPECT_GT(apart, 1500);
}

// The disjoint distance's candidates run in AVX2 lanes where the CPU has them
// (tri_distance_avx2.cpp) and one at a time otherwise: both paths must give the same distance
// and points bit for bit, on random, grid (shared vertices and edges, coplanar, parallel, touching:
// the answer there is meaningless but still one), degenerate (segments, points), nearly parallel
// and far-apart pairs, and the distance must stay symmetric on either path.
TEST(TriDistance, AvxAndScalarPathsAgreeBitForBit) {
  if (!query_detail::avx2_bounds_available()) GTEST_SKIP() << "no AVX2 lanes here: the scalar path alone runs";
  std::mt19937_64 rng(23);
  std::uniform_int_distribution<int> g(0, 3);
  std::uniform_real_distribution<double> tiny(-1e-9, 1e-9);
  const auto same = [](const TriangleDistance& x, const TriangleDistance& y) {
    return x.distance == y.distance && x.point_p == y.point_p && x.point_q == y.point_q;
  };
  int parallel_like = 0, within_count = 0, beyond_count = 0;
  for (int k = 0; k < 20000; ++k) {
    Tri p, q;
    switch (k % 6) {
      case 0:  // grid: shared corners, edges, coplanar and parallel faces, touching pairs
        for (Vec3& v : p) v = Vec3(g(rng), g(rng), g(rng) * 0.5);
        for (Vec3& v : q) v = Vec3(g(rng), g(rng), g(rng) * 0.5);
        break;
      case 1: {  // random, apart
        for (Vec3& v : p) v = random_point(rng, 1.0);
        const Vec3 shift = random_point(rng, 3.0);
        for (Vec3& v : q) v = random_point(rng, 1.0) + shift;
        break;
      }
      case 2:  // degenerate: a segment against a point or a triangle
        p = {random_point(rng, 1.0), random_point(rng, 1.0), Vec3::Zero()};
        p[2] = p[0] + (k % 4 == 0 ? 0.0 : 0.5) * (p[1] - p[0]);
        q = {random_point(rng, 1.0), random_point(rng, 1.0), random_point(rng, 1.0)};
        if (k % 5 == 0) q[1] = q[2] = q[0];
        break;
      case 3: {  // nearly parallel edges: a translated copy with a tiny tilt
        for (Vec3& v : p) v = random_point(rng, 1.0);
        const Vec3 shift = random_point(rng, 0.5);
        for (int i = 0; i < 3; ++i) q[i] = p[i] + shift + Vec3(tiny(rng), tiny(rng), tiny(rng));
        ++parallel_like;
        break;
      }
      case 4: {  // parallel planes, one triangle above the other
        for (Vec3& v : p) v = Vec3(random_point(rng, 1.0).x(), random_point(rng, 1.0).y(), 0.0);
        const double h = 1e-3 * (1 + g(rng));
        for (Vec3& v : q) v = Vec3(random_point(rng, 1.0).x(), random_point(rng, 1.0).y(), h);
        break;
      }
      default: {  // far from the origin, small and close
        const Vec3 far = random_point(rng, 1e6);
        for (Vec3& v : p) v = far + random_point(rng, 1e-3);
        for (Vec3& v : q) v = far + random_point(rng, 1e-3) + Vec3(2e-3, 0, 0);
      }
    }
    const TriangleDistance lanes = query_detail::tri_tri_distance_disjoint_path(p[0], p[1], p[2], q[0], q[1], q[2], true);
    const TriangleDistance scalar =
        query_detail::tri_tri_distance_disjoint_path(p[0], p[1], p[2], q[0], q[1], q[2], false);
    ASSERT_TRUE(same(lanes, scalar)) << k << ": " << lanes.distance << " vs " << scalar.distance;
    const TriangleDistance swapped =
        query_detail::tri_tri_distance_disjoint_path(q[0], q[1], q[2], p[0], p[1], p[2], false);
    ASSERT_EQ(swapped.distance, scalar.distance) << k;
    ASSERT_EQ(swapped.point_p, scalar.point_q) << k;
    if (!tri_tri_overlap(p, q)) ASSERT_TRUE(same(tri_tri_distance(p, q), lanes)) << k;
    // The margin predicate stops at the first candidate within the margin: on either path it
    // must still decide as the whole distance does, also a rounding step either side of it.
    const double d = scalar.distance;
    for (const double margin : {d, std::nextafter(d, 0.0), std::nextafter(d, 1e300), 0.5 * d, 2.0 * d}) {
      const bool within_lanes =
          query_detail::tri_tri_within_disjoint_path(p[0], p[1], p[2], q[0], q[1], q[2], margin, true);
      const bool within_scalar =
          query_detail::tri_tri_within_disjoint_path(p[0], p[1], p[2], q[0], q[1], q[2], margin, false);
      ASSERT_EQ(within_scalar, d <= margin) << k << " margin " << margin;
      ASSERT_EQ(within_lanes, d <= margin) << k << " margin " << margin;
      (d <= margin ? within_count : beyond_count) += 1;
    }
  }
  EXPECT_GT(parallel_like, 3000);
  EXPECT_GT(within_count, 40000);
  EXPECT_GT(beyond_count, 30000);
}

TEST(TriDistance, WithinIsTheDistanceComparedToTheMargin) {
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> g(0, 3);
  int within = 0, beyond = 0;
  for (int k = 0; k < 2000; ++k) {
    Tri p, q;
    for (Vec3& v : p) v = Vec3(g(rng), g(rng), g(rng) * 0.5);
    for (Vec3& v : q) v = Vec3(g(rng), g(rng), g(rng) * 0.5) + (k % 2 ? random_point(rng, 0.3) : Vec3::Zero());
    const double d = tri_tri_distance(p, q).distance;
    for (const double margin : {0.0, 0.1, 0.5, d, std::nextafter(d, 0.0), 1.0}) {
      const bool w = tri_tri_within(p[0], p[1], p[2], q[0], q[1], q[2], margin);
      EXPECT_EQ(w, d <= margin) << k << " margin " << margin;
      EXPECT_EQ(w, tri_tri_within(q[0], q[1], q[2], p[0], p[1], p[2], margin));
      (w ? within : beyond) += 1;
    }
  }
  EXPECT_GT(within, 2000);
  EXPECT_GT(beyond, 2000);
}

TEST(TriDistance, NearlyParallelEdges) {
  // Two long edges at an angle of ~1e-9 rad with a gap of 1e-3: the 2x2 solve cancels; the
  // endpoint candidates keep the answer right.
  const Tri p{Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(5, -1, 0)};
  for (const double tilt : {1e-5, 1e-9, 0.0}) {
    SCOPED_TRACE(tilt);
    const Tri q{Vec3(-3, 0, 1e-3), Vec3(7, 10 * tilt, 1e-3), Vec3(2, 1, 1e-3 + 1)};
    // q's edge y = tilt (x + 3) at height 1e-3 is nearest over x = 0, to p's corner (0, 0, 0).
    EXPECT_NEAR(checked(p, q).distance, std::hypot(1e-3, 3 * tilt), 1e-15);
  }
}

}  // namespace
}  // namespace tightbvh
