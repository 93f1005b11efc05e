#pragma once
// Internal: the candidates of the disjoint triangle distance (tri_distance.cpp) over a lane type,
// without branches, with no dependency but <cmath> (as box_lanes.hpp, and for the same reason:
// tri_distance_avx2.cpp instantiates them for AVX2 and must compile no shared inline function).
//
// tri_distance.cpp instantiates them for one double (the scalar path, and the winner's points on
// either path); tri_distance_avx2.cpp for four doubles. Every lane performs, operation for
// operation, the same IEEE arithmetic (no FMA: neither file is compiled with -mfma, and
// -ffp-contract=off), so a lane's squared distance equals the scalar one bit for bit and the
// search's answers do not depend on the CPU. Branch-free because which clamp applies, and
// whether a vertex projects inside a face, is close to a coin toss for the pairs distance()
// measures: a branchy scalar loop is mispredicted about 20 times a pair.
#include <cmath>

namespace tightbvh::query_detail {

// Lane operations for a plain double (masks are bool). Each mirrors the AVX2 instruction's
// semantics: lane_min(x, y) = x < y ? x : y (vminpd), compares false on NaN (ordered, quiet).
inline bool tri_lt(double x, double y) { return x < y; }
inline bool tri_le(double x, double y) { return x <= y; }
inline bool tri_gt(double x, double y) { return x > y; }
inline bool tri_eq(double x, double y) { return x == y; }
inline double tri_select(bool m, double p, double q) { return m ? p : q; }
inline bool tri_or(bool x, bool y) { return x || y; }
inline bool tri_and(bool x, bool y) { return x && y; }
inline bool tri_andnot(bool x, bool y) { return !x && y; }  // (not x) and y
template <class V>
V tri_splat(double x);
template <>
inline double tri_splat<double>(double x) {
  return x;
}

// x clamped to [0, 1] (NaN stays NaN: no candidate below is NaN for finite corners).
template <class V>
[[nodiscard]] inline V tri_clamp01(V x) {
  const V zero = tri_splat<V>(0.0), one = tri_splat<V>(1.0);
  return tri_select(tri_lt(x, zero), zero, tri_select(tri_gt(x, one), one, x));
}

template <class V>
[[nodiscard]] inline V tri_dot(const V (&x)[3], const V (&y)[3]) {
  return x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
}

// The point at parameter s of segment [a, b] (u = b - a); the endpoints exactly.
template <class V>
inline void tri_at(const V (&a)[3], const V (&b)[3], const V (&u)[3], V s, V (&out)[3]) {
  const auto is0 = tri_eq(s, tri_splat<V>(0.0)), is1 = tri_eq(s, tri_splat<V>(1.0));
  for (int k = 0; k < 3; ++k) out[k] = tri_select(is0, a[k], tri_select(is1, b[k], a[k] + s * u[k]));
}

// sin^2 of the angle between two edges below which the 2x2 solve (whose determinant then
// cancels) is backed by the four endpoint-to-segment candidates (tri_distance.cpp adds them for
// the flagged pairs). With sin^2 above it the determinant keeps ~10 correct digits.
constexpr double kTriNearlyParallel = 1e-6;

// Closest points of segments [p0, p1] and [q0, q1] (Ericson 2005, 5.1.9): minimise
// |r + s u - t v|^2 over [0,1]^2 (r = p0 - q0); the unconstrained s, then t for that s, then s
// again where t was clamped. A segment of length 0 is its point (its denominator replaced by 1:
// s or t is then 0, without a 0/0). Returns the squared distance, the points in xp, xq, and in
// `parallel` whether the pair needs the endpoint candidates (nearly parallel or degenerate).
template <class V, class M>
[[nodiscard]] inline V tri_segment_segment(const V (&p0)[3], const V (&p1)[3], const V (&q0)[3], const V (&q1)[3],
                                           V (&xp)[3], V (&xq)[3], M& parallel) {
  const V zero = tri_splat<V>(0.0), one = tri_splat<V>(1.0);
  V u[3], v[3], r[3];
  for (int k = 0; k < 3; ++k) u[k] = p1[k] - p0[k], v[k] = q1[k] - q0[k], r[k] = p0[k] - q0[k];
  const V a = tri_dot(u, u), e = tri_dot(v, v), b = tri_dot(u, v), c = tri_dot(u, r), f = tri_dot(v, r);
  const V det = a * e - b * b;
  const auto solvable = tri_gt(det, zero);
  const V a1 = tri_select(tri_eq(a, zero), one, a), e1 = tri_select(tri_eq(e, zero), one, e);
  const V s0 = tri_select(solvable, tri_clamp01((b * f - c * e) / tri_select(solvable, det, one)), zero);
  const V t_free = (b * s0 + f) / e1;
  const V t = tri_clamp01(t_free);
  // t clamped (or B's segment a point): s for that t; b * 0 - c = -c and b * 1 - c exactly.
  const auto again = tri_or(tri_or(tri_lt(t_free, zero), tri_gt(t_free, one)), tri_eq(e, zero));
  const V s = tri_select(again, tri_clamp01((b * t - c) / a1), s0);
  tri_at(p0, p1, u, s, xp);
  tri_at(q0, q1, v, t, xq);
  parallel = tri_le(det, tri_splat<V>(kTriNearlyParallel) * a * e);
  V d[3];
  for (int k = 0; k < 3; ++k) d[k] = xp[k] - xq[k];
  return tri_dot(d, d);
}

// A triangle's face for the vertex-face candidates (tri_distance.cpp computes it once per
// triangle): its corners, edges c[i+1] - c[i], normal (c1 - c0) x (c2 - c0) and its square, and
// whether the face counts (not nearly degenerate).
template <class V, class M>
struct TriFace {
  V c[3][3];
  V edge[3][3];
  V normal[3];
  V normal_squared;  // 1 where the face does not count (no division by 0)
  M valid;
};

template <class V>
inline void tri_cross(const V (&x)[3], const V (&y)[3], V (&out)[3]) {
  out[0] = x[1] * y[2] - x[2] * y[1];
  out[1] = x[2] * y[0] - x[0] * y[2];
  out[2] = x[0] * y[1] - x[1] * y[0];
}

// Vertex x against the face: the squared distance to its projection y on the plane where x
// projects into the closed triangle and the face counts, else infinity.
template <class V, class M>
[[nodiscard]] inline V tri_vertex_face(const V (&x)[3], const TriFace<V, M>& f, V (&y)[3]) {
  const V zero = tri_splat<V>(0.0);
  M outside = tri_andnot(f.valid, tri_eq(zero, zero));  // not valid
  for (int i = 0; i < 3; ++i) {
    V w[3], side[3];
    for (int k = 0; k < 3; ++k) w[k] = x[k] - f.c[i][k];
    tri_cross(f.edge[i], w, side);
    outside = tri_or(outside, tri_lt(tri_dot(f.normal, side), zero));
  }
  V w[3];
  for (int k = 0; k < 3; ++k) w[k] = x[k] - f.c[0][k];
  const V h = tri_dot(f.normal, w) / f.normal_squared;
  for (int k = 0; k < 3; ++k) y[k] = x[k] - f.normal[k] * h;
  V d[3];
  for (int k = 0; k < 3; ++k) d[k] = x[k] - y[k];
  return tri_select(outside, tri_splat<V>(INFINITY), tri_dot(d, d));
}

}  // namespace tightbvh::query_detail

namespace tightbvh::query_detail {

// The candidates of two triangles (in canonical order): 9 edge pairs, k = 3 i + j for P's edge
// from p[i] to p[i+1] and Q's from q[j] to q[j+1]; then p[0..2] against Q's face (9..11) and
// q[0..2] against P's face (12..14).
constexpr int kTriCandidates = 15;
struct TriPairInput {
  double p[3][3];
  double q[3][3];
  TriFace<double, bool> face_p, face_q;
};

// Defined in tri_distance_avx2.cpp where TIGHTBVH_AVX2_BOUNDS is (box_bounds4.hpp): the squared
// distances in four AVX2 lanes, each equal bit for bit to the scalar one. The edge pairs fill
// d2[0..8] and return the pairs flagged `parallel` (bit k); the vertex-face candidates fill
// d2[9..14].
unsigned tri_edge_pairs_avx2(const TriPairInput& in, double (&d2)[kTriCandidates]);
// Whether some edge pair's max(sqrt(d2), DBL_MIN) <= margin, batch by batch, stopping at the
// first batch that has one; when none has, `parallel` is set as tri_edge_pairs_avx2 returns it.
bool tri_edge_pairs_within_avx2(const TriPairInput& in, double margin, unsigned& parallel);
void tri_vertex_faces_avx2(const TriPairInput& in, double (&d2)[kTriCandidates]);

}  // namespace tightbvh::query_detail
