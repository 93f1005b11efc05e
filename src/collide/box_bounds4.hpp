#pragma once
// Internal: the box kernels for four pairs at once in AVX2 lanes (box_bounds_avx2.cpp, compiled
// with -mavx2 on x86-64 only; callers check avx2_bounds_available() at run time, so the library
// still runs on any x86-64): distance()'s box bound and collide()'s box test. Each lane is the
// one-pair kernel's arithmetic (box_lanes.hpp), operation for operation and without FMA, so each
// lane equals the one-pair bound, or decides as the one-pair test, bit for bit. The boxes come as
// plain arrays: that file includes no Eigen (box_lanes.hpp says why).

// x86-64 with GCC or Clang: src/collide/CMakeLists.txt compiles box_bounds_avx2.cpp for AVX2 there.
#if defined(__x86_64__) && defined(__GNUC__)
#define TIGHTBVH_AVX2_BOUNDS 1
#endif

namespace tightbvh::query_detail {

// One pair: A's box as stored (float center, axes column-major, half extents) and B's box mapped
// into A's frame (double axes column-major and center) with B's float half extents.
struct BoundInput {
  const float* a_center;
  const float* a_axes;
  const float* a_half;
  const double* b_axes;
  const double* b_center;
  const float* b_half;
};

// The four child pairs of a split of both nodes: A's children's boxes a[0], a[1] (as stored)
// against B's children's boxes b[0], b[1] (mapped into A's frame, B's half extents), pair k in
// traverse.hpp's both_children order: `a_major` (a0 b0, a0 b1, a1 b0, a1 b1) or not (a0 b0,
// a1 b0, a0 b1, a1 b1). Each side has two distinct boxes, so the lanes load two and repeat them.
struct CrossInput {
  const float* a_center[2];
  const float* a_axes[2];
  const float* a_half[2];
  const double* b_axes[2];
  const double* b_center[2];
  const float* b_half[2];
};

// Defined where TIGHTBVH_AVX2_BOUNDS is: box_distance_bound over four pairs, each lane loaded from
// its own pointers (any four pairs).
void box_distance_bounds4_avx2(const BoundInput (&pairs)[4], double eps, double (&bounds)[4]);
// Defined there too. box_separated over those four lanes: bit k set when pair
// k's boxes are separated by more than `margin` (obb_overlap()'s negation with kSatEpsilon = eps).
[[nodiscard]] int boxes_separated_cross_avx2(const CrossInput& boxes, bool a_major, double margin, double eps);
// box_distance_bound over those four lanes (distance()'s bound with kSatEpsilon = eps).
void box_distance_bounds_cross_avx2(const CrossInput& boxes, bool a_major, double eps, double (&bounds)[4]);

// Whether the functions above exist and this CPU can run them.
[[nodiscard]] inline bool avx2_bounds_available() {
#ifdef TIGHTBVH_AVX2_BOUNDS
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

}  // namespace tightbvh::query_detail
