// projected_range in AVX lanes (projected_range.hpp): the three projections of a point in one
// vector (lane j = direction j, lane 3 unused), four points in flight so that the min/max chains
// do not wait on each other. Compiled with -mavx -mno-fma (src/fit/CMakeLists.txt); includes
// nothing but intrinsics, so no inline function of the library is compiled here for AVX.
#include "projected_range.hpp"

#ifdef TIGHTBVH_AVX_RANGE
#include <immintrin.h>

namespace tightbvh::fit_detail {

void projected_range_avx(const double* xyz, std::size_t n, const double (&a)[3][4], double (&lo)[3],
                         double (&hi)[3]) {
  const __m256d r0 = _mm256_loadu_pd(a[0]), r1 = _mm256_loadu_pd(a[1]), r2 = _mm256_loadu_pd(a[2]);
  // (x a0 + y a1) + z a2, as the scalar loop.
  const auto project = [&](const double* p) {
    const __m256d xy = _mm256_add_pd(_mm256_mul_pd(_mm256_broadcast_sd(p), r0),
                                     _mm256_mul_pd(_mm256_broadcast_sd(p + 1), r1));
    return _mm256_add_pd(xy, _mm256_mul_pd(_mm256_broadcast_sd(p + 2), r2));
  };
  // min_pd(q, lo) is q < lo ? q : lo, which is std::min(lo, q) (a NaN q keeps lo); max alike.
  const __m256d inf = _mm256_set1_pd(__builtin_inf());
  __m256d lo4[4] = {inf, inf, inf, inf};
  const __m256d minus_inf = _mm256_set1_pd(-__builtin_inf());
  __m256d hi4[4] = {minus_inf, minus_inf, minus_inf, minus_inf};
  std::size_t k = 0;
  for (; k + 4 <= n; k += 4)
    for (int u = 0; u < 4; ++u) {
      const __m256d q = project(xyz + 3 * (k + u));
      lo4[u] = _mm256_min_pd(q, lo4[u]);
      hi4[u] = _mm256_max_pd(q, hi4[u]);
    }
  for (; k < n; ++k) {
    const __m256d q = project(xyz + 3 * k);
    lo4[0] = _mm256_min_pd(q, lo4[0]);
    hi4[0] = _mm256_max_pd(q, hi4[0]);
  }
  // min and max are exact: combining the four chains in any order gives the scalar loop's result.
  const __m256d l = _mm256_min_pd(_mm256_min_pd(lo4[0], lo4[1]), _mm256_min_pd(lo4[2], lo4[3]));
  const __m256d h = _mm256_max_pd(_mm256_max_pd(hi4[0], hi4[1]), _mm256_max_pd(hi4[2], hi4[3]));
  alignas(32) double lo_out[4], hi_out[4];
  _mm256_store_pd(lo_out, l);
  _mm256_store_pd(hi_out, h);
  for (int j = 0; j < 3; ++j) lo[j] = lo_out[j], hi[j] = hi_out[j];
}

}  // namespace tightbvh::fit_detail
#endif
