// Closed triangle-triangle overlap: Guigue & Devillers (2003) for the general case, with
// explicit handling of coplanar pairs and of degenerate (segment / point) triangles. Every
// decision is the exact sign of an orientation determinant (predicates.hpp), so the answer is the
// exact one for the given double coordinates. See include/tightbvh/tri_tri.hpp for "touching".
#include "tightbvh/tri_tri.hpp"

#include <algorithm>
#include <cmath>

#include "../geometry/predicates.hpp"

namespace tightbvh {
namespace {

using detail::collinear;
using detail::OrientPlane;
using detail::orient3d;

// ---------------------------------------------------------------- 2D (a plane projected along an axis)
struct P2 {
  double x, y;
};

// Drops coordinate `axis`: injective on any plane whose normal has a non-zero `axis` component.
[[nodiscard]] inline P2 drop(const Vec3& p, int axis) {
  switch (axis) {
    case 0: return {p.y(), p.z()};
    case 1: return {p.z(), p.x()};
    default: return {p.x(), p.y()};
  }
}

[[nodiscard]] inline int orient2d(const P2& a, const P2& b, const P2& c) {
  return detail::orient2d(a.x, a.y, b.x, b.y, c.x, c.y);
}

// The sign of component `axis` of (b - a) x (c - a), exactly: the orientation of the triangle
// projected along `axis`.
[[nodiscard]] inline int projected_orientation(const Vec3& a, const Vec3& b, const Vec3& c, int axis) {
  return orient2d(drop(a, axis), drop(b, axis), drop(c, axis));
}

// An axis along which the non-collinear points (a, b, c) project to a non-degenerate triangle:
// the largest component of the rounded normal first, checked exactly.
[[nodiscard]] int projection_axis(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a).cwiseAbs();
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&n](int i, int j) { return n[i] > n[j]; });
  for (const int axis : order)
    if (projected_orientation(a, b, c, axis) != 0) return axis;
  return order[0];  // unreachable for non-collinear points
}

[[nodiscard]] inline bool same_strict_side(int u, int v) { return u * v > 0; }

[[nodiscard]] bool boxes_overlap_2d(const P2& a, const P2& b, const P2& c, const P2& d) {
  return std::max(std::min(a.x, b.x), std::min(c.x, d.x)) <= std::min(std::max(a.x, b.x), std::max(c.x, d.x)) &&
         std::max(std::min(a.y, b.y), std::min(c.y, d.y)) <= std::min(std::max(a.y, b.y), std::max(c.y, d.y));
}

// Closed segments [a, b] and [c, d] in the plane; either may be a single point.
[[nodiscard]] bool segments_overlap_2d(const P2& a, const P2& b, const P2& c, const P2& d) {
  const int d1 = orient2d(a, b, c), d2 = orient2d(a, b, d);
  if (same_strict_side(d1, d2)) return false;
  const int d3 = orient2d(c, d, a), d4 = orient2d(c, d, b);
  if (same_strict_side(d3, d4)) return false;
  // All four points on one line (or points): the intervals overlap iff their boxes do.
  if (d1 == 0 && d2 == 0 && d3 == 0 && d4 == 0) return boxes_overlap_2d(a, b, c, d);
  return true;
}

// Point in a closed non-degenerate triangle (either orientation).
[[nodiscard]] bool point_in_triangle_2d(const P2& p, const P2& t0, const P2& t1, const P2& t2) {
  const int o1 = orient2d(t0, t1, p), o2 = orient2d(t1, t2, p), o3 = orient2d(t2, t0, p);
  return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

[[nodiscard]] bool segment_triangle_2d(const P2& a, const P2& b, const P2& t0, const P2& t1, const P2& t2) {
  return point_in_triangle_2d(a, t0, t1, t2) || point_in_triangle_2d(b, t0, t1, t2) ||
         segments_overlap_2d(a, b, t0, t1) || segments_overlap_2d(a, b, t1, t2) || segments_overlap_2d(a, b, t2, t0);
}

// Coplanar non-degenerate triangles overlap iff two edges meet or one contains a vertex of the
// other.
[[nodiscard]] bool coplanar_triangles(const Vec3 p[3], const Vec3 q[3]) {
  const int axis = projection_axis(p[0], p[1], p[2]);
  const P2 a[3] = {drop(p[0], axis), drop(p[1], axis), drop(p[2], axis)};
  const P2 b[3] = {drop(q[0], axis), drop(q[1], axis), drop(q[2], axis)};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (segments_overlap_2d(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3])) return true;
  return point_in_triangle_2d(a[0], b[0], b[1], b[2]) || point_in_triangle_2d(b[0], a[0], a[1], a[2]);
}

// ---------------------------------------------------------------- 3D primitives
// Closed segment [a, b] (a != b) against a closed non-degenerate triangle.
[[nodiscard]] bool segment_triangle(const Vec3& a, const Vec3& b, const Vec3 t[3]) {
  const OrientPlane plane(t[0], t[1], t[2]);
  const int da = plane.sign(a), db = plane.sign(b);
  if (same_strict_side(da, db)) return false;
  if (da == 0 && db == 0) {
    const int axis = projection_axis(t[0], t[1], t[2]);
    return segment_triangle_2d(drop(a, axis), drop(b, axis), drop(t[0], axis), drop(t[1], axis), drop(t[2], axis));
  }
  // The line ab crosses the plane in one point, inside the segment; it lies in the closed
  // triangle iff the line passes on the same side of (or through) all three edges.
  const int o1 = orient3d(a, b, t[0], t[1]), o2 = orient3d(a, b, t[1], t[2]), o3 = orient3d(a, b, t[2], t[0]);
  return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

[[nodiscard]] bool point_triangle(const Vec3& p, const Vec3 t[3]) {
  if (orient3d(t[0], t[1], t[2], p) != 0) return false;
  const int axis = projection_axis(t[0], t[1], t[2]);
  return point_in_triangle_2d(drop(p, axis), drop(t[0], axis), drop(t[1], axis), drop(t[2], axis));
}

[[nodiscard]] bool in_bounds(const Vec3& p, const Vec3& a, const Vec3& b) {
  return (p.array() >= a.cwiseMin(b).array()).all() && (p.array() <= a.cwiseMax(b).array()).all();
}

// Closed segments [a, b] and [c, d], a != b, c != d.
[[nodiscard]] bool segment_segment(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  if (orient3d(a, b, c, d) != 0) return false;  // not coplanar
  int axis;
  if (!collinear(a, b, c)) {
    axis = projection_axis(a, b, c);
  } else if (!collinear(a, b, d)) {
    axis = projection_axis(a, b, d);
  } else {
    // All four points on one line: the intervals overlap iff the bounding boxes do.
    return (a.cwiseMin(b).array() <= c.cwiseMax(d).array()).all() &&
           (c.cwiseMin(d).array() <= a.cwiseMax(b).array()).all();
  }
  return segments_overlap_2d(drop(a, axis), drop(b, axis), drop(c, axis), drop(d, axis));
}

[[nodiscard]] bool point_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  return collinear(a, b, p) && in_bounds(p, a, b);
}

// ---------------------------------------------------------------- degenerate classification
enum class Kind { triangle, segment, point };

struct Shape {
  Kind kind;
  Vec3 a, b;  // segment endpoints, or the point in a
};

// Exactly collinear corners make a segment (between the two extreme corners along the axis of
// largest spread) or a point.
[[nodiscard]] Shape classify(const Vec3 t[3]) {
  if (!collinear(t[0], t[1], t[2])) return {Kind::triangle, t[0], t[1]};
  if (t[0] == t[1] && t[1] == t[2]) return {Kind::point, t[0], t[0]};
  const Vec3 lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]), hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  int imin = 0, imax = 0;
  for (int i = 1; i < 3; ++i) {
    if (t[i][axis] < t[imin][axis]) imin = i;
    if (t[i][axis] > t[imax][axis]) imax = i;
  }
  return {Kind::segment, t[imin], t[imax]};
}

// Guigue-Devillers for two non-degenerate triangles.
[[nodiscard]] bool triangles_overlap(const Vec3 p[3], const Vec3 q[3]) {
  // Signs of q's corners relative to the plane of p, and vice versa (Section 3 of the paper).
  const OrientPlane plane_p(p[0], p[1], p[2]);
  const int sq[3] = {plane_p.sign(q[0]), plane_p.sign(q[1]), plane_p.sign(q[2])};
  if (sq[0] != 0 && sq[0] == sq[1] && sq[1] == sq[2]) return false;
  const OrientPlane plane_q(q[0], q[1], q[2]);
  const int sp[3] = {plane_q.sign(p[0]), plane_q.sign(p[1]), plane_q.sign(p[2])};
  if (sp[0] != 0 && sp[0] == sp[1] && sp[1] == sp[2]) return false;
  if (sq[0] == 0 && sq[1] == 0 && sq[2] == 0) return coplanar_triangles(p, q);  // exact: then sp == 0 too

  // The "alone" corner: strictly on one side with the others on the other side or on the plane,
  // or on the plane with the two others strictly on the same side. One always exists here.
  const auto alone = [](const int s[3]) {
    for (int i = 0; i < 3; ++i) {
      const int j = s[(i + 1) % 3], k = s[(i + 2) % 3];
      if (s[i] != 0 ? (j * s[i] <= 0 && k * s[i] <= 0) : (j != 0 && j == k)) return i;
    }
    return 0;  // unreachable
  };
  const int ip = alone(sp), iq = alone(sq);
  // Canonical form: the alone corner of each triangle on the non-negative side of the other
  // triangle's plane, the two other corners on the non-positive side. Swapping the last two
  // corners of a triangle flips its plane's orientation.
  const bool flip_q = sp[ip] < 0 || (sp[ip] == 0 && sp[(ip + 1) % 3] > 0);
  const bool flip_p = sq[iq] < 0 || (sq[iq] == 0 && sq[(iq + 1) % 3] > 0);
  const Vec3& a1 = p[ip];
  const Vec3& a2 = flip_p ? p[(ip + 2) % 3] : p[(ip + 1) % 3];
  const Vec3& a3 = flip_p ? p[(ip + 1) % 3] : p[(ip + 2) % 3];
  const Vec3& b1 = q[iq];
  const Vec3& b2 = flip_q ? q[(iq + 2) % 3] : q[(iq + 1) % 3];
  const Vec3& b3 = flip_q ? q[(iq + 1) % 3] : q[(iq + 2) % 3];
  // Both triangles cut the line L of the two planes in closed intervals [j, i] (p) and [k, l]
  // (q), i on edge a1a2, j on a1a3, k on b1b2, l on b1b3. They overlap iff k <= i and j <= l;
  // each comparison is the side of a corner of one triangle relative to the plane through an
  // edge of the other and the alone corner of the first.
  if (orient3d(a2, b1, a1, b2) > 0) return false;  // k beyond i
  if (orient3d(a1, b1, a3, b3) > 0) return false;  // l before j
  return true;
}

}  // namespace

bool tri_tri_overlap(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  const Vec3 p[3] = {p0, p1, p2};
  const Vec3 q[3] = {q0, q1, q2};
  const Shape sp = classify(p), sq = classify(q);
  if (sp.kind == Kind::triangle && sq.kind == Kind::triangle) return triangles_overlap(p, q);
  // Degenerate cases, with the "larger" kind first (triangle < segment < point).
  const auto pair = [](const Shape& s, const Vec3* t, const Shape& o) -> bool {
    switch (s.kind) {
      case Kind::triangle:
        return o.kind == Kind::segment ? segment_triangle(o.a, o.b, t) : point_triangle(o.a, t);
      case Kind::segment:
        return o.kind == Kind::segment ? segment_segment(s.a, s.b, o.a, o.b) : point_segment(o.a, s.a, s.b);
      default:
        return s.a == o.a;
    }
  };
  return static_cast<int>(sp.kind) <= static_cast<int>(sq.kind) ? pair(sp, p, sq) : pair(sq, q, sp);
}

}  // namespace tightbvh
