#pragma once
// Internal: tri_tri_distance() without its touching test, for callers that already know the
// triangles do not touch (distance()'s search: its touching phase has tested every pair whose
// boxes overlap, so no pair it reaches touches). For triangles that do not touch
// (tri_tri_overlap() false) it equals tri_tri_distance() bit for bit; for touching triangles
// its answer is meaningless (not 0). tests/collide/tri_distance_test.cpp checks the equality.
#include "tightbvh/tri_distance.hpp"

namespace tightbvh::query_detail {

[[nodiscard]] TriangleDistance tri_tri_distance_disjoint(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                                         const Vec3& q0, const Vec3& q1, const Vec3& q2);

// The same with the path chosen: `avx2` false forces the scalar kernel (tests compare the two
// paths bit for bit); true uses the AVX2 lanes where the CPU has them.
[[nodiscard]] TriangleDistance tri_tri_distance_disjoint_path(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                                              const Vec3& q0, const Vec3& q1, const Vec3& q2,
                                                              bool avx2);

// tri_tri_within() without its touching test, on the chosen path: for triangles that do not
// touch it is tri_tri_distance(...).distance <= margin, exactly, on either path.
[[nodiscard]] bool tri_tri_within_disjoint_path(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                                const Vec3& q0, const Vec3& q1, const Vec3& q2, double margin,
                                                bool avx2);

}  // namespace tightbvh::query_detail
