// grid_order.hpp's AVX loops (the ordering pass of grid_search's scan). Compiled with -mavx
// -mno-fma -ffp-contract=off (src/fit/CMakeLists.txt); includes nothing but intrinsics, so no
// inline function of the library is compiled here for AVX.
#include "grid_order.hpp"

#ifdef TIGHTBVH_AVX_GRID_ORDER
#include <immintrin.h>

namespace tightbvh::fit_detail {

void projection_ranges_avx(const double* xyz, std::size_t n, const double* dx, const double* dy, const double* dz,
                           double* lo, double* hi, std::size_t lanes) {
  for (std::size_t i = 0; i < lanes; i += 4) {
    const __m256d ax = _mm256_loadu_pd(dx + i), ay = _mm256_loadu_pd(dy + i), az = _mm256_loadu_pd(dz + i);
    __m256d l = _mm256_set1_pd(__builtin_inf()), h = _mm256_set1_pd(-__builtin_inf());
    for (std::size_t k = 0; k < n; ++k) {
      const double* p = xyz + 3 * k;
      const __m256d d = _mm256_add_pd(
          _mm256_add_pd(_mm256_mul_pd(ax, _mm256_broadcast_sd(p)), _mm256_mul_pd(ay, _mm256_broadcast_sd(p + 1))),
          _mm256_mul_pd(az, _mm256_broadcast_sd(p + 2)));
      l = _mm256_min_pd(l, d);
      h = _mm256_max_pd(h, d);
    }
    _mm256_storeu_pd(lo + i, l);
    _mm256_storeu_pd(hi + i, h);
  }
}

void cheap_bounds_avx(const double* normals, int count, const double* dx, const double* dy, const double* dz,
                      const double* lo, const double* hi, double* out, std::size_t lanes) {
  const __m256d sign = _mm256_set1_pd(-0.0);
  for (std::size_t i = 0; i < lanes; i += 4) {
    const __m256d ax = _mm256_loadu_pd(dx + i), ay = _mm256_loadu_pd(dy + i), az = _mm256_loadu_pd(dz + i);
    __m256d projected = _mm256_setzero_pd();
    for (int t = 0; t < count; ++t) {
      const double* m = normals + 3 * t;
      const __m256d d = _mm256_add_pd(
          _mm256_add_pd(_mm256_mul_pd(ax, _mm256_broadcast_sd(m)), _mm256_mul_pd(ay, _mm256_broadcast_sd(m + 1))),
          _mm256_mul_pd(az, _mm256_broadcast_sd(m + 2)));
      projected = _mm256_max_pd(projected, _mm256_andnot_pd(sign, d));
    }
    const __m256d norm2 =
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ax, ax), _mm256_mul_pd(ay, ay)), _mm256_mul_pd(az, az));
    const __m256d width = _mm256_sub_pd(_mm256_loadu_pd(hi + i), _mm256_loadu_pd(lo + i));
    _mm256_storeu_pd(out + i, _mm256_div_pd(_mm256_mul_pd(width, projected), norm2));
  }
}

}  // namespace tightbvh::fit_detail
#endif
