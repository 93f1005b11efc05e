#pragma once
/// @file
/// Minimum Euclidean distance between two closed triangles, with a closest point on each.
///
/// Triangles are the closed point sets of tri_tri.hpp (degenerate ones are the segment or point
/// they are). The answer is consistent with the touching predicate: the distance is exactly 0 iff
/// tri_tri_overlap() says the triangles touch (it is called first), and > 0 otherwise.
///
/// Disjoint triangles: the minimum is attained by an edge of one and an edge of the other, or by
/// a vertex of one and the interior of the other (the closest points of two disjoint convex
/// polygons, one of them at a vertex or both on edges). So the answer is the least of 9
/// segment-segment distances and 6 vertex-to-face projections that fall inside the face. Each
/// candidate is a pair of actual points, so rounding never makes the answer smaller than what
/// its points realise. Near-parallel edge pairs (where the usual 2x2 solve loses precision) also
/// try the four endpoint-to-segment distances, and faces are skipped for degenerate triangles
/// (their edges cover them). For disjoint triangles all 15 candidates are measured, branch-free
/// (in AVX2 lanes where the CPU has them, with the same answer bit for bit on any CPU), and the
/// least is kept, the first on a tie.
///
/// Symmetric: tri_tri_distance(p, q) and tri_tri_distance(q, p) give the same distance bit for
/// bit (the pair is put in a canonical order before any arithmetic) with the points swapped.
#include <array>

#include "tightbvh/pose.hpp"

namespace tightbvh {

/// The answer of tri_tri_distance().
struct TriangleDistance {
  double distance = 0.0;        ///< >= 0; exactly 0 iff the triangles touch
  Vec3 point_p = Vec3::Zero();  ///< on triangle (p0, p1, p2)
  Vec3 point_q = Vec3::Zero();  ///< on triangle (q0, q1, q2)
};

/// The distance between triangles (p0, p1, p2) and (q0, q1, q2), with a closest point on each
/// (as described above). All in one frame; the answer is in the same frame and unit.
[[nodiscard]] TriangleDistance tri_tri_distance(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                                const Vec3& q0, const Vec3& q1, const Vec3& q2);

/// The same for triangles given as corner arrays (Mesh::corners).
[[nodiscard]] inline TriangleDistance tri_tri_distance(const std::array<Vec3, 3>& p, const std::array<Vec3, 3>& q) {
  return tri_tri_distance(p[0], p[1], p[2], q[0], q[1], q[2]);
}

/// tri_tri_distance(...).distance <= margin, exactly, but cheaper: the candidates first, and the
/// touching test only when none is within the margin (collide's margin).
[[nodiscard]] bool tri_tri_within(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                  const Vec3& q0, const Vec3& q1, const Vec3& q2, double margin);

}  // namespace tightbvh
