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
  // Per direction, the start of the first block that reached its extreme (strict comparisons: a
  // later block that only ties keeps it), kept by blends: whether a block improves an extreme is a
  // coin toss early on, and as branches (with the search for the point inside the block at every
  // improvement) they would be 11% of an auto build's mispredictions (cachegrind --branch-sim, knot1).
  alignas(32) double lo_block[kKernelLanes] = {}, hi_block[kKernelLanes] = {};
  __m256d qx[kBlock], qy[kBlock], qz[kBlock];
  for (std::size_t b = 0; b < n; b += kBlock) {
    const std::size_t b_end = b + kBlock < n ? b + kBlock : n;
    const std::size_t count = b_end - b;
    for (std::size_t k = 0; k < count; ++k) {
      const double* q = xyz + 3 * (b + k);
      qx[k] = _mm256_set1_pd(q[0] - center[0]), qy[k] = _mm256_set1_pd(q[1] - center[1]), qz[k] = _mm256_set1_pd(q[2] - center[2]);
    }
    const __m256d block_start = _mm256_set1_pd(static_cast<double>(b));
    for (std::size_t i = 0; i < kKernelLanes; i += 4) {
      const __m256d ax = _mm256_load_pd(&d.x[i]), ay = _mm256_load_pd(&d.y[i]), az = _mm256_load_pd(&d.z[i]);
      __m256d block_lo = inf, block_hi = minus_inf;
      for (std::size_t k = 0; k < count; ++k) {
        const __m256d v = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ax, qx[k]), _mm256_mul_pd(ay, qy[k])), _mm256_mul_pd(az, qz[k]));
        block_lo = _mm256_min_pd(block_lo, v);
        block_hi = _mm256_max_pd(block_hi, v);
      }
      const __m256d lo = _mm256_load_pd(&out.lo[i]), hi = _mm256_load_pd(&out.hi[i]);
      const __m256d below = _mm256_cmp_pd(block_lo, lo, _CMP_LT_OQ), above = _mm256_cmp_pd(block_hi, hi, _CMP_GT_OQ);
      _mm256_store_pd(&out.lo[i], _mm256_blendv_pd(lo, block_lo, below));
      _mm256_store_pd(&out.hi[i], _mm256_blendv_pd(hi, block_hi, above));
      _mm256_store_pd(&lo_block[i], _mm256_blendv_pd(_mm256_load_pd(&lo_block[i]), block_start, below));
      _mm256_store_pd(&hi_block[i], _mm256_blendv_pd(_mm256_load_pd(&hi_block[i]), block_start, above));
    }
  }
  // The first point of the recorded block whose projection is the extreme: computed again the way
  // the lanes computed it ((dx qx + dy qy) + dz qz, no FMA), so the same value. Directions whose
  // extreme never moved (only non-finite projections) keep point 0.
  const auto first_reaching = [&](std::size_t lane, double block, double value) {
    const std::size_t begin = static_cast<std::size_t>(block), end = begin + kBlock < n ? begin + kBlock : n;
    std::size_t p = begin;
    for (; p + 1 < end; ++p) {
      const double* q = xyz + 3 * p;
      const double qx = q[0] - center[0], qy = q[1] - center[1], qz = q[2] - center[2];
      const double v = (d.x[lane] * qx + d.y[lane] * qy) + d.z[lane] * qz;
      if (v == value) break;
    }
    return static_cast<double>(p);
  };
  for (std::size_t i = 0; i < kKernelLanes; ++i) {
    if (out.lo[i] < __builtin_inf()) out.at_lo[i] = first_reaching(i, lo_block[i], out.lo[i]);
    if (out.hi[i] > -__builtin_inf()) out.at_hi[i] = first_reaching(i, hi_block[i], out.hi[i]);
  }
}

}  // namespace tightbvh::fit_detail
#endif
