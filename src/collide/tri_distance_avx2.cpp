// The disjoint triangle distance's 15 candidates in four AVX2 lanes of doubles (tri_lanes.hpp).
// Compiled with -mavx2 -mno-fma -ffp-contract=off (src/collide/CMakeLists.txt) and called only
// where the CPU reports AVX2; as box_bounds_avx2.cpp, nothing from Eigen or the rest of the
// library is compiled here.
#include "box_bounds4.hpp"

#ifdef TIGHTBVH_AVX2_BOUNDS
#include <immintrin.h>

#include <limits>

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

namespace {

// One coordinate of a triangle's corners in lanes: c0, c1, c2, c0. A batch of edge pairs takes
// its corners from these by permutes (one instruction each), not by gathers lane by lane.
struct CornerLanes {
  F64x4 p[3], q[3];
};

CornerLanes corner_lanes(const TriPairInput& in) {
  CornerLanes c;
  for (int k = 0; k < 3; ++k) {
    c.p[k] = {_mm256_set_pd(in.p[0][k], in.p[2][k], in.p[1][k], in.p[0][k])};
    c.q[k] = {_mm256_set_pd(in.q[0][k], in.q[2][k], in.q[1][k], in.q[0][k])};
  }
  return c;
}

template <int L0, int L1, int L2, int L3>
inline void pick(const F64x4 (&lanes)[3], F64x4 (&out)[3]) {
  constexpr int kOrder = L0 | (L1 << 2) | (L2 << 4) | (L3 << 6);
  for (int k = 0; k < 3; ++k) out[k] = {_mm256_permute4x64_pd(lanes[k].v, kOrder)};
}

// The edge pairs (P's edge from corner I_l to I_l + 1, Q's from J_l to J_l + 1) of lanes l = 0..3.
template <int I0, int I1, int I2, int I3, int J0, int J1, int J2, int J3>
inline F64x4 edge_batch(const CornerLanes& c, Mask4& parallel) {
  F64x4 p0[3], p1[3], q0[3], q1[3], xp[3], xq[3];
  pick<I0, I1, I2, I3>(c.p, p0);
  pick<(I0 + 1) % 3, (I1 + 1) % 3, (I2 + 1) % 3, (I3 + 1) % 3>(c.p, p1);
  pick<J0, J1, J2, J3>(c.q, q0);
  pick<(J0 + 1) % 3, (J1 + 1) % 3, (J2 + 1) % 3, (J3 + 1) % 3>(c.q, q1);
  return tri_segment_segment<F64x4, Mask4>(p0, p1, q0, q1, xp, xq, parallel);
}

// Pairs k = 3 i + j in batches of four: 0-3, 4-7, then 8 (repeated in every lane).
inline F64x4 edge_batch(int b, const CornerLanes& c, Mask4& parallel) {
  if (b == 0) return edge_batch<0, 0, 0, 1, 0, 1, 2, 0>(c, parallel);
  if (b == 1) return edge_batch<1, 1, 2, 2, 1, 2, 0, 1>(c, parallel);
  return edge_batch<2, 2, 2, 2, 2, 2, 2, 2>(c, parallel);
}

}  // namespace

unsigned tri_edge_pairs_avx2(const TriPairInput& in, double (&d2)[kTriCandidates]) {
  alignas(32) double out[12];
  unsigned parallel = 0;
  const CornerLanes c = corner_lanes(in);
  for (int b = 0; b < 3; ++b) {
    Mask4 par;
    _mm256_store_pd(out + 4 * b, edge_batch(b, c, par).v);
    parallel |= static_cast<unsigned>(_mm256_movemask_pd(par.v)) << (4 * b);
  }
  for (int k = 0; k < 9; ++k) d2[k] = out[k];
  return parallel & 0x1ff;
}

bool tri_edge_pairs_within_avx2(const TriPairInput& in, double margin, unsigned& parallel) {
  // max(sqrt(d2), DBL_MIN) <= margin in lanes: vsqrtpd rounds as std::sqrt, and vmaxpd with
  // DBL_MIN first returns the second operand on NaN as std::max does, so each lane decides as
  // disjoint_distance(d2) <= margin.
  const __m256d least = _mm256_set1_pd(std::numeric_limits<double>::min()), bound = _mm256_set1_pd(margin);
  const CornerLanes c = corner_lanes(in);
  parallel = 0;
  for (int b = 0; b < 3; ++b) {
    Mask4 par;
    const __m256d distance = _mm256_max_pd(least, _mm256_sqrt_pd(edge_batch(b, c, par).v));
    if (_mm256_movemask_pd(_mm256_cmp_pd(distance, bound, _CMP_LE_OQ)) != 0) return true;
    parallel |= static_cast<unsigned>(_mm256_movemask_pd(par.v)) << (4 * b);
  }
  parallel &= 0x1ff;
  return false;
}

void tri_vertex_faces_avx2(const TriPairInput& in, double (&d2)[kTriCandidates]) {
  alignas(32) double out[8];
  // Vertices against faces: p[0..2] against Q's, q[0..2] against P's (the fourth lane repeats).
  static constexpr int kV[4] = {0, 1, 2, 2};
  const TriFace<F64x4, Mask4> fq = broadcast(in.face_q), fp = broadcast(in.face_p);
  F64x4 x[3], y[3];
  corners(in.p, kV, x);
  _mm256_store_pd(out, tri_vertex_face<F64x4, Mask4>(x, fq, y).v);
  corners(in.q, kV, x);
  _mm256_store_pd(out + 4, tri_vertex_face<F64x4, Mask4>(x, fp, y).v);
  for (int k = 0; k < 3; ++k) d2[9 + k] = out[k], d2[12 + k] = out[4 + k];
}

}  // namespace tightbvh::query_detail
#endif
