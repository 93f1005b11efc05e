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
inline F8 lane_abs(F8 x) { return {_mm256_andnot_ps(_mm256_set1_ps(-0.0f), x.v)}; }
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

// B's children of both calls: lanes 0-3 from b0, 4-7 from b1; then the kernel.
[[gnu::always_inline]] inline unsigned kept_lanes(WideLanes<F8>& l, const WideNode& b0, const WideNode& b1) {
  for (int r = 0; r < 9; ++r) l.bx[r] = load_halves(b0.axes[r], b1.axes[r]);
  for (int k = 0; k < 3; ++k) {
    l.cb[k] = load_halves(b0.center[k], b1.center[k]);
    l.eb[k] = load_halves(b0.half[k], b1.half[k]);
  }
  l.center_factor = {_mm256_set1_ps(16.0f * kUnitRoundoff)};
  const M8 sep = wide_separated<WideTier::full, F8, M8>(l);
  return ~static_cast<unsigned>(_mm256_movemask_ps(sep.v)) & 0xFFu;
}

}  // namespace

unsigned wide_overlap2_avx2(const WideHoisted& h0, const WideNode& b0, const WideHoisted& h1, const WideNode& b1) {
  WideLanes<F8> l;
  for (int r = 0; r < 9; ++r) l.m[r] = splat_halves(h0.m[r], h1.m[r]);
  for (int k = 0; k < 3; ++k) {
    l.tn[k] = splat_halves(h0.tn[k], h1.tn[k]);
    l.ea[k] = splat_halves(h0.ea[k], h1.ea[k]);
  }
  l.kappa = splat_halves(h0.kappa, h1.kappa);
  l.base = splat_halves(h0.base, h1.base);
  return kept_lanes(l, b0, b1);
}

unsigned wide_overlap2_avx2(const WideBoxView& a0, const WideNode& b0, const WideBoxView& a1, const WideNode& b1) {
  WideLanes<F8> l;
  for (int r = 0; r < 9; ++r) l.m[r] = splat_halves(a0.node->m[r][a0.lane], a1.node->m[r][a1.lane]);
  for (int k = 0; k < 3; ++k) {
    l.tn[k] = splat_halves(a0.tn[k], a1.tn[k]);
    l.ea[k] = splat_halves(a0.node->ea[k][a0.lane], a1.node->ea[k][a1.lane]);
  }
  l.kappa = splat_halves(a0.node->kappa, a1.node->kappa);
  l.base = splat_halves(a0.base, a1.base);
  return kept_lanes(l, b0, b1);
}

}  // namespace tightbvh::query_detail
#endif
