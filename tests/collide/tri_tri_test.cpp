#include "tightbvh/tri_tri.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <random>

#include <Eigen/Geometry>

namespace tightbvh {
namespace {

using Tri = std::array<Vec3, 3>;

// The answer must not depend on the order of the pair nor on the order of the corners.
// Every hand case below has dyadic coordinates, so the orientation determinants are exact and
// the expected answer is the exact one.
void expect_overlap(const Tri& p, const Tri& q, bool expected) {
  static constexpr int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  for (const auto& pp : perms)
    for (const auto& qq : perms) {
      const Tri a{p[pp[0]], p[pp[1]], p[pp[2]]};
      const Tri b{q[qq[0]], q[qq[1]], q[qq[2]]};
      ASSERT_EQ(tri_tri_overlap(a, b), expected) << "permutation " << pp[0] << pp[1] << pp[2] << " / " << qq[0] << qq[1]
                                                 << qq[2];
      ASSERT_EQ(tri_tri_overlap(b, a), expected) << "swapped pair";
    }
}

Tri shifted(const Tri& t, const Vec3& d) { return {t[0] + d, t[1] + d, t[2] + d}; }

const Tri kBase{Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0)};  // in the plane z = 0
constexpr double kTiny = 1.0 / 1024;

TEST(TriTri, Separated) {
  expect_overlap(kBase, shifted(kBase, {0, 0, 1}), false);
  expect_overlap(kBase, shifted(kBase, {0, 0, -kTiny}), false);
  expect_overlap(kBase, {Vec3(3, 3, -1), Vec3(3, 3, 1), Vec3(4, 2, 0)}, false);  // crosses the plane outside
}

TEST(TriTri, Crossing) {
  expect_overlap(kBase, {Vec3(0.5, 0.5, -1), Vec3(0.5, 0.5, 1), Vec3(-1, -1, 0)}, true);
  expect_overlap(kBase, {Vec3(1, -1, -1), Vec3(1, 3, -1), Vec3(1, 0.5, 2)}, true);  // cuts through two edges
}

TEST(TriTri, EdgeEdgeTouch) {
  // Q lies in the plane x = 1, region y + z <= 0; it meets the base only in (1, 0, 0), where
  // an edge of Q crosses the edge y = 0 of the base.
  const Tri q{Vec3(1, -1, 1), Vec3(1, 1, -1), Vec3(1, -1, -1)};
  expect_overlap(kBase, q, true);
  expect_overlap(kBase, shifted(q, {0, -kTiny, 0}), false);
  expect_overlap(kBase, shifted(q, {0, kTiny, 0}), true);
  // Skew edges touching in one point, the rest of the triangles apart.
  expect_overlap(kBase, {Vec3(1, 0, 0), Vec3(1, -1, 1), Vec3(2, -1, 1)}, true);
}

TEST(TriTri, VertexOnFace) {
  const Tri q{Vec3(0.5, 0.5, 0), Vec3(1, 0.5, 1), Vec3(0.5, 1, 1)};
  expect_overlap(kBase, q, true);
  expect_overlap(kBase, shifted(q, {0, 0, kTiny}), false);
  // Vertex on an edge, and vertex on a vertex.
  expect_overlap(kBase, {Vec3(1, 1, 0), Vec3(2, 2, 1), Vec3(1, 2, 1)}, true);
  expect_overlap(kBase, {Vec3(2, 0, 0), Vec3(3, 0, 1), Vec3(3, 1, 1)}, true);
  expect_overlap(kBase, {Vec3(2 + kTiny, 0, 0), Vec3(3, 0, 1), Vec3(3, 1, 1)}, false);
}

TEST(TriTri, SharedVertexAndEdge) {
  expect_overlap(kBase, {Vec3(0, 0, 0), Vec3(-1, 0, 1), Vec3(0, -1, 1)}, true);  // shared vertex only
  expect_overlap(kBase, {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, -1, 1)}, true);   // shared edge (hinge)
  expect_overlap(kBase, {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, -1, 0)}, true);   // shared edge, coplanar
}

TEST(TriTri, Coplanar) {
  expect_overlap(kBase, {Vec3(0.5, 0.5, 0), Vec3(3, 0.5, 0), Vec3(0.5, 3, 0)}, true);       // overlapping
  expect_overlap(kBase, {Vec3(0.25, 0.25, 0), Vec3(0.5, 0.25, 0), Vec3(0.25, 0.5, 0)}, true);  // contained
  expect_overlap(kBase, {Vec3(-1, -1, 0), Vec3(5, -1, 0), Vec3(-1, 5, 0)}, true);           // containing
  expect_overlap(kBase, {Vec3(2, 0, 0), Vec3(0, 2, 0), Vec3(2, 2, 0)}, true);               // touching along an edge
  expect_overlap(kBase, {Vec3(1, 1, 0), Vec3(2, 2, 0), Vec3(1, 3, 0)}, true);               // vertex on edge
  expect_overlap(kBase, {Vec3(2, 0, 0), Vec3(3, 0, 0), Vec3(2, -1, 0)}, true);              // vertex on vertex
  expect_overlap(kBase, {Vec3(2, 2, 0), Vec3(3, 2, 0), Vec3(2, 3, 0)}, false);              // disjoint
  expect_overlap(kBase, {Vec3(1 + kTiny, 1 + kTiny, 0), Vec3(2, 2, 0), Vec3(1, 3, 0)}, false);  // just apart
  // Coplanar but not in z = 0.
  const Tri tilted{Vec3(0, 0, 0), Vec3(2, 0, 2), Vec3(0, 2, 2)};
  expect_overlap(tilted, {Vec3(1, 1, 2), Vec3(2, 2, 4), Vec3(1, 3, 4)}, true);
  expect_overlap(tilted, {Vec3(2, 2, 4), Vec3(3, 2, 5), Vec3(2, 3, 5)}, false);
}

TEST(TriTri, DegenerateSegment) {
  expect_overlap(kBase, {Vec3(0.5, 0.5, -1), Vec3(0.5, 0.5, 1), Vec3(0.5, 0.5, 0.25)}, true);  // pierces
  expect_overlap(kBase, {Vec3(0.5, 0.5, 1), Vec3(0.5, 0.5, 2), Vec3(0.5, 0.5, 3)}, false);     // above
  expect_overlap(kBase, {Vec3(0.5, 0.5, 0), Vec3(0.5, 0.5, 2), Vec3(0.5, 0.5, 1)}, true);      // ends on the face
  expect_overlap(kBase, {Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(1, 0, 0)}, true);                 // in the plane, across an edge
  expect_overlap(kBase, {Vec3(3, -1, 0), Vec3(3, 1, 0), Vec3(3, 0, 0)}, false);                // in the plane, outside
  expect_overlap(kBase, {Vec3(2, -1, 0), Vec3(2, 1, 0), Vec3(2, 0, 0)}, true);                 // in the plane, through a vertex
  expect_overlap(kBase, {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(-1, 0, 0)}, true);                 // repeated corner, touches a vertex
  // Segment vs segment.
  const Tri s{Vec3(0, 0, 0), Vec3(2, 2, 0), Vec3(1, 1, 0)};
  expect_overlap(s, {Vec3(0, 2, 0), Vec3(2, 0, 0), Vec3(1, 1, 0)}, true);         // crossing at (1, 1, 0)
  expect_overlap(s, {Vec3(0, 2, 1), Vec3(2, 0, 1), Vec3(1, 1, 1)}, false);        // skew
  expect_overlap(s, {Vec3(1, 0, 0), Vec3(3, 2, 0), Vec3(2, 1, 0)}, false);        // parallel
  expect_overlap(s, {Vec3(2, 2, 0), Vec3(3, 3, 0), Vec3(4, 4, 0)}, true);         // collinear, touching
  expect_overlap(s, {Vec3(2.5, 2.5, 0), Vec3(3, 3, 0), Vec3(4, 4, 0)}, false);    // collinear, apart
  expect_overlap(s, {Vec3(0.5, 0.5, 0), Vec3(3, 3, 0), Vec3(4, 4, 0)}, true);     // collinear, overlapping
}

TEST(TriTri, DegeneratePoint) {
  const auto point = [](const Vec3& p) { return Tri{p, p, p}; };
  expect_overlap(kBase, point({0.5, 0.5, 0}), true);
  expect_overlap(kBase, point({0.5, 0.5, kTiny}), false);
  expect_overlap(kBase, point({1, 0, 0}), true);   // on an edge
  expect_overlap(kBase, point({2, 0, 0}), true);   // on a vertex
  expect_overlap(kBase, point({1 + kTiny, 1, 0}), false);
  const Tri s{Vec3(0, 0, 0), Vec3(2, 2, 0), Vec3(1, 1, 0)};
  expect_overlap(s, point({1.5, 1.5, 0}), true);
  expect_overlap(s, point({1.5, 1.25, 0}), false);
  expect_overlap(s, point({3, 3, 0}), false);
  expect_overlap(point({1, 2, 3}), point({1, 2, 3}), true);
  expect_overlap(point({1, 2, 3}), point({1, 2, 3 + kTiny}), false);
}

TEST(TriTri, NearlyParallel) {
  // Planes 1e-12 apart in slope: separated, and crossing along x + y = 1.
  expect_overlap(kBase, {Vec3(0, 0, 1e-3), Vec3(2, 0, 1e-3), Vec3(0, 2, 1e-3 + 1e-12)}, false);
  expect_overlap(kBase, {Vec3(0, 0, -1e-12), Vec3(2, 0, 1e-12), Vec3(0, 2, 1e-12)}, true);
  expect_overlap(kBase, {Vec3(3, 0, -1e-12), Vec3(5, 0, 1e-12), Vec3(3, 2, 1e-12)}, false);
}

// ------------------------------------------------------------------ exact integer reference
// An independent implementation in exact integer arithmetic: two closed triangles meet iff an
// edge of one meets the other (the vertices of their intersection lie on edges); degenerate
// triangles are their segment or point. Only valid for small integer coordinates.
using I3 = std::array<std::int64_t, 3>;
I3 sub(const I3& a, const I3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
I3 cross(const I3& a, const I3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
std::int64_t dot(const I3& a, const I3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
bool is_zero(const I3& a) { return a[0] == 0 && a[1] == 0 && a[2] == 0; }
int sgn(std::int64_t x) { return (x > 0) - (x < 0); }

bool ref_point_on_segment(const I3& p, const I3& a, const I3& b) {
  if (a == b) return p == a;
  const I3 ab = sub(b, a), ap = sub(p, a);
  return is_zero(cross(ab, ap)) && dot(ap, ab) >= 0 && dot(ap, ab) <= dot(ab, ab);
}

bool ref_segment_segment(const I3& a, const I3& b, const I3& c, const I3& d) {
  if (a == b) return ref_point_on_segment(a, c, d);
  if (c == d) return ref_point_on_segment(c, a, b);
  const I3 ab = sub(b, a), cd = sub(d, c);
  if (dot(cross(ab, sub(c, a)), sub(d, a)) != 0) return false;  // not coplanar
  const I3 n = cross(ab, cd);
  if (is_zero(n)) {  // parallel
    if (!is_zero(cross(ab, sub(c, a)))) return false;
    const std::int64_t tc = dot(sub(c, a), ab), td = dot(sub(d, a), ab);
    return std::max(tc, td) >= 0 && std::min(tc, td) <= dot(ab, ab);
  }
  const int s1 = sgn(dot(cross(ab, sub(c, a)), n)), s2 = sgn(dot(cross(ab, sub(d, a)), n));
  const int s3 = sgn(dot(cross(cd, sub(a, c)), n)), s4 = sgn(dot(cross(cd, sub(b, c)), n));
  return s1 * s2 <= 0 && s3 * s4 <= 0;
}

// Point (x / w) in the closed non-degenerate triangle t, x in homogeneous form, w != 0.
bool ref_point_in_triangle(const I3& x, std::int64_t w, const std::array<I3, 3>& t) {
  const I3 n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
  const I3 xw = {x[0] - w * t[0][0], x[1] - w * t[0][1], x[2] - w * t[0][2]};
  if (dot(n, xw) != 0) return false;
  for (int i = 0; i < 3; ++i) {
    const I3& u = t[i];
    const I3& v = t[(i + 1) % 3];
    const I3 rel = {x[0] - w * u[0], x[1] - w * u[1], x[2] - w * u[2]};
    if (sgn(dot(cross(sub(v, u), rel), n)) * sgn(w) < 0) return false;
  }
  return true;
}

bool ref_segment_triangle(const I3& a, const I3& b, const std::array<I3, 3>& t) {
  if (a == b) return ref_point_in_triangle(a, 1, t);
  const I3 n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
  const std::int64_t da = dot(n, sub(a, t[0])), db = dot(n, sub(b, t[0]));
  if (sgn(da) * sgn(db) > 0) return false;
  if (da == 0 && db == 0) {
    if (ref_point_in_triangle(a, 1, t) || ref_point_in_triangle(b, 1, t)) return true;
    for (int i = 0; i < 3; ++i)
      if (ref_segment_segment(a, b, t[i], t[(i + 1) % 3])) return true;
    return false;
  }
  // Crossing point (db a - da b) / (db - da).
  const I3 x = {db * a[0] - da * b[0], db * a[1] - da * b[1], db * a[2] - da * b[2]};
  return ref_point_in_triangle(x, db - da, t);
}

bool ref_overlap(const std::array<I3, 3>& p, const std::array<I3, 3>& q) {
  const auto degenerate = [](const std::array<I3, 3>& t) { return is_zero(cross(sub(t[1], t[0]), sub(t[2], t[0]))); };
  // A degenerate triangle: the segment between its two farthest corners (or a point).
  const auto hull = [](const std::array<I3, 3>& t) {
    std::pair<I3, I3> best{t[0], t[1]};
    std::int64_t d = dot(sub(t[1], t[0]), sub(t[1], t[0]));
    for (const auto& [i, j] : {std::pair{1, 2}, std::pair{2, 0}}) {
      const std::int64_t e = dot(sub(t[j], t[i]), sub(t[j], t[i]));
      if (e > d) d = e, best = {t[i], t[j]};
    }
    return best;
  };
  const bool dp = degenerate(p), dq = degenerate(q);
  if (dp && dq) {
    const auto [a, b] = hull(p);
    const auto [c, d] = hull(q);
    return ref_segment_segment(a, b, c, d);
  }
  if (dp) {
    const auto [a, b] = hull(p);
    return ref_segment_triangle(a, b, q);
  }
  if (dq) {
    const auto [a, b] = hull(q);
    return ref_segment_triangle(a, b, p);
  }
  for (int i = 0; i < 3; ++i)
    if (ref_segment_triangle(p[i], p[(i + 1) % 3], q) || ref_segment_triangle(q[i], q[(i + 1) % 3], p)) return true;
  return false;
}

Vec3 to_vec(const I3& a) { return Vec3(double(a[0]), double(a[1]), double(a[2])); }

// Random small-integer triangle pairs: many touching, coplanar and degenerate configurations.
TEST(TriTri, MatchesExactIntegerReference) {
  std::mt19937_64 rng(7);
  std::size_t counts[2] = {0, 0};
  for (const int range : {1, 2, 4}) {
    std::uniform_int_distribution<int> coord(-range, range);
    for (int iter = 0; iter < 200000; ++iter) {
      std::array<I3, 3> p, q;
      for (auto& v : p) v = {coord(rng), coord(rng), coord(rng)};
      for (auto& v : q) v = {coord(rng), coord(rng), coord(rng)};
      // Often share corners, or make q coplanar with p.
      const int mode = iter % 4;
      if (mode == 1) q[0] = p[0];
      if (mode == 2) q[0] = p[0], q[1] = p[1];
      if (mode == 3) {
        for (auto& v : q) v[2] = 0;
        for (auto& v : p) v[2] = 0;
      }
      const bool expected = ref_overlap(p, q);
      ++counts[expected];
      const Tri a{to_vec(p[0]), to_vec(p[1]), to_vec(p[2])};
      const Tri b{to_vec(q[0]), to_vec(q[1]), to_vec(q[2])};
      ASSERT_EQ(tri_tri_overlap(a, b), expected)
          << "p = " << a[0].transpose() << " | " << a[1].transpose() << " | " << a[2].transpose()
          << "\nq = " << b[0].transpose() << " | " << b[1].transpose() << " | " << b[2].transpose();
      // Exact rigid motions (signed axis permutation, integer translation, power-of-2 scale)
      // must not change the answer.
      const Vec3 shift(coord(rng), coord(rng), coord(rng));
      const auto move = [&](const Vec3& v) -> Vec3 { return Vec3(-4.0 * v.z(), 4.0 * v.x(), -4.0 * v.y()) + shift; };
      ASSERT_EQ(tri_tri_overlap(Tri{move(a[0]), move(a[1]), move(a[2])}, Tri{move(b[0]), move(b[1]), move(b[2])}),
                expected)
          << "p = " << a[0].transpose() << " | " << a[1].transpose() << " | " << a[2].transpose()
          << "\nq = " << b[0].transpose() << " | " << b[1].transpose() << " | " << b[2].transpose()
          << "\nshift = " << shift.transpose();
    }
  }
  // The generator must exercise both answers.
  EXPECT_GT(counts[0], 10000u);
  EXPECT_GT(counts[1], 10000u);
}

// Continuous random pairs: exact symmetry, and the same answer after a random rigid motion of
// both triangles (contact within rounding of the boundary has probability ~0 here).
TEST(TriTri, SymmetricAndStableUnderPose) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto rand_vec = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  std::size_t hits = 0;
  for (int iter = 0; iter < 100000; ++iter) {
    const Vec3 c = 0.6 * rand_vec();
    const Tri a{rand_vec(), rand_vec(), rand_vec()};
    const Tri b{c + 0.7 * rand_vec(), c + 0.7 * rand_vec(), c + 0.7 * rand_vec()};
    const bool r = tri_tri_overlap(a, b);
    hits += r;
    ASSERT_EQ(tri_tri_overlap(b, a), r);
    const Eigen::Quaterniond qrot(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized());
    const Mat3 rot = qrot.toRotationMatrix();
    const Vec3 t = 100.0 * rand_vec();
    const auto move = [&](const Vec3& v) { return Vec3(rot * v + t); };
    ASSERT_EQ(tri_tri_overlap(Tri{move(a[0]), move(a[1]), move(a[2])}, Tri{move(b[0]), move(b[1]), move(b[2])}), r)
        << "iteration " << iter;
  }
  EXPECT_GT(hits, 10000u);
  EXPECT_LT(hits, 90000u);
}

}  // namespace
}  // namespace tightbvh
