// The wide kernel (wide_kernel.hpp) in eight AVX2 lanes of floats: two boxes of A, each against
// the four children of a node of B. Compiled with -mavx2 -mno-fma (src/collide/CMakeLists.txt);
// everything here but the entry point has internal linkage, and nothing from Eigen or the rest of
// the library is compiled here. Each lane's operations are the four-lane kernel's, in the same
// order and without FMA, so the masks equal wide_overlap's bit for bit.
#include "wide_kernel.hpp"

#ifdef TIGHTBVH_WIDE_AVX2
#include <immintrin.h>

namespace tightbvh::query_detail {
namespace {

struct F8 {
  __m256 v;
};
inline F8 operator+(F8 x, F8 y) { return {_mm256_add_ps(x.v, y.v)}; }
inline F8 operator-(F8 x, F8 y) { return {_mm256_sub_ps(x.v, y.v)}; }
inline F8 operator*(F8 x, F8 y) { return {_mm256_mul_ps(x.v, y.v)}; }
inline F8 operator/(F8 x, F8 y) { return {_mm256_div_ps(x.v, y.v)}; }
inline F8 lane_abs(F8 x) { return {_mm256_andnot_ps(_mm256_set1_ps(-0.0f), x.v)}; }
inline F8 lane_max(F8 x, F8 y) { return {_mm256_max_ps(x.v, y.v)}; }
inline F8 lane_sqrt(F8 x) { return {_mm256_sqrt_ps(x.v)}; }
inline F8 splat8(float x) { return {_mm256_set1_ps(x)}; }
struct M8 {
  __m256 v;
};
inline M8 operator|(M8 x, M8 y) { return {_mm256_or_ps(x.v, y.v)}; }
// x > y, false where either is NaN, as SSE's _mm_cmpgt_ps in the four-lane kernel.
inline M8 lane_gt(F8 x, F8 y) { return {_mm256_cmp_ps(x.v, y.v, _CMP_GT_OQ)}; }
inline bool all_lanes(M8 m) { return _mm256_movemask_ps(m.v) == 0xFF; }

// Lanes 0-3 from p0 (four floats), 4-7 from p1.
inline F8 load_halves(const float* p0, const float* p1) {
  return {_mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(p0)), _mm_load_ps(p1), 1)};
}
// Lanes 0-3 x0, 4-7 x1.
inline F8 splat_halves(float x0, float x1) {
  return {_mm256_insertf128_ps(_mm256_castps128_ps256(_mm_set1_ps(x0)), _mm_set1_ps(x1), 1)};
}

// A's side of both calls: lanes 0-3 h0's box, 4-7 h1's (WideHoisted, or a box of a node hoisted
// in lanes: WideBoxView).
[[gnu::always_inline]] inline void a_sides(WideLanes<F8>& l, const WideHoisted& h0, const WideHoisted& h1) {
  for (int r = 0; r < 9; ++r) l.m[r] = splat_halves(h0.m[r], h1.m[r]);
  for (int k = 0; k < 3; ++k) {
    l.tn[k] = splat_halves(h0.tn[k], h1.tn[k]);
    l.ea[k] = splat_halves(h0.ea[k], h1.ea[k]);
  }
  l.kappa = splat_halves(h0.kappa, h1.kappa);
  l.base = splat_halves(h0.base, h1.base);
}
[[gnu::always_inline]] inline void a_sides(WideLanes<F8>& l, const WideBoxView& a0, const WideBoxView& a1) {
  for (int r = 0; r < 9; ++r) l.m[r] = splat_halves(a0.node->m[r][a0.lane], a1.node->m[r][a1.lane]);
  for (int k = 0; k < 3; ++k) {
    l.tn[k] = splat_halves(a0.tn[k], a1.tn[k]);
    l.ea[k] = splat_halves(a0.node->ea[k][a0.lane], a1.node->ea[k][a1.lane]);
  }
  l.kappa = splat_halves(a0.node->kappa, a1.node->kappa);
  l.base = splat_halves(a0.base, a1.base);
}
// B's children of both calls: lanes 0-3 from b0, 4-7 from b1.
[[gnu::always_inline]] inline void b_sides(WideLanes<F8>& l, const WideNode& b0, const WideNode& b1) {
  for (int r = 0; r < 9; ++r) l.bx[r] = load_halves(b0.axes[r], b1.axes[r]);
  for (int k = 0; k < 3; ++k) {
    l.cb[k] = load_halves(b0.center[k], b1.center[k]);
    l.eb[k] = load_halves(b0.half[k], b1.half[k]);
  }
  l.center_factor = splat8(16.0f * kUnitRoundoff);
}

template <class H>
[[gnu::always_inline]] inline unsigned overlap2(const H& h0, const WideNode& b0, const H& h1, const WideNode& b1) {
  WideLanes<F8> l;
  a_sides(l, h0, h1);
  b_sides(l, b0, b1);
  const M8 sep = wide_separated<WideTier::full, F8, M8>(l);
  return ~static_cast<unsigned>(_mm256_movemask_ps(sep.v)) & 0xFFu;
}

template <class H>
[[gnu::always_inline]] inline void distance_bounds2(const H& h0, const WideNode& b0, const H& h1, const WideNode& b1,
                                                    float len_sq, float factor, float (&bounds)[2 * kWideLanes]) {
  WideLanes<F8> l;
  a_sides(l, h0, h1);
  b_sides(l, b0, b1);
  const F8 bound = wide_bound(l, splat8(len_sq), splat8(16.0f * kUnitRoundoff), splat8(1.0f - 4.0f * kUnitRoundoff),
                              splat8(0.0f));
  _mm256_storeu_ps(bounds, (bound * splat8(factor)).v);
}

}  // namespace

unsigned wide_overlap2_permuted_avx2(const WideHoisted& h0, const WideNode& b0, const WideHoisted& h1,
                                     const WideNode& b1, const WidePermutation& a) {
  WideLanes<F8> l;
  a_sides(l, h0, h1);
  b_sides(l, b0, b1);
  const F8 signs[3] = {splat8(a.s[0]), splat8(a.s[1]), splat8(a.s[2])};
  const M8 sep = wide_separated_given<WideTier::full, F8, M8>(l, wide_relative_permuted(l, a, signs));
  return ~static_cast<unsigned>(_mm256_movemask_ps(sep.v)) & 0xFFu;
}

unsigned wide_overlap2_avx2(const WideHoisted& h0, const WideNode& b0, const WideHoisted& h1, const WideNode& b1) {
  return overlap2(h0, b0, h1, b1);
}

unsigned wide_overlap2_avx2(const WideBoxView& a0, const WideNode& b0, const WideBoxView& a1, const WideNode& b1) {
  return overlap2(a0, b0, a1, b1);
}

void wide_distance_bounds2_avx2(const WideHoisted& h0, const WideNode& b0, const WideHoisted& h1, const WideNode& b1,
                                float len_sq, float factor, float (&bounds)[2 * kWideLanes]) {
  distance_bounds2(h0, b0, h1, b1, len_sq, factor, bounds);
}

void wide_distance_bounds2_avx2(const WideBoxView& a0, const WideNode& b0, const WideBoxView& a1, const WideNode& b1,
                                float len_sq, float factor, float (&bounds)[2 * kWideLanes]) {
  distance_bounds2(a0, b0, a1, b1, len_sq, factor, bounds);
}

}  // namespace tightbvh::query_detail
#endif
