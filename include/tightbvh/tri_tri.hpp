#pragma once
// Triangle-triangle overlap test for closed triangles (Guigue & Devillers 2003, "Fast and
// robust triangle-triangle overlap test using orientation predicates", J. Graphics Tools 8(1)).
//
// "Touching" (the definition used by every query in tightbvh, brute force included): a triangle
// is the closed set of its points (interior + edges + vertices), and two triangles touch iff the
// two closed sets share at least one point. Shared vertices, shared edges, a vertex on the other
// triangle's face or edge, and coplanar overlap all count as contact.
//
// Degenerate triangles (zero area: (b - a) x (c - a) == 0 exactly, the same criterion as
// tightbvh::validate) are the closed point sets they are: a segment (between the two corners
// farthest apart) or a single point, tested as segment/point against the other primitive.
//
// Arithmetic is plain double precision; every decision is a sign test of an orientation
// determinant (never a division), so configurations whose determinants are computed exactly
// (e.g. small-integer or dyadic coordinates) get the exact answer, including touching cases.
// The test is symmetric by construction (tri_tri_overlap(a, b) == tri_tri_overlap(b, a) bit for
// bit): the pair is put in a canonical order before testing.
#include <array>

#include "tightbvh/pose.hpp"

namespace tightbvh {

[[nodiscard]] bool tri_tri_overlap(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                   const Vec3& q0, const Vec3& q1, const Vec3& q2);

[[nodiscard]] inline bool tri_tri_overlap(const std::array<Vec3, 3>& p, const std::array<Vec3, 3>& q) {
  return tri_tri_overlap(p[0], p[1], p[2], q[0], q[1], q[2]);
}

}  // namespace tightbvh
