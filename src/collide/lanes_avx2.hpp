#pragma once
// Internal: four doubles in one AVX2 register with the arithmetic operators, so that a lane
// template (box_lanes.hpp, tri_lanes.hpp) reads as its scalar instantiation does. Included only by
// the files compiled with -mavx2 (box_bounds_avx2.cpp, tri_distance_avx2.cpp); internal linkage,
// so nothing compiled for AVX2 can stand in for another file's code.
#include <immintrin.h>

namespace tightbvh::query_detail {
namespace {

struct F64x4 {
  __m256d v;
};
inline F64x4 operator+(F64x4 x, F64x4 y) { return {_mm256_add_pd(x.v, y.v)}; }
inline F64x4 operator-(F64x4 x, F64x4 y) { return {_mm256_sub_pd(x.v, y.v)}; }
inline F64x4 operator*(F64x4 x, F64x4 y) { return {_mm256_mul_pd(x.v, y.v)}; }
inline F64x4 operator/(F64x4 x, F64x4 y) { return {_mm256_div_pd(x.v, y.v)}; }

}  // namespace
}  // namespace tightbvh::query_detail
