// Contact geometry of two triangles (see include/tightbvh/contact.hpp): exact classification
// with orient3d, points in double.
#include "tightbvh/contact.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "../geometry/predicates.hpp"
#include "tightbvh/tri_tri.hpp"

namespace tightbvh {

namespace {

using detail::accurate_normal;
using detail::collinear;
using detail::orient3d;
using Corners = std::array<Vec3, 3>;

Vec3 unit(const Vec3& n) {
  const double length = n.norm();
  return length > 0.0 ? Vec3(n / length) : Vec3::Zero();
}

// Where the segment from x (signed distance dx to a plane) to y (dy) crosses the plane; the
// parameter is clamped to the segment, so rounding never moves the point off it.
Vec3 crossing(const Vec3& x, double dx, const Vec3& y, double dy) {
  const double t = dx == dy ? 0.5 : std::clamp(dx / (dx - dy), 0.0, 1.0);
  return x + t * (y - x);
}

// An end of the interval where a triangle meets the other's plane: its corner u (u == v), or the
// point where its edge (u, v), whose corners are strictly on opposite sides, crosses the plane.
struct End {
  Vec3 p;
  int u = 0, v = 0;
  [[nodiscard]] bool corner() const { return u == v; }
};

// The interval where triangle x meets the plane (origin o, normal n; exact sides s of x's
// corners, not all 0 and not all the same strict side). The apex k is a corner on a strict side
// whose two edges reach the plane (the other corners are on it or on the other side); without
// one, a single corner lies on the plane and the others strictly on one side.
std::array<End, 2> interval(const Corners& x, const std::array<int, 3>& s, const Vec3& n, const Vec3& o) {
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    if (s[k] == 0 || s[i] * s[k] > 0 || s[j] * s[k] > 0) continue;
    const double dk = n.dot(x[k] - o);
    const auto end = [&](int m) {
      return s[m] == 0 ? End{x[m], m, m} : End{crossing(x[k], dk, x[m], n.dot(x[m] - o)), k, m};
    };
    return {end(i), end(j)};
  }
  int k = 0;
  while (s[k] != 0) ++k;
  return {End{x[k], k, k}, End{x[k], k, k}};
}

// Whether end e of A and end f of B (both on the line where the planes meet) are the same point,
// exactly: a crossing edge meets that line at one point only.
bool same(const Corners& a, const End& e, const Corners& b, const End& f) {
  if (e.corner() && f.corner()) return a[e.u] == b[f.u];
  if (e.corner()) return collinear(a[e.u], b[f.u], b[f.v]);
  if (f.corner()) return collinear(b[f.u], a[e.u], a[e.v]);
  return orient3d(a[e.u], a[e.v], b[f.u], b[f.v]) == 0;
}

void set_point(Contact& c, const Vec3& p) {
  c.kind = ContactKind::point;
  c.count = 1;
  c.points[0] = p;
}

void set_segment(Contact& c, const Vec3& p, const Vec3& q) {
  if (p == q) return set_point(c, p);
  c.kind = ContactKind::segment;
  c.count = 2;
  c.points[0] = p;
  c.points[1] = q;
}

// Size of the pair, for the tolerance of the coplanar overlap's rounding.
double extent(const Corners& a, const Corners& b) {
  double m = 0.0;
  for (const Vec3& p : a)
    for (const Vec3& q : b) m = std::max(m, (p - q).lpNorm<Eigen::Infinity>());
  for (const Vec3& p : a) m = std::max(m, p.lpNorm<Eigen::Infinity>());
  return m;
}

// The points in `poly` as a contact: duplicates (within tol) dropped; a polygon of (near) zero
// area collapses to its two farthest points.
void set_polygon(Contact& c, const Vec3* poly, int n, double tol) {
  std::array<Vec3, 6> kept;
  int m = 0;
  for (int i = 0; i < n; ++i) {
    bool dup = false;
    for (int j = 0; j < m; ++j) dup = dup || (poly[i] - kept[j]).norm() <= tol;
    if (!dup && m < 6) kept[m++] = poly[i];
  }
  if (m == 0) return;
  if (m == 1) return set_point(c, kept[0]);
  int fi = 0, fj = 1;
  for (int i = 0; i < m; ++i)
    for (int j = i + 1; j < m; ++j)
      if ((kept[i] - kept[j]).squaredNorm() > (kept[fi] - kept[fj]).squaredNorm()) fi = i, fj = j;
  Vec3 area = Vec3::Zero();
  for (int i = 1; i + 1 < m; ++i) area += (kept[i] - kept[0]).cross(kept[i + 1] - kept[0]);
  if (m == 2 || area.norm() <= tol * (kept[fi] - kept[fj]).norm()) return set_segment(c, kept[fi], kept[fj]);
  c.kind = ContactKind::polygon;
  c.count = static_cast<std::uint8_t>(m);
  std::copy(kept.begin(), kept.begin() + m, c.points.begin());
}

// Sutherland–Hodgman: the part of coplanar triangle a inside triangle b (unnormalised normal nb).
void coplanar_overlap(Contact& c, const Corners& a, const Corners& b, const Vec3& nb, double tol) {
  Vec3 poly[9], next[9];
  int n = 3;
  std::copy(a.begin(), a.end(), poly);
  for (int k = 0; k < 3 && n > 0; ++k) {
    const Vec3 inward = nb.cross(b[(k + 1) % 3] - b[k]);  // points into b from its edge k
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const Vec3& p = poly[i];
      const Vec3& q = poly[(i + 1) % n];
      const double fp = inward.dot(p - b[k]), fq = inward.dot(q - b[k]);
      if (fp >= 0.0) next[m++] = p;
      if ((fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0)) next[m++] = crossing(p, fp, q, fq);
    }
    n = m;
    std::copy(next, next + m, poly);
  }
  c.coplanar = true;
  set_polygon(c, poly, n, tol);
}

// The two farthest corners of a degenerate triangle: the segment (or point) it is.
std::pair<Vec3, Vec3> as_segment(const Corners& x) {
  std::pair<Vec3, Vec3> s{x[0], x[1]};
  if ((x[2] - x[0]).squaredNorm() > (s.second - s.first).squaredNorm()) s = {x[0], x[2]};
  if ((x[2] - x[1]).squaredNorm() > (s.second - s.first).squaredNorm()) s = {x[1], x[2]};
  return s;
}

// Degenerate a (a segment p q) against triangle b, which it touches.
void segment_triangle(Contact& c, const Corners& a, const Corners& b, const Vec3& nb, double tol) {
  const auto [p, q] = as_segment(a);
  if (!collinear(b[0], b[1], b[2])) {
    const int sp = orient3d(b[0], b[1], b[2], p), sq = orient3d(b[0], b[1], b[2], q);
    if (sp == 0 && sq == 0) {  // in b's plane: clip p q to b (Cyrus–Beck)
      double t0 = 0.0, t1 = 1.0;
      for (int k = 0; k < 3; ++k) {
        const Vec3 inward = nb.cross(b[(k + 1) % 3] - b[k]);
        const double fp = inward.dot(p - b[k]), fq = inward.dot(q - b[k]);
        if (fp < 0.0 && fq < 0.0) continue;  // rounding: the pair touches
        if (fp < 0.0) t0 = std::max(t0, fp / (fp - fq));
        if (fq < 0.0) t1 = std::min(t1, fp / (fp - fq));
      }
      c.coplanar = true;
      const Vec3 x = p + t0 * (q - p), y = p + std::max(t0, t1) * (q - p);
      if ((y - x).norm() <= tol) return set_point(c, x);
      return set_segment(c, x, y);
    }
    if (sp == 0) return set_point(c, p);
    if (sq == 0) return set_point(c, q);
    return set_point(c, crossing(p, nb.dot(p - b[0]), q, nb.dot(q - b[0])));
  }
  // Both degenerate: two segments (or points) that touch.
  const auto [r, s] = as_segment(b);
  const Vec3 d1 = q - p, d2 = s - r;
  if (collinear(p, q, r) && collinear(p, q, s)) {  // on one line: the overlap of the intervals
    const Vec3 dir = d1.squaredNorm() >= d2.squaredNorm() ? d1 : d2;
    if (dir.squaredNorm() == 0.0) return set_point(c, p);
    std::pair<Vec3, Vec3> u{p, q}, v{r, s};
    if (dir.dot(u.first) > dir.dot(u.second)) std::swap(u.first, u.second);
    if (dir.dot(v.first) > dir.dot(v.second)) std::swap(v.first, v.second);
    const Vec3 lo = dir.dot(u.first) >= dir.dot(v.first) ? u.first : v.first;
    const Vec3 hi = dir.dot(u.second) <= dir.dot(v.second) ? u.second : v.second;
    if (dir.dot(hi) <= dir.dot(lo)) return set_point(c, lo);
    return set_segment(c, lo, hi);
  }
  // Crossing lines: the closest points of the two lines coincide up to rounding.
  const double a11 = d1.dot(d1), a12 = d1.dot(d2), a22 = d2.dot(d2), det = a11 * a22 - a12 * a12;
  const Vec3 w = p - r;
  double t = a11 == 0.0 || det == 0.0 ? 0.0 : std::clamp((a12 * d2.dot(w) - a22 * d1.dot(w)) / det, 0.0, 1.0);
  set_point(c, p + t * d1);
}

}  // namespace

const char* to_string(ContactKind kind) {
  switch (kind) {
    case ContactKind::none: return "none";
    case ContactKind::point: return "point";
    case ContactKind::segment: return "segment";
    case ContactKind::polygon: return "polygon";
  }
  return "none";
}

Contact triangle_contact(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1,
                         const Vec3& b2) {
  Contact c;
  const Corners a{a0, a1, a2}, b{b0, b1, b2};
  c.degenerate_a = collinear(a0, a1, a2);
  c.degenerate_b = collinear(b0, b1, b2);
  const Vec3 na = accurate_normal(a0, a1, a2), nb = accurate_normal(b0, b1, b2);
  if (!c.degenerate_a) c.normal_a = unit(na);
  if (!c.degenerate_b) c.normal_b = unit(nb);
  if (!tri_tri_overlap(a, b)) return c;
  const double tol = 1e-12 * extent(a, b);
  if (c.degenerate_a) {
    segment_triangle(c, a, b, nb, tol);
    return c;
  }
  if (c.degenerate_b) {
    segment_triangle(c, b, a, na, tol);
    return c;
  }
  std::array<int, 3> sa{}, sb{};
  for (int i = 0; i < 3; ++i) {
    sa[i] = orient3d(b0, b1, b2, a[i]);
    sb[i] = orient3d(a0, a1, a2, b[i]);
  }
  if (sa[0] == 0 && sa[1] == 0 && sa[2] == 0) {
    coplanar_overlap(c, a, b, nb, tol);
    return c;
  }
  // Each triangle meets the other's plane in an interval of the line where the planes meet; the
  // contact is the intersection of the two intervals (ordered along that line's direction).
  std::array<End, 2> ea = interval(a, sa, nb, b0), eb = interval(b, sb, na, a0);
  const Vec3 dir = na.cross(nb);
  const auto at = [&](const End& e) { return dir.dot(e.p); };
  if (at(ea[0]) > at(ea[1])) std::swap(ea[0], ea[1]);
  if (at(eb[0]) > at(eb[1])) std::swap(eb[0], eb[1]);
  if (ea[0].corner() && ea[1].corner() && ea[0].u == ea[1].u) {  // a corner of A on B
    set_point(c, ea[0].p);
    return c;
  }
  if (eb[0].corner() && eb[1].corner() && eb[0].u == eb[1].u) {  // a corner of B on A
    set_point(c, eb[0].p);
    return c;
  }
  // The intervals meet end to end: an edge through an edge, or a corner on an edge.
  if (same(a, ea[1], b, eb[0]) && !same(a, ea[0], b, eb[1])) {
    set_point(c, ea[1].corner() ? ea[1].p : eb[0].p);
    return c;
  }
  if (same(a, ea[0], b, eb[1]) && !same(a, ea[1], b, eb[0])) {
    set_point(c, ea[0].corner() ? ea[0].p : eb[1].p);
    return c;
  }
  const Vec3 lo = at(ea[0]) >= at(eb[0]) ? ea[0].p : eb[0].p;
  const Vec3 hi = at(ea[1]) <= at(eb[1]) ? ea[1].p : eb[1].p;
  if (dir.dot(hi) < dir.dot(lo)) {  // the pair touches: ends that differ only by rounding
    set_point(c, 0.5 * (lo + hi));
    return c;
  }
  set_segment(c, lo, hi);
  return c;
}

Contact transformed(const Contact& contact, const Pose& pose) {
  Contact out = contact;
  for (int i = 0; i < contact.count; ++i) out.points[i] = pose.apply(contact.points[i]);
  out.normal_a = pose.rotation * contact.normal_a;
  out.normal_b = pose.rotation * contact.normal_b;
  return out;
}

}  // namespace tightbvh
