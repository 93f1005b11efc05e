#pragma once
// Internal: the approx-kernel's extreme-point pass over AVX lanes (kernel_extremes_avx.cpp), for
// extreme_point_kernel in fit.cpp, which keeps the SSE2 loop for CPUs without AVX. Both give the
// same extremes and points bit for bit (the same operations in the same order, no FMA).
#include <cstddef>

#if defined(__x86_64__) && defined(__GNUC__)
#define TIGHTBVH_AVX_KERNEL 1
#endif

namespace tightbvh::fit_detail {

// The 49 kernel directions padded with zero vectors to a multiple of four lanes.
constexpr std::size_t kKernelLanes = 52;

struct KernelDirections {
  alignas(32) double x[kKernelLanes];
  alignas(32) double y[kKernelLanes];
  alignas(32) double z[kKernelLanes];
};

// Per direction the least and greatest projection and the first point reaching each (its index
// as a double).
struct KernelExtremes {
  alignas(32) double lo[kKernelLanes];
  alignas(32) double hi[kKernelLanes];
  alignas(32) double at_lo[kKernelLanes];
  alignas(32) double at_hi[kKernelLanes];
};

// xyz: n >= 1 points, x, y, z consecutive. Projections of p - center. SSE2 where the compiler
// targets it (x86-64), else a scalar loop; the same results as kernel_extremes_avx.
void kernel_extremes_sse2(const double* xyz, std::size_t n, const double (&center)[3], const KernelDirections& d,
                          KernelExtremes& out);

#ifdef TIGHTBVH_AVX_KERNEL
// xyz: n >= 1 points, x, y, z consecutive. Projections of p - center.
void kernel_extremes_avx(const double* xyz, std::size_t n, const double (&center)[3], const KernelDirections& d,
                         KernelExtremes& out);
[[nodiscard]] inline bool has_avx_kernel() { return __builtin_cpu_supports("avx"); }
#else
[[nodiscard]] inline bool has_avx_kernel() { return false; }
inline void kernel_extremes_avx(const double* xyz, std::size_t n, const double (&center)[3], const KernelDirections& d,
                                KernelExtremes& out) {
  kernel_extremes_sse2(xyz, n, center, d, out);
}
#endif

}  // namespace tightbvh::fit_detail
