// The disjoint triangle distance's 15 candidates in four AVX2 lanes of doubles (tri_lanes.hpp).
// Compiled with -mavx2 -mno-fma -ffp-contract=off (src/collide/CMakeLists.txt) and called only
// where the CPU reports AVX2; as box_bounds_avx2.cpp, nothing from Eigen or the rest of the
// library is compiled here.
#include "box_bounds4.hpp"

#ifdef TIGHTBVH_AVX2_BOUNDS
#include <immintrin.h>

#include "tri_lanes.hpp"
#include "lanes_avx2.hpp"

namespace tightbvh::query_detail {
namespace {

struct Mask4 {
  __m256d v;
};
// Ordered, quiet compares: false on NaN, as the scalar's.
inline Mask4 tri_lt(F64x4 x, F64x4 y) { return {_mm256_cmp_pd(x.v, y.v, _CMP_LT_OQ)}; }
inline Mask4 tri_le(F64x4 x, F64x4 y) { return {_mm256_cmp_pd(x.v, y.v, _CMP_LE_OQ)}; }
inline Mask4 tri_gt(F64x4 x, F64x4 y) { return {_mm256_cmp_pd(x.v, y.v, _CMP_GT_OQ)}; }
inline Mask4 tri_eq(F64x4 x, F64x4 y) { return {_mm256_cmp_pd(x.v, y.v, _CMP_EQ_OQ)}; }
inline F64x4 tri_select(Mask4 m, F64x4 p, F64x4 q) { return {_mm256_blendv_pd(q.v, p.v, m.v)}; }
inline Mask4 tri_or(Mask4 x, Mask4 y) { return {_mm256_or_pd(x.v, y.v)}; }
inline Mask4 tri_and(Mask4 x, Mask4 y) { return {_mm256_and_pd(x.v, y.v)}; }
inline Mask4 tri_andnot(Mask4 x, Mask4 y) { return {_mm256_andnot_pd(x.v, y.v)}; }

}  // namespace

template <>
inline F64x4 tri_splat<F64x4>(double x) {
  return {_mm256_set1_pd(x)};
}

namespace {

// Lane l of corner array c at indices idx[l].
inline void corners(const double (&c)[3][3], const int (&idx)[4], F64x4 (&out)[3]) {
  for (int k = 0; k < 3; ++k) out[k] = {_mm256_set_pd(c[idx[3]][k], c[idx[2]][k], c[idx[1]][k], c[idx[0]][k])};
}

inline TriFace<F64x4, Mask4> broadcast(const TriFace<double, bool>& f) {
  TriFace<F64x4, Mask4> out;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      out.c[i][k] = tri_splat<F64x4>(f.c[i][k]);
      out.edge[i][k] = tri_splat<F64x4>(f.edge[i][k]);
    }
  for (int k = 0; k < 3; ++k) out.normal[k] = tri_splat<F64x4>(f.normal[k]);
  out.normal_squared = tri_splat<F64x4>(f.normal_squared);
  out.valid = {_mm256_castsi256_pd(_mm256_set1_epi64x(f.valid ? -1 : 0))};
  return out;
}

}  // namespace

unsigned tri_candidates_avx2(const TriPairInput& in, double (&d2)[kTriCandidates]) {
  alignas(32) double out[20];
  unsigned parallel = 0;
  // Edge pairs k = 4 b + l (the last batch repeats pair 8).
  static constexpr int kI[3][4] = {{0, 0, 0, 1}, {1, 1, 2, 2}, {2, 2, 2, 2}};
  static constexpr int kJ[3][4] = {{0, 1, 2, 0}, {1, 2, 0, 1}, {2, 2, 2, 2}};
  for (int b = 0; b < 3; ++b) {
    int i1[4], j1[4];
    for (int l = 0; l < 4; ++l) i1[l] = (kI[b][l] + 1) % 3, j1[l] = (kJ[b][l] + 1) % 3;
    F64x4 p0[3], p1[3], q0[3], q1[3], xp[3], xq[3];
    corners(in.p, kI[b], p0);
    corners(in.p, i1, p1);
    corners(in.q, kJ[b], q0);
    corners(in.q, j1, q1);
    Mask4 par;
    const F64x4 d = tri_segment_segment<F64x4, Mask4>(p0, p1, q0, q1, xp, xq, par);
    _mm256_store_pd(out + 4 * b, d.v);
    parallel |= static_cast<unsigned>(_mm256_movemask_pd(par.v)) << (4 * b);
  }
  // Vertices against faces: p[0..2] against Q's, q[0..2] against P's (the fourth lane repeats).
  static constexpr int kV[4] = {0, 1, 2, 2};
  const TriFace<F64x4, Mask4> fq = broadcast(in.face_q), fp = broadcast(in.face_p);
  F64x4 x[3], y[3];
  corners(in.p, kV, x);
  _mm256_store_pd(out + 12, tri_vertex_face<F64x4, Mask4>(x, fq, y).v);
  corners(in.q, kV, x);
  _mm256_store_pd(out + 16, tri_vertex_face<F64x4, Mask4>(x, fp, y).v);
  for (int k = 0; k < 9; ++k) d2[k] = out[k];
  for (int k = 0; k < 3; ++k) d2[9 + k] = out[12 + k], d2[12 + k] = out[16 + k];
  return parallel & 0x1ff;
}

}  // namespace tightbvh::query_detail
#endif
