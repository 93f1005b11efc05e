#pragma once
// Internal: the range of a point set along three directions, the one pass over a node's corners
// that a refit (and compact_box_with_axes) makes at every node. Four lanes at once where the CPU
// has AVX (projected_range_avx.cpp, compiled with -mavx -mno-fma on x86-64 with GCC or Clang
// only; chosen at run time, so the library still runs on any x86-64), else the scalar loop. Both
// compute every projection as (x a0j + y a1j) + z a2j, without FMA, and min/max are exact, so the
// two paths give the same range bit for bit.
#include <cstddef>

#if defined(__x86_64__) && defined(__GNUC__)
#define TIGHTBVH_AVX_RANGE 1
#endif

namespace tightbvh::fit_detail {

// lo[j] / hi[j] = min / max over the n points (x, y, z consecutive, 3n doubles) of
// (x a[0][j] + y a[1][j]) + z a[2][j]; a[i] is row i of the axes matrix (the columns are the
// directions), a[i][3] unused. n >= 1. A NaN projection is skipped, as std::min/std::max do.
void projected_range_scalar(const double* xyz, std::size_t n, const double (&a)[3][4], double (&lo)[3],
                            double (&hi)[3]);
#ifdef TIGHTBVH_AVX_RANGE
void projected_range_avx(const double* xyz, std::size_t n, const double (&a)[3][4], double (&lo)[3],
                         double (&hi)[3]);
#endif

// The AVX path where this CPU has it, else the scalar one.
inline void projected_range(const double* xyz, std::size_t n, const double (&a)[3][4], double (&lo)[3],
                            double (&hi)[3]) {
#ifdef TIGHTBVH_AVX_RANGE
  if (__builtin_cpu_supports("avx")) return projected_range_avx(xyz, n, a, lo, hi);
#endif
  projected_range_scalar(xyz, n, a, lo, hi);
}

}  // namespace tightbvh::fit_detail
