// Exact-predicate-consistent triangle-triangle distance: the touching test first (tri_tri.hpp),
// then the least of the edge-edge and vertex-face candidates. See include/tightbvh/tri_distance.hpp.
#include "tightbvh/tri_distance.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "box_bounds4.hpp"
#include "tightbvh/tri_tri.hpp"
#include "tri_distance_disjoint.hpp"
#include "tri_lanes.hpp"

namespace tightbvh {
namespace {

// The closest pair found so far: `p` on the first triangle, `q` on the second.
struct Closest {
  double squared = std::numeric_limits<double>::infinity();
  Vec3 p = Vec3::Zero();
  Vec3 q = Vec3::Zero();

  // True when the pair became the best.
  bool offer(const Vec3& on_p, const Vec3& on_q) {
    const double d2 = (on_p - on_q).squaredNorm();
    if (!(d2 < squared)) return false;
    squared = d2, p = on_p, q = on_q;
    return true;
  }
};

[[nodiscard]] inline double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

// The point at parameter s on segment [a, b] (direction u = b - a); the endpoints exactly.
[[nodiscard]] inline Vec3 at(const Vec3& a, const Vec3& b, const Vec3& u, double s) {
  return s == 0.0 ? a : (s == 1.0 ? b : Vec3(a + s * u));
}

// The point of segment [a, b] (u = b - a) closest to x.
[[nodiscard]] inline Vec3 closest_on_segment(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& u) {
  const double uu = u.squaredNorm();
  return uu == 0.0 ? a : at(a, b, u, clamp01((x - a).dot(u) / uu));
}

// sin^2 of the angle between two edges below which the 2x2 solve (whose determinant then
// cancels) is backed by the four endpoint-to-segment candidates. With sin^2 above it the
// determinant keeps ~10 correct digits.
constexpr double kNearlyParallel = 1e-6;

// Closest points of segments [p0, p1] and [q0, q1]: minimise |r + s u - t v|^2 over [0,1]^2
// (r = p0 - q0); the unconstrained s, then t for that s, then s again if t was clamped.
// Returns true when it improved `best`.
bool segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, Closest& best) {
  const Vec3 u = p1 - p0, v = q1 - q0, r = p0 - q0;
  const double a = u.squaredNorm(), e = v.squaredNorm();
  if (a == 0.0 || e == 0.0) {  // a point against a segment (or a point)
    if (a == 0.0) return best.offer(p0, closest_on_segment(p0, q0, q1, v));
    return best.offer(closest_on_segment(q0, p0, p1, u), q0);
  }
  const double b = u.dot(v), c = u.dot(r), f = v.dot(r);
  const double det = a * e - b * b;
  double s = det > 0.0 ? clamp01((b * f - c * e) / det) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0, s = clamp01(-c / a);
  } else if (t > 1.0) {
    t = 1.0, s = clamp01((b - c) / a);
  }
  bool improved = best.offer(at(p0, p1, u, s), at(q0, q1, v, t));
  if (det <= kNearlyParallel * a * e) {
    improved |= best.offer(p0, closest_on_segment(p0, q0, q1, v));
    improved |= best.offer(p1, closest_on_segment(p1, q0, q1, v));
    improved |= best.offer(closest_on_segment(q0, p0, p1, u), q0);
    improved |= best.offer(closest_on_segment(q1, p0, p1, u), q1);
  }
  return improved;
}

// A triangle's plane, or none for (nearly) degenerate triangles: with sin(angle) < 1e-10 the
// rounded normal's direction is unreliable, and the edges (segment candidates) cover the face.
struct Face {
  const Vec3* c[3];
  Vec3 normal;  // (c1 - c0) x (c2 - c0), not normalised
  double normal_squared;
  bool valid;

  Face(const Vec3& c0, const Vec3& c1, const Vec3& c2) : c{&c0, &c1, &c2} {
    const Vec3 e1 = c1 - c0, e2 = c2 - c0;
    normal = e1.cross(e2);
    normal_squared = normal.squaredNorm();
    valid = normal_squared > 1e-20 * e1.squaredNorm() * e2.squaredNorm() && normal_squared > 0.0;
  }
  // x projects into the closed triangle (the component of x along the normal cancels out).
  [[nodiscard]] bool projects_inside(const Vec3& x) const {
    for (int i = 0; i < 3; ++i) {
      const Vec3& a = *c[i];
      const Vec3& b = *c[(i + 1) % 3];
      if (normal.dot((b - a).cross(x - a)) < 0.0) return false;
    }
    return true;
  }
  [[nodiscard]] Vec3 project(const Vec3& x) const { return x - normal * (normal.dot(x - *c[0]) / normal_squared); }
};

// Vertex x against the interior of `face`; `x_on_p` says which triangle x belongs to.
void vertex_face(const Vec3& x, const Face& face, bool x_on_p, Closest& best) {
  if (!face.valid || !face.projects_inside(x)) return;
  const Vec3 y = face.project(x);
  if (x_on_p)
    best.offer(x, y);
  else
    best.offer(y, x);
}

// Touching triangles only (to report a common point): where edge [a, b] crosses the face's plane
// inside the face. Non-coplanar touching triangles meet in a segment whose endpoints lie on
// edges of one triangle and in the other, so one of these crossings (or an edge-edge or
// vertex-face candidate, for edges in the plane) is a common point up to rounding.
void edge_crossing(const Vec3& a, const Vec3& b, const Face& face, bool edge_on_p, Closest& best) {
  if (!face.valid) return;
  const double sa = face.normal.dot(a - *face.c[0]), sb = face.normal.dot(b - *face.c[0]);
  if ((sa > 0.0 && sb > 0.0) || (sa < 0.0 && sb < 0.0) || sa == sb) return;
  const Vec3 x = a + (sa / (sa - sb)) * (b - a);
  if (!face.projects_inside(x)) return;
  const Vec3 y = face.project(x);
  if (edge_on_p)
    best.offer(x, y);
  else
    best.offer(y, x);
}

// Touching triangles (tri_tri_overlap says so; the distance is 0): a common point up to
// rounding, from the candidates and the edges' crossings of the other face.
Closest closest_touching(const std::array<Vec3, 3>& p, const std::array<Vec3, 3>& q) {
  Closest best;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) segment_segment(p[i], p[(i + 1) % 3], q[j], q[(j + 1) % 3], best);
  const Face face_p(p[0], p[1], p[2]), face_q(q[0], q[1], q[2]);
  for (int i = 0; i < 3; ++i) {
    vertex_face(p[i], face_q, true, best);
    vertex_face(q[i], face_p, false, best);
  }
  if (best.squared > 0.0) {
    for (int i = 0; i < 3; ++i) {
      edge_crossing(p[i], p[(i + 1) % 3], face_q, true, best);
      edge_crossing(q[i], q[(i + 1) % 3], face_p, false, best);
    }
  }
  return best;
}

// ---- Disjoint triangles: every candidate, branch-free (tri_lanes.hpp) ----------------------
// The 15 candidates (9 edge pairs, 6 vertex-face) are all measured and the least kept (the first
// on a tie), in four AVX2 lanes where the CPU has them, else one at a time with the same
// arithmetic; either way the same squared distances bit for bit. The winner's points are then
// recomputed by the scalar kernel (the same operations, so the same values), and the edge pairs
// flagged nearly parallel or degenerate add their four endpoint-to-segment candidates (rare).
// All 15 are measured rather than stopping early as PQP does (at the first candidate whose normal
// planes separate the triangles): that test and the clamps' branches are mispredicted about 20
// times a pair (callgrind's model), at ~400 ns a pair (perf, shipped separated poses).

using query_detail::TriFace;
using query_detail::TriPairInput;
using query_detail::kTriCandidates;

TriFace<double, bool> make_face(const std::array<Vec3, 3>& c) {
  TriFace<double, bool> f;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      f.c[i][k] = c[i][k];
      f.edge[i][k] = c[(i + 1) % 3][k] - c[i][k];
    }
  const Face face(c[0], c[1], c[2]);  // the face test and normal of the touching path
  for (int k = 0; k < 3; ++k) f.normal[k] = face.normal[k];
  f.valid = face.valid;
  f.normal_squared = face.valid ? face.normal_squared : 1.0;
  return f;
}

unsigned edge_pairs_scalar(const TriPairInput& in, double (&d2)[kTriCandidates]) {
  unsigned parallel = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double xp[3], xq[3];
      bool par;
      d2[3 * i + j] = query_detail::tri_segment_segment<double, bool>(in.p[i], in.p[(i + 1) % 3], in.q[j],
                                                                      in.q[(j + 1) % 3], xp, xq, par);
      parallel |= static_cast<unsigned>(par) << (3 * i + j);
    }
  return parallel;
}

void vertex_faces_scalar(const TriPairInput& in, double (&d2)[kTriCandidates]) {
  for (int i = 0; i < 3; ++i) {
    double y[3];
    d2[9 + i] = query_detail::tri_vertex_face<double, bool>(in.p[i], in.face_q, y);
    d2[12 + i] = query_detail::tri_vertex_face<double, bool>(in.q[i], in.face_p, y);
  }
}

// The edge pairs' candidates (d2[0..8]) in lanes or one at a time; returns the pairs flagged parallel.
unsigned edge_pairs(const TriPairInput& in, bool avx2, double (&d2)[kTriCandidates]) {
#ifdef TIGHTBVH_AVX2_BOUNDS
  if (avx2) return query_detail::tri_edge_pairs_avx2(in, d2);
#endif
  (void)avx2;
  return edge_pairs_scalar(in, d2);
}

// The vertex-face candidates (d2[9..14]), likewise.
void vertex_faces(const TriPairInput& in, bool avx2, double (&d2)[kTriCandidates]) {
#ifdef TIGHTBVH_AVX2_BOUNDS
  if (avx2) return query_detail::tri_vertex_faces_avx2(in, d2);
#endif
  (void)avx2;
  vertex_faces_scalar(in, d2);
}

// The corners of a pair; `with_faces`: also the faces (the vertex-face candidates need them).
TriPairInput pair_input(const std::array<Vec3, 3>& p, const std::array<Vec3, 3>& q, bool with_faces = true) {
  TriPairInput in;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) in.p[i][k] = p[i][k], in.q[i][k] = q[i][k];
  if (with_faces) in.face_p = make_face(p), in.face_q = make_face(q);
  return in;
}

// The four endpoint-to-segment candidates of a flagged edge pair k (nearly parallel or
// degenerate), offered to `best`.
void offer_endpoints(const std::array<Vec3, 3>& p, const std::array<Vec3, 3>& q, int k, Closest& best) {
  const int i = k / 3, j = k % 3;
  const Vec3 &p0 = p[i], &p1 = p[(i + 1) % 3], &q0 = q[j], &q1 = q[(j + 1) % 3];
  const Vec3 u = p1 - p0, v = q1 - q0;
  best.offer(p0, closest_on_segment(p0, q0, q1, v));
  best.offer(p1, closest_on_segment(p1, q0, q1, v));
  best.offer(closest_on_segment(q0, p0, p1, u), q0);
  best.offer(closest_on_segment(q1, p0, p1, u), q1);
}

Vec3 vec(const double (&x)[3]) { return {x[0], x[1], x[2]}; }

// Candidate k's points (the scalar kernel, as measured).
void candidate_points(const TriPairInput& in, int k, Closest& best) {
  double xp[3], xq[3];
  if (k < 9) {
    const int i = k / 3, j = k % 3;
    bool par;
    (void)query_detail::tri_segment_segment<double, bool>(in.p[i], in.p[(i + 1) % 3], in.q[j], in.q[(j + 1) % 3], xp,
                                                          xq, par);
  } else if (k < 12) {
    for (int c = 0; c < 3; ++c) xp[c] = in.p[k - 9][c];
    (void)query_detail::tri_vertex_face<double, bool>(in.p[k - 9], in.face_q, xq);
  } else {
    for (int c = 0; c < 3; ++c) xq[c] = in.q[k - 12][c];
    (void)query_detail::tri_vertex_face<double, bool>(in.q[k - 12], in.face_p, xp);
  }
  best.p = vec(xp), best.q = vec(xq);
}

Closest closest_disjoint(const std::array<Vec3, 3>& p, const std::array<Vec3, 3>& q, bool avx2) {
  const TriPairInput in = pair_input(p, q);
  double d2[kTriCandidates];
  unsigned parallel = edge_pairs(in, avx2, d2);
  vertex_faces(in, avx2, d2);
  // The least, the first on a tie (selects, not branches: which candidate wins is a coin toss).
  int win = -1;
  double least = std::numeric_limits<double>::infinity();
  for (int k = 0; k < kTriCandidates; ++k) {
    const bool less = d2[k] < least;
    least = less ? d2[k] : least;
    win = less ? k : win;
  }
  Closest best;
  if (win >= 0) {
    best.squared = least;
    candidate_points(in, win, best);
  }
  // Nearly parallel or degenerate edge pairs: the 2x2 solve may have cancelled; the endpoint
  // candidates keep the answer right.
  for (; parallel != 0; parallel &= parallel - 1) offer_endpoints(p, q, std::countr_zero(parallel), best);
  return best;
}

// The reported distance of disjoint triangles whose closest pair is `squared` apart: never 0,
// even when the closest points round to the same double.
[[nodiscard]] inline double disjoint_distance(double squared) {
  return std::max(std::sqrt(squared), std::numeric_limits<double>::min());
}

// disjoint_distance(closest_disjoint(p, q, avx2).squared) <= margin, exactly, without the
// closest points and stopping at the first candidate within the margin: that distance is the
// least of the candidates (and of the flagged pairs' endpoint candidates), and the comparison is
// monotone in it, so it holds iff it holds for some candidate. The edge pairs go first, in lanes
// batch by batch, and the faces are made only when they decide nothing: on the shipped pair's
// near poses at a margin of 1% the edge pairs decide most pairs, and this path takes a third
// fewer instructions than the whole distance did (docs/design-notes/distance-margin-solid.md,
// "Margin: boxes inflated, the pair test stops at the first candidate").
bool disjoint_within(const std::array<Vec3, 3>& p, const std::array<Vec3, 3>& q, bool avx2, double margin) {
  TriPairInput in = pair_input(p, q, false);
  double d2[kTriCandidates];
  const auto any_within = [&](int from, int to) {
    bool within = false;
    for (int k = from; k < to; ++k) within |= disjoint_distance(d2[k]) <= margin;
    return within;
  };
  unsigned parallel = 0;
#ifdef TIGHTBVH_AVX2_BOUNDS
  if (avx2) {
    if (query_detail::tri_edge_pairs_within_avx2(in, margin, parallel)) return true;
  } else
#endif
  {
    parallel = edge_pairs_scalar(in, d2);
    if (any_within(0, 9)) return true;
  }
  in.face_p = make_face(p), in.face_q = make_face(q);
  vertex_faces(in, avx2, d2);
  if (any_within(9, kTriCandidates)) return true;
  for (; parallel != 0; parallel &= parallel - 1) {
    Closest best;
    offer_endpoints(p, q, std::countr_zero(parallel), best);
    if (disjoint_distance(best.squared) <= margin) return true;
  }
  return false;
}

bool use_avx2() {
  static const bool avx2 = query_detail::avx2_bounds_available();
  return avx2;
}

// Canonical order (lexicographic on the nine coordinates of each), so that swapping the two
// triangles swaps the points and leaves every rounding, hence the distance, unchanged.
[[nodiscard]] bool canonical_swap(std::array<Vec3, 3>& p, std::array<Vec3, 3>& q) {
  const auto key = [](const std::array<Vec3, 3>& t) {
    return std::array<double, 9>{t[0].x(), t[0].y(), t[0].z(), t[1].x(), t[1].y(),
                                 t[1].z(), t[2].x(), t[2].y(), t[2].z()};
  };
  const bool swapped = key(q) < key(p);
  if (swapped) std::swap(p, q);
  return swapped;
}

}  // namespace

namespace {

TriangleDistance distance_given(bool touching, bool avx2, const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  std::array<Vec3, 3> p{p0, p1, p2}, q{q0, q1, q2};
  const bool swapped = canonical_swap(p, q);
  const Closest best = touching ? closest_touching(p, q) : closest_disjoint(p, q, avx2);
  TriangleDistance result;
  result.point_p = swapped ? best.q : best.p;
  result.point_q = swapped ? best.p : best.q;
  result.distance = touching ? 0.0 : disjoint_distance(best.squared);
  return result;
}

}  // namespace

TriangleDistance tri_tri_distance(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                  const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  return distance_given(tri_tri_overlap(p0, p1, p2, q0, q1, q2), use_avx2(), p0, p1, p2, q0, q1, q2);
}

TriangleDistance query_detail::tri_tri_distance_disjoint(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                                         const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  return distance_given(false, use_avx2(), p0, p1, p2, q0, q1, q2);
}

TriangleDistance query_detail::tri_tri_distance_disjoint_path(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                                              const Vec3& q0, const Vec3& q1, const Vec3& q2,
                                                              bool avx2) {
  return distance_given(false, avx2 && use_avx2(), p0, p1, p2, q0, q1, q2);
}

bool query_detail::tri_tri_within_disjoint_path(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                                const Vec3& q0, const Vec3& q1, const Vec3& q2, double margin,
                                                bool avx2) {
  std::array<Vec3, 3> p{p0, p1, p2}, q{q0, q1, q2};
  (void)canonical_swap(p, q);
  return disjoint_within(p, q, avx2 && use_avx2(), margin);
}

bool tri_tri_within(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                    const Vec3& q0, const Vec3& q1, const Vec3& q2, double margin) {
  // The candidates first, the touching test only when none is within the margin: most pairs
  // within a margin are near, not crossing. The same answer, bit for bit, as the touching test
  // first: triangles that touch are within the margin either way, and for those that do not,
  // the candidates decide in both orders.
  std::array<Vec3, 3> p{p0, p1, p2}, q{q0, q1, q2};
  (void)canonical_swap(p, q);  // the order alone matters here
  if (disjoint_within(p, q, use_avx2(), margin)) return true;
  return tri_tri_overlap(p0, p1, p2, q0, q1, q2);
}

}  // namespace tightbvh
