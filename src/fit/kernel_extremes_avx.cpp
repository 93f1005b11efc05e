// The approx-kernel's extreme-point pass (fit.cpp, extreme_point_kernel) in AVX lanes: four
// directions per instruction where the SSE2 loop takes two. Compiled with -mavx -mno-fma
// (src/fit/CMakeLists.txt) and chosen at run time (kernel_extremes.hpp). Every projection is
// (dx qx + dy qy) + dz qz with q = p - center, as in the SSE2 loop, without FMA, and min/max
// and the strict comparisons are exact: the same extremes and the same points bit for bit.
#include "kernel_extremes.hpp"

#ifdef TIGHTBVH_AVX_KERNEL
#include <immintrin.h>

namespace tightbvh::fit_detail {

void kernel_extremes_avx(const double* xyz, std::size_t n, const double (&center)[3], const KernelDirections& d,
                         KernelExtremes& out) {
  constexpr std::size_t kBlock = 8;
  const __m256d inf = _mm256_set1_pd(__builtin_inf()), minus_inf = _mm256_set1_pd(-__builtin_inf());
  for (std::size_t i = 0; i < kKernelLanes; i += 4) {
    _mm256_store_pd(&out.lo[i], inf);
    _mm256_store_pd(&out.hi[i], minus_inf);
    _mm256_store_pd(&out.at_lo[i], _mm256_setzero_pd());
    _mm256_store_pd(&out.at_hi[i], _mm256_setzero_pd());
  }
  const auto projection = [&](std::size_t p, std::size_t i) {
    const double* q = xyz + 3 * p;
    const __m256d qx = _mm256_set1_pd(q[0] - center[0]), qy = _mm256_set1_pd(q[1] - center[1]),
                  qz = _mm256_set1_pd(q[2] - center[2]);
    return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_load_pd(&d.x[i]), qx), _mm256_mul_pd(_mm256_load_pd(&d.y[i]), qy)),
                         _mm256_mul_pd(_mm256_load_pd(&d.z[i]), qz));
  };
  // The first point of [begin, end) whose projection on direction i + j is `value`.
  const auto first_reaching = [&](std::size_t begin, std::size_t end, std::size_t i, std::size_t j, double value) {
    std::size_t p = begin;
    for (; p + 1 < end; ++p) {
      alignas(32) double v[4];
      _mm256_store_pd(v, projection(p, i));
      if (v[j] == value) break;
    }
    return p;
  };
  __m256d qx[kBlock], qy[kBlock], qz[kBlock];
  for (std::size_t b = 0; b < n; b += kBlock) {
    const std::size_t b_end = b + kBlock < n ? b + kBlock : n;
    const std::size_t count = b_end - b;
    for (std::size_t k = 0; k < count; ++k) {
      const double* q = xyz + 3 * (b + k);
      qx[k] = _mm256_set1_pd(q[0] - center[0]), qy[k] = _mm256_set1_pd(q[1] - center[1]), qz[k] = _mm256_set1_pd(q[2] - center[2]);
    }
    for (std::size_t i = 0; i < kKernelLanes; i += 4) {
      const __m256d ax = _mm256_load_pd(&d.x[i]), ay = _mm256_load_pd(&d.y[i]), az = _mm256_load_pd(&d.z[i]);
      __m256d block_lo = inf, block_hi = minus_inf;
      for (std::size_t k = 0; k < count; ++k) {
        const __m256d v = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ax, qx[k]), _mm256_mul_pd(ay, qy[k])), _mm256_mul_pd(az, qz[k]));
        block_lo = _mm256_min_pd(block_lo, v);
        block_hi = _mm256_max_pd(block_hi, v);
      }
      const int below = _mm256_movemask_pd(_mm256_cmp_pd(block_lo, _mm256_load_pd(&out.lo[i]), _CMP_LT_OQ));
      const int above = _mm256_movemask_pd(_mm256_cmp_pd(block_hi, _mm256_load_pd(&out.hi[i]), _CMP_GT_OQ));
      if ((below | above) == 0) continue;
      alignas(32) double block_lo_at[4], block_hi_at[4];
      _mm256_store_pd(block_lo_at, block_lo);
      _mm256_store_pd(block_hi_at, block_hi);
      for (std::size_t j = 0; j < 4; ++j) {
        if (below & (1 << j)) {
          out.lo[i + j] = block_lo_at[j];
          out.at_lo[i + j] = static_cast<double>(first_reaching(b, b_end, i, j, block_lo_at[j]));
        }
        if (above & (1 << j)) {
          out.hi[i + j] = block_hi_at[j];
          out.at_hi[i + j] = static_cast<double>(first_reaching(b, b_end, i, j, block_hi_at[j]));
        }
      }
    }
  }
}

}  // namespace tightbvh::fit_detail
#endif
