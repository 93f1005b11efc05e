#pragma once
/// @file
/// Triangle-triangle overlap test for closed triangles (Guigue & Devillers 2003, "Fast and
/// robust triangle-triangle overlap test using orientation predicates", J. Graphics Tools 8(1)).
///
/// "Touching" (the definition used by every query in tightbvh, brute force included): a triangle
/// is the closed set of its points (interior + edges + vertices), and two triangles touch iff the
/// two closed sets share at least one point. Shared vertices, shared edges, a vertex on the other
/// triangle's face or edge, and coplanar overlap all count as contact.
///
/// Degenerate triangles (exactly collinear corners, zero area) are the closed point sets they
/// are: a segment (between the two extreme corners) or a single point, tested as segment/point
/// against the other primitive.
///
/// Exact: every decision is the sign of an orientation determinant (never a division), evaluated
/// in double precision with a forward error bound and, when that cannot decide, exactly with
/// floating-point expansions (Shewchuk 1997). The answer is therefore the exact answer for the
/// given double coordinates (assuming no overflow/underflow: |coordinates| within ~1e+-100): it
/// is symmetric (tri_tri_overlap(a, b) == tri_tri_overlap(b, a)), independent of the order of
/// the corners, and exactly right for touching, coplanar and degenerate configurations. Under a
/// rigid motion the coordinates are rounded, so only pairs within rounding of contact can change.
#include <array>

#include "tightbvh/pose.hpp"

namespace tightbvh {

/// Whether the closed triangles (p0, p1, p2) and (q0, q1, q2) touch (exact, as described above).
[[nodiscard]] bool tri_tri_overlap(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                   const Vec3& q0, const Vec3& q1, const Vec3& q2);

/// The same for triangles given as corner arrays (Mesh::corners).
[[nodiscard]] inline bool tri_tri_overlap(const std::array<Vec3, 3>& p, const std::array<Vec3, 3>& q) {
  return tri_tri_overlap(p[0], p[1], p[2], q[0], q[1], q[2]);
}

}  // namespace tightbvh
