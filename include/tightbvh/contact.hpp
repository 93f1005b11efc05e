#pragma once
/// @file
/// Contact geometry of two touching triangles: where they cross (Möller 1997, "A fast
/// triangle-triangle intersection test", J. Graphics Tools 2(2); Guigue & Devillers 2003, the
/// orientation-predicate formulation used by tri_tri.hpp; Ericson, Real-Time Collision
/// Detection, 2005, §5.2).
///
/// Two triangles in general position cross along a segment of the line where their planes meet:
/// each triangle meets the other's plane in an interval of that line, and the contact is the
/// intersection of the two intervals. It is a point when they only touch (a corner on the other
/// triangle, an edge through an edge), and, when both triangles lie in one plane, the overlap
/// polygon (at most six corners, Sutherland–Hodgman clipping of one by the other's edges).
///
/// Exact and rounded parts: which side of the other's plane each corner is on, and so whether the
/// triangles are coplanar and whether a triangle meets the other's plane in a single corner or
/// along a whole edge, is decided by the exact orientation predicate (orient3d, Shewchuk 1997);
/// whether two interval ends coincide (edge through edge, corner on edge) is decided exactly too.
/// The points are computed in double: a corner is returned exactly; a point where an edge crosses a
/// plane is within a few units of rounding (relative to the coordinates) of the exact one, divided by
/// the sine of the angle between the edge and that plane; the order of interval ends along the line
/// that are not exactly equal is decided in double. Degenerate (zero-area) triangles are the segment
/// or point they are: their contact with the other triangle is a point or a segment, their normal
/// is zero and flagged.
#include <array>
#include <cstdint>

#include "tightbvh/pose.hpp"

namespace tightbvh {

/// What two triangles share.
enum class ContactKind : std::uint8_t {
  none,     ///< nothing (the triangles do not touch)
  point,    ///< one point (points[0])
  segment,  ///< a segment (points[0] to points[1])
  polygon,  ///< a convex polygon of `count` corners in order (coplanar overlap)
};
/// The enumerator's name: "none", "point", "segment" or "polygon".
[[nodiscard]] const char* to_string(ContactKind kind);

/// The contact geometry of two triangles A and B (in the frame their corners were given in; the
/// queries return it in the world frame).
struct Contact {
  ContactKind kind = ContactKind::none;  ///< Point, segment or (coplanar) polygon.
  /// Both triangles lie in one plane (exact). The contact is then their overlap: a polygon, or
  /// a segment or point when they only touch along an edge or at a corner.
  bool coplanar = false;
  std::uint8_t count = 0;         ///< Number of valid entries of `points` (0, 1, 2, or 3 to 6).
  std::array<Vec3, 6> points{};   ///< The point, the segment's ends, or the polygon's corners.
  Vec3 normal_a = Vec3::Zero();   ///< A's unit face normal ((a1 - a0) x (a2 - a0)), zero if degenerate.
  Vec3 normal_b = Vec3::Zero();   ///< B's unit face normal, zero if degenerate.
  bool degenerate_a = false;      ///< A's corners are collinear (exactly): it has no normal.
  bool degenerate_b = false;      ///< B's corners are collinear (exactly): it has no normal.

  /// The segment's length (kind segment), else 0.
  [[nodiscard]] double length() const { return kind == ContactKind::segment ? (points[1] - points[0]).norm() : 0.0; }
};

/// The contact geometry of the closed triangles (a0, a1, a2) and (b0, b1, b2), as described above.
/// kind none when they do not touch.
[[nodiscard]] Contact triangle_contact(const Vec3& a0, const Vec3& a1, const Vec3& a2,  //
                                       const Vec3& b0, const Vec3& b1, const Vec3& b2);

/// The same for triangles given as corner arrays (Mesh::corners).
[[nodiscard]] inline Contact triangle_contact(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b) {
  return triangle_contact(a[0], a[1], a[2], b[0], b[1], b[2]);
}

/// The contact mapped by `pose` (points by pose.apply, normals by pose.rotation only).
[[nodiscard]] Contact transformed(const Contact& contact, const Pose& pose);

}  // namespace tightbvh
