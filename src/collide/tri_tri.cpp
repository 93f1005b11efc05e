// Closed triangle-triangle overlap: Guigue & Devillers (2003) for the general case, with
// explicit handling of coplanar pairs and of degenerate (segment / point) triangles.
// See include/tightbvh/tri_tri.hpp for the definition of "touching".
#include "tightbvh/tri_tri.hpp"

#include <cmath>
#include <utility>

namespace tightbvh {
namespace {

// Signed volume det[b - a, c - a, d - a]: > 0 iff d lies on the side of plane (a, b, c) that
// its normal (b - a) x (c - a) points to.
[[nodiscard]] inline double orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).cross(c - a).dot(d - a);
}

[[nodiscard]] inline int sign(double x) { return (x > 0.0) - (x < 0.0); }

// ---------------------------------------------------------------- 2D predicates (closed sets)
struct P2 {
  double x, y;
};

// Projection that drops coordinate `axis` (the dominant axis of a plane normal).
[[nodiscard]] inline P2 drop(const Vec3& p, int axis) {
  switch (axis) {
    case 0: return {p.y(), p.z()};
    case 1: return {p.z(), p.x()};
    default: return {p.x(), p.y()};
  }
}

[[nodiscard]] inline int dominant_axis(const Vec3& n) {
  const Vec3 a = n.cwiseAbs();
  if (a.x() >= a.y() && a.x() >= a.z()) return 0;
  return a.y() >= a.z() ? 1 : 2;
}

[[nodiscard]] inline double orient2d(const P2& a, const P2& b, const P2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

[[nodiscard]] inline bool same_strict_side(double u, double v) { return (u > 0.0 && v > 0.0) || (u < 0.0 && v < 0.0); }

// Closed segments [a, b] and [c, d] in the plane; either may be a single point.
[[nodiscard]] bool segments_overlap_2d(const P2& a, const P2& b, const P2& c, const P2& d) {
  const double d1 = orient2d(a, b, c), d2 = orient2d(a, b, d);
  if (same_strict_side(d1, d2)) return false;
  const double d3 = orient2d(c, d, a), d4 = orient2d(c, d, b);
  if (same_strict_side(d3, d4)) return false;
  if (d1 == 0.0 && d2 == 0.0 && d3 == 0.0 && d4 == 0.0) {
    // All four points collinear (or points): the closed intervals on the common line overlap
    // iff their bounding boxes do.
    return std::max(std::min(a.x, b.x), std::min(c.x, d.x)) <= std::min(std::max(a.x, b.x), std::max(c.x, d.x)) &&
           std::max(std::min(a.y, b.y), std::min(c.y, d.y)) <= std::min(std::max(a.y, b.y), std::max(c.y, d.y));
  }
  return true;
}

// Point in closed non-degenerate triangle (either orientation).
[[nodiscard]] bool point_in_triangle_2d(const P2& p, const P2& t0, const P2& t1, const P2& t2) {
  const double o1 = orient2d(t0, t1, p), o2 = orient2d(t1, t2, p), o3 = orient2d(t2, t0, p);
  return (o1 >= 0.0 && o2 >= 0.0 && o3 >= 0.0) || (o1 <= 0.0 && o2 <= 0.0 && o3 <= 0.0);
}

[[nodiscard]] bool segment_triangle_2d(const P2& a, const P2& b, const P2& t0, const P2& t1, const P2& t2) {
  return point_in_triangle_2d(a, t0, t1, t2) || point_in_triangle_2d(b, t0, t1, t2) ||
         segments_overlap_2d(a, b, t0, t1) || segments_overlap_2d(a, b, t1, t2) || segments_overlap_2d(a, b, t2, t0);
}

// Coplanar non-degenerate triangles: they overlap iff two edges cross or one triangle contains a
// vertex of the other (containment).
[[nodiscard]] bool coplanar_triangles(const Vec3 p[3], const Vec3 q[3], const Vec3& normal) {
  const int axis = dominant_axis(normal);
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
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  const double da = n.dot(a - t[0]), db = n.dot(b - t[0]);
  if (same_strict_side(da, db)) return false;
  if (da == 0.0 && db == 0.0) {
    const int axis = dominant_axis(n);
    return segment_triangle_2d(drop(a, axis), drop(b, axis), drop(t[0], axis), drop(t[1], axis), drop(t[2], axis));
  }
  // The line ab crosses the plane in one point, inside the segment; it lies in the closed
  // triangle iff the line passes on the same side of (or touches) all three edges.
  const double o1 = orient3d(a, b, t[0], t[1]), o2 = orient3d(a, b, t[1], t[2]), o3 = orient3d(a, b, t[2], t[0]);
  return (o1 >= 0.0 && o2 >= 0.0 && o3 >= 0.0) || (o1 <= 0.0 && o2 <= 0.0 && o3 <= 0.0);
}

[[nodiscard]] bool point_triangle(const Vec3& p, const Vec3 t[3]) {
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  if (n.dot(p - t[0]) != 0.0) return false;
  const int axis = dominant_axis(n);
  return point_in_triangle_2d(drop(p, axis), drop(t[0], axis), drop(t[1], axis), drop(t[2], axis));
}

[[nodiscard]] bool in_bounds(const Vec3& p, const Vec3& a, const Vec3& b) {
  return (p.array() >= a.cwiseMin(b).array()).all() && (p.array() <= a.cwiseMax(b).array()).all();
}

// Closed segments [a, b] and [c, d], a != b, c != d.
[[nodiscard]] bool segment_segment(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  if (orient3d(a, b, c, d) != 0.0) return false;  // not coplanar
  Vec3 n = (b - a).cross(c - a);
  if (n == Vec3::Zero()) n = (b - a).cross(d - a);
  if (n == Vec3::Zero()) {
    // All four points on one line: the intervals overlap iff the bounding boxes do.
    return (a.cwiseMin(b).array() <= c.cwiseMax(d).array()).all() &&
           (c.cwiseMin(d).array() <= a.cwiseMax(b).array()).all();
  }
  const int axis = dominant_axis(n);
  return segments_overlap_2d(drop(a, axis), drop(b, axis), drop(c, axis), drop(d, axis));
}

[[nodiscard]] bool point_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  return (b - a).cross(p - a) == Vec3::Zero() && in_bounds(p, a, b);
}

// ---------------------------------------------------------------- degenerate classification
enum class Kind { triangle, segment, point };

struct Shape {
  Kind kind;
  Vec3 a, b;  // segment endpoints, or the point in a
};

[[nodiscard]] Shape classify(const Vec3 t[3]) {
  if ((t[1] - t[0]).cross(t[2] - t[0]) != Vec3::Zero()) return {Kind::triangle, t[0], t[1]};
  if (t[0] == t[1] && t[1] == t[2]) return {Kind::point, t[0], t[0]};
  // Zero area but not a point: the segment between the two corners farthest apart.
  const double d01 = (t[1] - t[0]).squaredNorm(), d12 = (t[2] - t[1]).squaredNorm(), d20 = (t[0] - t[2]).squaredNorm();
  if (d01 >= d12 && d01 >= d20) return {Kind::segment, t[0], t[1]};
  if (d12 >= d20) return {Kind::segment, t[1], t[2]};
  return {Kind::segment, t[2], t[0]};
}

// Guigue-Devillers for two non-degenerate triangles.
[[nodiscard]] bool triangles_overlap(const Vec3 p[3], const Vec3 q[3]) {
  // Signs of q's corners relative to the plane of p, and vice versa (Section 3 of the paper).
  const Vec3 np = (p[1] - p[0]).cross(p[2] - p[0]);
  const int sq[3] = {sign(np.dot(q[0] - p[0])), sign(np.dot(q[1] - p[0])), sign(np.dot(q[2] - p[0]))};
  if (sq[0] != 0 && sq[0] == sq[1] && sq[1] == sq[2]) return false;
  const Vec3 nq = (q[1] - q[0]).cross(q[2] - q[0]);
  const int sp[3] = {sign(nq.dot(p[0] - q[0])), sign(nq.dot(p[1] - q[0])), sign(nq.dot(p[2] - q[0]))};
  if (sp[0] != 0 && sp[0] == sp[1] && sp[1] == sp[2]) return false;
  if ((sq[0] == 0 && sq[1] == 0 && sq[2] == 0) || (sp[0] == 0 && sp[1] == 0 && sp[2] == 0))
    return coplanar_triangles(p, q, np);

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
  if (orient3d(a2, b1, a1, b2) > 0.0) return false;  // k beyond i
  if (orient3d(a1, b1, a3, b3) > 0.0) return false;  // l before j
  return true;
}

[[nodiscard]] bool lexicographic_less(const Vec3 p[3], const Vec3 q[3]) {
  for (int v = 0; v < 3; ++v)
    for (int c = 0; c < 3; ++c)
      if (p[v][c] != q[v][c]) return p[v][c] < q[v][c];
  return false;
}

}  // namespace

bool tri_tri_overlap(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  const Vec3 u[3] = {p0, p1, p2};
  const Vec3 w[3] = {q0, q1, q2};
  // Canonical order of the pair makes the test exactly symmetric.
  const bool swap = lexicographic_less(w, u);
  const Vec3* p = swap ? w : u;
  const Vec3* q = swap ? u : w;
  const Shape sp = classify(p), sq = classify(q);
  if (sp.kind == Kind::triangle && sq.kind == Kind::triangle) return triangles_overlap(p, q);
  // Degenerate cases: order so that the "larger" kind comes first.
  const auto pair = [&](const Shape& s, const Vec3* t, const Shape& o, const Vec3* ot) -> bool {
    // s.kind <= o.kind in the enum order (triangle < segment < point).
    switch (s.kind) {
      case Kind::triangle:
        return o.kind == Kind::segment ? segment_triangle(o.a, o.b, t) : point_triangle(o.a, t);
      case Kind::segment:
        return o.kind == Kind::segment ? segment_segment(s.a, s.b, o.a, o.b) : point_segment(o.a, s.a, s.b);
      default:
        (void)ot;
        return s.a == o.a;
    }
  };
  return static_cast<int>(sp.kind) <= static_cast<int>(sq.kind) ? pair(sp, p, sq, q) : pair(sq, q, sp, p);
}

}  // namespace tightbvh
