// min_area_rect_of_points' pair search in AVX lanes (min_rect.cpp): four pair directions per
// instruction where the SSE2 loop takes two. Compiled with -mavx -mno-fma -ffp-contract=off
// (src/geometry/CMakeLists.txt) and chosen at run time; the same products, sums, spans and areas
// as the SSE2 and scalar loops, so the same areas bit for bit. Includes nothing but intrinsics.
#include <cstddef>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

namespace tightbvh::detail {

// area[q] for the `pairs` directions (ex[q], ey[q]) (arrays padded to a multiple of 4) over the n
// points (px[k], py[k]): ((max - min of e . p) * (max - min of v . p)) / |e|^2, v = (-ey, ex).
void pair_areas_avx(const double* px, const double* py, std::size_t n, const double* ex, const double* ey,
                    std::size_t pairs, double* area) {
  const __m256d sign = _mm256_set1_pd(-0.0);
  for (std::size_t q = 0; q < pairs; q += 4) {
    const __m256d x = _mm256_loadu_pd(ex + q), y = _mm256_loadu_pd(ey + q);
    const __m256d my = _mm256_xor_pd(y, sign);
    const auto along = [&](std::size_t k) {
      return _mm256_add_pd(_mm256_mul_pd(x, _mm256_broadcast_sd(px + k)), _mm256_mul_pd(y, _mm256_broadcast_sd(py + k)));
    };
    const auto across = [&](std::size_t k) {
      return _mm256_add_pd(_mm256_mul_pd(my, _mm256_broadcast_sd(px + k)), _mm256_mul_pd(x, _mm256_broadcast_sd(py + k)));
    };
    __m256d u_lo = along(0), u_hi = u_lo, v_lo = across(0), v_hi = v_lo;
    for (std::size_t k = 1; k < n; ++k) {
      const __m256d a = along(k), b = across(k);
      u_lo = _mm256_min_pd(a, u_lo), u_hi = _mm256_max_pd(a, u_hi);
      v_lo = _mm256_min_pd(b, v_lo), v_hi = _mm256_max_pd(b, v_hi);
    }
    const __m256d len2 = _mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(y, y));
    _mm256_storeu_pd(area + q, _mm256_div_pd(_mm256_mul_pd(_mm256_sub_pd(u_hi, u_lo), _mm256_sub_pd(v_hi, v_lo)), len2));
  }
}

}  // namespace tightbvh::detail
#endif
