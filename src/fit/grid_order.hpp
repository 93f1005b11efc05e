#pragma once
// Internal: the ordering pass of grid_search's scan (grid_search.cpp, scan_grid) over AVX lanes:
// per grid direction the range of the points' projections, then VolumeBound's cheap bound. Four
// directions per instruction where the SSE2 loops of grid_search.cpp take two; compiled with -mavx
// -mno-fma (grid_order_avx.cpp, src/fit/CMakeLists.txt) and chosen at run time, so the library
// still runs on any x86-64. The same operations in the same order as the SSE2 loops, without FMA,
// and min/max are exact: the same ranges and bounds bit for bit, hence the same scan.
#include <cstddef>

#if defined(__x86_64__) && defined(__GNUC__)
#define TIGHTBVH_AVX_GRID_ORDER 1
#endif

namespace tightbvh::fit_detail {

// Per direction i < lanes (lanes a multiple of 4): lo[i] / hi[i] = min /
// max over the n >= 1 points (x, y, z consecutive) of (dx[i] x + dy[i] y) + dz[i] z.
void projection_ranges_avx(const double* xyz, std::size_t n, const double* dx, const double* dy, const double* dz,
                           double* lo, double* hi, std::size_t lanes);
// out[i] = ((hi[i] - lo[i]) * max_t |(dx[i] nx_t + dy[i] ny_t) + dz[i] nz_t|) / ((dx[i]^2 + dy[i]^2) + dz[i]^2)
// over the `count` vectors n_t (x, y, z consecutive): VolumeBound::cheap_lanes.
void cheap_bounds_avx(const double* normals, int count, const double* dx, const double* dy, const double* dz,
                      const double* lo, const double* hi, double* out, std::size_t lanes);

[[nodiscard]] inline bool has_avx_grid_order() {
#ifdef TIGHTBVH_AVX_GRID_ORDER
  return __builtin_cpu_supports("avx");
#else
  return false;
#endif
}

}  // namespace tightbvh::fit_detail
