#pragma once
// Internal: the triangle-triangle test of four pairs at once in AVX2 lanes of doubles, for
// all_pairs queries, which test every leaf pair and never stop at a hit (collide.cpp buffers
// their leaf pairs). Each lane runs Guigue & Devillers' test (tri_tri.cpp) on the static filter
// of its orientation determinants alone, the same bound as OrientPlane::filter
// (predicates.hpp): a sign the filter decides is the exact sign, so a lane that every sign it
// needs decides answers as the exact tri_tri_overlap() does. A lane whose filter cannot decide a
// sign (a corner within rounding of the other triangle's plane: touching, coplanar or degenerate
// pairs, NaN) is left undecided and the caller runs tri_tri_overlap() on it. Compiled with
// -mavx2 (tri_tri_avx2.cpp, x86-64 with GCC or Clang); callers check avx2_bounds_available().
#include "box_bounds4.hpp"

namespace tightbvh::query_detail {

// The lanes' filter bound: predicates.hpp's kOrient3dBound (16 u, u = 2^-53), the relative bound
// of OrientPlane::filter (restated here, as this header is compiled without Eigen; tri_batch.hpp
// checks that the two agree).
inline constexpr double kTriLanesFilterBound = 16.0 * 1.1102230246251565e-16;

// Four pairs, structure of arrays: c[3 * k + i][lane] is coordinate i of corner k, corners
// p0, p1, p2 (A's triangle) then q0, q1, q2 (B's, in A's frame).
struct TriPairs4 {
  alignas(32) double c[18][4];
};

// Defined where TIGHTBVH_AVX2_BOUNDS is (box_bounds4.hpp). Bit l (l < 4): lane l decided.
// Bit 4 + l: lane l's triangles touch (only where decided).
[[nodiscard]] int tri_tri_overlap4_avx2(const TriPairs4& pairs);

}  // namespace tightbvh::query_detail
