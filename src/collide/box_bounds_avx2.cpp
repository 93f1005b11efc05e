// distance()'s box bound and collide()'s box test, four pairs at once in AVX2 lanes of doubles
// (box_bounds4.hpp). Compiled with -mavx2 -mno-fma (src/collide/CMakeLists.txt); everything here
// but the entry points has internal linkage, and nothing from Eigen or the rest of the library is
// compiled here.
#include "box_bounds4.hpp"

#ifdef TIGHTBVH_AVX2_BOUNDS
#include <immintrin.h>

#include "box_lanes.hpp"
#include "lanes_avx2.hpp"

namespace tightbvh::query_detail {
namespace {

inline F64x4 lane_abs(F64x4 x) { return {_mm256_andnot_pd(_mm256_set1_pd(-0.0), x.v)}; }
inline F64x4 lane_max(F64x4 x, F64x4 y) { return {_mm256_max_pd(x.v, y.v)}; }
inline F64x4 lane_sqrt(F64x4 x) { return {_mm256_sqrt_pd(x.v)}; }
inline F64x4 lane_select_le(F64x4 x, F64x4 y, F64x4 p, F64x4 q) {
  return {_mm256_blendv_pd(q.v, p.v, _mm256_cmp_pd(x.v, y.v, _CMP_LE_OQ))};
}
struct Mask4 {
  __m256d v;
};
inline Mask4 operator|(Mask4 x, Mask4 y) { return {_mm256_or_pd(x.v, y.v)}; }
// x > y, false where either is NaN, as SSE2's _mm_cmpgt_pd in collide's two lanes.
inline Mask4 lane_gt(F64x4 x, F64x4 y) { return {_mm256_cmp_pd(x.v, y.v, _CMP_GT_OQ)}; }
inline bool all_lanes(Mask4 m) { return _mm256_movemask_pd(m.v) == 15; }

// The four pairs' values at one offset, widened exactly to double.
inline F64x4 gather(const float* const (&p)[4], int k) { return {_mm256_cvtps_pd(_mm_set_ps(p[3][k], p[2][k], p[1][k], p[0][k]))}; }
inline F64x4 gather(const double* const (&p)[4], int k) { return {_mm256_set_pd(p[3][k], p[2][k], p[1][k], p[0][k])}; }

}  // namespace

template <>
inline F64x4 lane_splat<F64x4>(double x) {
  return {_mm256_set1_pd(x)};
}

void box_distance_bounds4_avx2(const BoundInput (&pairs)[4], double eps, double (&bounds)[4]) {
  const float* const a_center[4] = {pairs[0].a_center, pairs[1].a_center, pairs[2].a_center, pairs[3].a_center};
  const float* const a_axes[4] = {pairs[0].a_axes, pairs[1].a_axes, pairs[2].a_axes, pairs[3].a_axes};
  const float* const a_half[4] = {pairs[0].a_half, pairs[1].a_half, pairs[2].a_half, pairs[3].a_half};
  const double* const b_axes[4] = {pairs[0].b_axes, pairs[1].b_axes, pairs[2].b_axes, pairs[3].b_axes};
  const double* const b_center[4] = {pairs[0].b_center, pairs[1].b_center, pairs[2].b_center, pairs[3].b_center};
  const float* const b_half[4] = {pairs[0].b_half, pairs[1].b_half, pairs[2].b_half, pairs[3].b_half};
  LaneBox<F64x4> a, b;
  for (int i = 0; i < 9; ++i) {  // axis i / 3, component i % 3: column-major storage
    a.axes[i] = gather(a_axes, i);
    b.axes[i] = gather(b_axes, i);
  }
  for (int k = 0; k < 3; ++k) {
    a.center[k] = gather(a_center, k);
    a.half[k] = gather(a_half, k);
    b.center[k] = gather(b_center, k);
    b.half[k] = gather(b_half, k);
  }
  _mm256_storeu_pd(bounds, box_distance_bound<F64x4>(a, b, lane_splat<F64x4>(eps)).v);
}

namespace {

// Two values in four lanes: (x0, x0, x1, x1) with EachTwice, else (x0, x1, x0, x1).
template <bool EachTwice>
inline F64x4 two_in_four(double x0, double x1) {
  const __m256d v = _mm256_castpd128_pd256(_mm_set_pd(x1, x0));
  if constexpr (EachTwice) return {_mm256_permute4x64_pd(v, 0x50)};
  return {_mm256_permute4x64_pd(v, 0x44)};
}

// The four pairs' boxes in lanes: with AMajor, A's lanes (a0, a0, a1, a1) and B's (b0, b1, b0,
// b1); else the other way round. Floats widen exactly to double.
template <bool AMajor>
void load_cross(const CrossInput& in, LaneBox<F64x4>& a, LaneBox<F64x4>& b) {
  for (int i = 0; i < 9; ++i) {
    a.axes[i] = two_in_four<AMajor>(in.a_axes[0][i], in.a_axes[1][i]);
    b.axes[i] = two_in_four<!AMajor>(in.b_axes[0][i], in.b_axes[1][i]);
  }
  for (int k = 0; k < 3; ++k) {
    a.center[k] = two_in_four<AMajor>(in.a_center[0][k], in.a_center[1][k]);
    a.half[k] = two_in_four<AMajor>(in.a_half[0][k], in.a_half[1][k]);
    b.center[k] = two_in_four<!AMajor>(in.b_center[0][k], in.b_center[1][k]);
    b.half[k] = two_in_four<!AMajor>(in.b_half[0][k], in.b_half[1][k]);
  }
}

template <bool AMajor>
int separated_cross(const CrossInput& in, double margin, double eps) {
  LaneBox<F64x4> a, b;
  load_cross<AMajor>(in, a, b);
  return _mm256_movemask_pd(box_separated<F64x4, Mask4>(a, b, lane_splat<F64x4>(margin), lane_splat<F64x4>(eps)).v);
}

template <bool AMajor>
void bounds_cross(const CrossInput& in, double eps, double (&bounds)[4]) {
  LaneBox<F64x4> a, b;
  load_cross<AMajor>(in, a, b);
  _mm256_storeu_pd(bounds, box_distance_bound<F64x4>(a, b, lane_splat<F64x4>(eps)).v);
}

}  // namespace

int boxes_separated_cross_avx2(const CrossInput& boxes, bool a_major, double margin, double eps) {
  return a_major ? separated_cross<true>(boxes, margin, eps) : separated_cross<false>(boxes, margin, eps);
}

void box_distance_bounds_cross_avx2(const CrossInput& boxes, bool a_major, double eps, double (&bounds)[4]) {
  if (a_major)
    bounds_cross<true>(boxes, eps, bounds);
  else
    bounds_cross<false>(boxes, eps, bounds);
}

}  // namespace tightbvh::query_detail
#endif  // TIGHTBVH_AVX2_BOUNDS
