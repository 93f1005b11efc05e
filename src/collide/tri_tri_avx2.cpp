// Guigue & Devillers' triangle test (2003; tri_tri.cpp) on four pairs in AVX2 lanes, decided by
// the orientation filter alone (tri_tri4.hpp). Compiled with -mavx2 -mno-fma -ffp-contract=off
// (src/collide/CMakeLists.txt); nothing from Eigen or the rest of the library is compiled here.
#include "tri_tri4.hpp"

#ifdef TIGHTBVH_AVX2_BOUNDS
#include <immintrin.h>

namespace tightbvh::query_detail {
namespace {

struct V3 {
  __m256d x, y, z;
};

inline V3 load(const TriPairs4& t, int corner) {
  return {_mm256_load_pd(t.c[3 * corner]), _mm256_load_pd(t.c[3 * corner + 1]), _mm256_load_pd(t.c[3 * corner + 2])};
}
inline V3 sub(const V3& a, const V3& b) {
  return {_mm256_sub_pd(a.x, b.x), _mm256_sub_pd(a.y, b.y), _mm256_sub_pd(a.z, b.z)};
}
inline __m256d abs4(__m256d x) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), x); }
inline V3 select(__m256d mask, const V3& p, const V3& q) {  // p where mask, else q
  return {_mm256_blendv_pd(q.x, p.x, mask), _mm256_blendv_pd(q.y, p.y, mask), _mm256_blendv_pd(q.z, p.z, mask)};
}

// OrientPlane(a, b, c) (predicates.hpp): the rounded normal (b - a) x (c - a) and its permanent,
// the same products with |.|, which bound the rounding error of normal . (d - a).
struct Plane {
  V3 origin, normal, permanent;
};

inline Plane plane(const V3& a, const V3& b, const V3& c) {
  const V3 u = sub(b, a), v = sub(c, a);
  const __m256d yz = _mm256_mul_pd(u.y, v.z), zy = _mm256_mul_pd(u.z, v.y);
  const __m256d zx = _mm256_mul_pd(u.z, v.x), xz = _mm256_mul_pd(u.x, v.z);
  const __m256d xy = _mm256_mul_pd(u.x, v.y), yx = _mm256_mul_pd(u.y, v.x);
  return {a,
          {_mm256_sub_pd(yz, zy), _mm256_sub_pd(zx, xz), _mm256_sub_pd(xy, yx)},
          {_mm256_add_pd(abs4(yz), abs4(zy)), _mm256_add_pd(abs4(zx), abs4(xz)), _mm256_add_pd(abs4(xy), abs4(yx))}};
}

// The sign of orient3d(a, b, c, d) where the filter decides it: `above` (+1) or `below` (-1);
// neither where it cannot (OrientPlane::filter's kUndecided, and its exact zeros, left to the
// exact test too). NaN compares false: undecided.
struct Side {
  __m256d above, below;
};

inline Side side(const Plane& p, const V3& d) {
  const V3 w = sub(d, p.origin);
  const __m256d det = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(p.normal.x, w.x), _mm256_mul_pd(p.normal.y, w.y)),
                                    _mm256_mul_pd(p.normal.z, w.z));
  const __m256d perm = _mm256_add_pd(
      _mm256_add_pd(_mm256_mul_pd(p.permanent.x, abs4(w.x)), _mm256_mul_pd(p.permanent.y, abs4(w.y))),
      _mm256_mul_pd(p.permanent.z, abs4(w.z)));
  const __m256d bound = _mm256_mul_pd(_mm256_set1_pd(kTriLanesFilterBound), perm);
  const __m256d neg = _mm256_sub_pd(_mm256_setzero_pd(), det);
  return {_mm256_cmp_pd(det, bound, _CMP_GT_OQ), _mm256_cmp_pd(neg, bound, _CMP_GT_OQ)};
}

inline __m256d decided(const Side& s) { return _mm256_or_pd(s.above, s.below); }
inline __m256d and3(__m256d a, __m256d b, __m256d c) { return _mm256_and_pd(_mm256_and_pd(a, b), c); }
inline __m256d xor2(__m256d a, __m256d b) { return _mm256_xor_pd(a, b); }

// A triangle's "alone" corner, the one on its own side of the other triangle's plane (with
// strict signs, not all equal, exactly one): corner 0 where `is0`, 1 where `is1`, else 2, and
// whether it lies above that plane. `above[k]`: corner k above.
struct Alone {
  __m256d is0, is1, above;
};

inline Alone alone(const __m256d (&above)[3]) {
  // Corner k is alone iff its side differs from both others'.
  const __m256d is0 = _mm256_and_pd(xor2(above[0], above[1]), xor2(above[0], above[2]));
  const __m256d is1 = _mm256_and_pd(xor2(above[1], above[0]), xor2(above[1], above[2]));
  return {is0, is1, _mm256_blendv_pd(_mm256_blendv_pd(above[2], above[1], is1), above[0], is0)};
}

// The corners in Guigue & Devillers' canonical order (tri_tri.cpp): the alone corner first, then
// the two others, swapped where the other triangle's alone corner lies below this triangle's
// plane (swapping two corners flips the plane, so that corner comes to lie above it).
struct Canonical {
  V3 first, second, third;
};

inline Canonical canonical(const V3 (&t)[3], const Alone& own, const Alone& other) {
  // Rotations: alone 0 -> (t0, t1, t2), 1 -> (t1, t2, t0), else (t2, t0, t1).
  const V3 r0 = select(own.is0, t[0], select(own.is1, t[1], t[2]));
  const V3 r1 = select(own.is0, t[1], select(own.is1, t[2], t[0]));
  const V3 r2 = select(own.is0, t[2], select(own.is1, t[0], t[1]));
  return {r0, select(other.above, r1, r2), select(other.above, r2, r1)};
}

}  // namespace

int tri_tri_overlap4_avx2(const TriPairs4& pairs) {
  const V3 p[3] = {load(pairs, 0), load(pairs, 1), load(pairs, 2)};
  const V3 q[3] = {load(pairs, 3), load(pairs, 4), load(pairs, 5)};
  // q's corners against p's plane, and p's against q's (Section 3 of the paper).
  const Plane plane_p = plane(p[0], p[1], p[2]);
  const Side sq[3] = {side(plane_p, q[0]), side(plane_p, q[1]), side(plane_p, q[2])};
  const Plane plane_q = plane(q[0], q[1], q[2]);
  const Side sp[3] = {side(plane_q, p[0]), side(plane_q, p[1]), side(plane_q, p[2])};
  // One triangle strictly on one side of the other's plane: apart. (A degenerate triangle's
  // determinants are exactly zero, so the filter never decides them: these lanes hold
  // non-degenerate planes, and the scalar test answers false on them too, degenerate or not the
  // other triangle.)
  const __m256d apart = _mm256_or_pd(
      _mm256_or_pd(and3(sq[0].above, sq[1].above, sq[2].above), and3(sq[0].below, sq[1].below, sq[2].below)),
      _mm256_or_pd(and3(sp[0].above, sp[1].above, sp[2].above), and3(sp[0].below, sp[1].below, sp[2].below)));
  // Every corner strictly on one side, not all on one: both triangles cross the other's plane,
  // both are non-degenerate, and the intervals on the planes' common line decide.
  const __m256d strict = _mm256_and_pd(and3(decided(sq[0]), decided(sq[1]), decided(sq[2])),
                                       and3(decided(sp[0]), decided(sp[1]), decided(sp[2])));
  const __m256d crossing = _mm256_andnot_pd(apart, strict);
  int result = _mm256_movemask_pd(apart);
  if (_mm256_movemask_pd(crossing) == 0) return result;
  // Canonical form (tri_tri.cpp): p's alone corner above q's plane, q's above p's.
  const Alone alone_p = alone({sp[0].above, sp[1].above, sp[2].above});
  const Alone alone_q = alone({sq[0].above, sq[1].above, sq[2].above});
  const Canonical a = canonical(p, alone_p, alone_q), b = canonical(q, alone_q, alone_p);
  // The intervals [j, i] (p) and [k, l] (q) on the common line overlap iff k <= i and j <= l:
  // orient3d(a2, b1, a1, b2) > 0 means k beyond i, orient3d(a1, b1, a3, b3) > 0 l before j.
  const Side k_beyond_i = side(plane(a.second, b.first, a.first), b.second);
  const Side l_before_j = side(plane(a.first, b.first, a.third), b.third);
  // As the scalar test: false at the first positive sign; true when both are negative.
  const __m256d no = _mm256_or_pd(k_beyond_i.above, _mm256_and_pd(k_beyond_i.below, l_before_j.above));
  const __m256d yes = _mm256_and_pd(k_beyond_i.below, l_before_j.below);
  result |= _mm256_movemask_pd(_mm256_and_pd(crossing, _mm256_or_pd(no, yes)));
  result |= _mm256_movemask_pd(_mm256_and_pd(crossing, yes)) << 4;
  return result;
}

}  // namespace tightbvh::query_detail
#endif
