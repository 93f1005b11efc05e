// Primitive shapes against a posed mesh: per-triangle tests (Ericson §5.1.5 for the sphere, the
// segment–triangle distance for the capsule, Akenine-Möller 2001's separating axes then exact
// predicates for the box), a culling descent (collide) and a best-first bound-and-prune descent
// (distance) over the mesh's tree. See include/tightbvh/shape.hpp.
#include "tightbvh/shape.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "gjk.hpp"
#include "query_common.hpp"
#include "../geometry/predicates.hpp"
#include "traverse.hpp"
#include "tri_lanes.hpp"
#include "tightbvh/compact_box.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/obb_distance.hpp"
#include "tightbvh/obb_overlap.hpp"
#include "tightbvh/point_query.hpp"
#include "tightbvh/scene.hpp"
#include "tightbvh/tri_distance.hpp"
#include "tightbvh/tri_tri.hpp"

namespace tightbvh {
namespace {

using query_detail::map_point;

// The relative allowance of the culling box for a shape pose whose rotation is orthonormal only
// within kRotationTolerance (twice, composed with the mesh pose): the box with those axes is
// within about 2e-6 times the sum of its half extents of the box with orthonormalised axes, which
// contains the shape. 1e-5 leaves a safety factor of 5.
constexpr double kShapeSkew = 1e-5;

// A separating axis of the box test must separate by more than this times |axis|_1 times the
// coordinates' scale: far above the rounding of the projections (about 3e-16 of that), so an
// axis that separates the computed projections also separates the exact ones.
constexpr double kSeparationSlack = 1e-10;

// A triangle's lower bound (ruled_out()) is shrunk by this relative amount and by this times the
// coordinates' scale before it rules a triangle out, far above the bound's and the measure's
// rounding (a few units of 2^-53 of the scale), so a triangle is skipped only when its computed
// distance is not below the best one.
constexpr double kTriangleBoundSlack = 1e-9;

// A point is strictly on one side of a triangle's plane when n . (x - a) (n = (b - a) x (c - a))
// exceeds this times (|b - a|_1 |c - a|_1 + |n|_1) |x - a|_1: the rounding of n (its products and
// differences) and of the dot product stay below about 10 units of 2^-53 of that, so the
// computed side is the exact side of the given coordinates.
constexpr double kPlaneSideSlack = 1e-12;

// The least distance between the triangle and the shape's core (before the radius) that rules the
// triangle out against `limit` (the best distance so far), shrunk as kTriangleBoundSlack says.
[[nodiscard]] double needed_gap(double limit, double radius, double scale) {
  return (limit + radius + kTriangleBoundSlack * scale) / (1.0 - kTriangleBoundSlack);
}

// The gap between the intervals [lo_a, hi_a] and [lo_b, hi_b] (0 when they overlap).
[[nodiscard]] double interval_gap(double lo_a, double hi_a, double lo_b, double hi_b) {
  return std::max({0.0, lo_a - hi_b, lo_b - hi_a});
}

// Whether the set whose extent along the triangle's normal n (any length; 0 for a degenerate
// triangle: no plane to bound by) is [lo, hi] about the triangle's plane (n . (x - v0)) is at
// least `need` from it: compared squared, gap^2 >= need^2 |n|^2, without a root or a division.
[[nodiscard]] bool plane_rules_out(const Vec3& n, double lo, double hi, double need) {
  const double gap = interval_gap(lo, hi, 0.0, 0.0), n2 = n.squaredNorm();
  return n2 > 0.0 && gap * gap >= need * need * n2;
}

[[nodiscard]] std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

void require_size(const char* who, const char* field, double value) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw InputError(std::string(who) + ": " + field + " must be positive and finite, got " + number(value));
}

// One triangle measured against a shape, mesh frame.
struct Measure {
  double distance = 0.0;        // >= 0; exactly 0 iff touching
  Vec3 point_shape = Vec3::Zero();  // on the shape
  Vec3 point_mesh = Vec3::Zero();   // on the triangle
};

// The answer for a closest point `q` of a triangle at distance `d` from a point `s` of the shape's
// core (the sphere's center, a point of the capsule's axis) with radius r.
[[nodiscard]] Measure rounded_measure(const Vec3& s, const Vec3& q, double d, double r) {
  if (d <= r) return {0.0, q, q};  // q is on the triangle and inside the shape
  return {d - r, s + (q - s) * (r / d), q};
}

// The shape's box in node box `node`'s frame, obb_overlap()'s frame.
[[nodiscard]] query_detail::BoxFrame frame_of(const CompactBox& node, const Obb& box) {
  return query_detail::in_box_frame(node, box.axes, box.center);
}

// A lower bound of the distance from anything in `box` (the shape's box) to anything in the node's
// float box, from three separating directions, in the node's frame (t the shape's center, R its
// axes): the node's face normals (the gaps of the shape box's bounding box, in quadrature), the
// shape's face normals (likewise, the node's box seen from the shape's frame), and the line of the
// centers (unit u = t / |t|: |t| less both boxes' reach along u, sum_i e_i |u_i| and
// sum_j h_j |(R^T u)_j|, compared scaled by |t|), which is the tightest for boxes far apart for
// their sizes. obb_distance_lower_bound()'s nine edge axes are left out: they cost half of it and
// rarely win at a shape's distance. The larger, shrunk for the float axes (combined as if
// orthonormal, off by a relative ~1e-6: compact_box.hpp) and less the allowance.
[[nodiscard]] double box_bound(const CompactBox& node, const Obb& box, double allowance) {
  const query_detail::BoxFrame f = frame_of(node, box);
  const Mat3& r = f.c;
  const Vec3& t = f.d;
  const Vec3 e = node.half_extents_d(), h = box.half_extents;
  const Mat3 abs_r = r.cwiseAbs().array() + kSatEpsilon;
  const Vec3 t_b = r.transpose() * t;  // t in the shape's frame
  const Vec3 gap_a = (t.cwiseAbs() - e - abs_r * h).cwiseMax(0.0);
  const Vec3 gap_b = (t_b.cwiseAbs() - abs_r.transpose() * e - h).cwiseMax(0.0);
  double raw2 = std::max(gap_a.squaredNorm(), gap_b.squaredNorm());
  const double t2 = t.squaredNorm();
  const double along = t2 - e.dot(t.cwiseAbs()) - h.dot(t_b.cwiseAbs());
  if (along > 0.0 && along * along > raw2 * t2) raw2 = along * along / t2;
  return std::max(0.0, std::sqrt(raw2) * (1.0 - kCompactBoxSlack) - allowance);
}

// A sphere in the mesh frame.
struct PlacedSphere {
  Vec3 center;
  double radius;
  Obb box;  // culling box, mesh frame

  PlacedSphere(const Sphere& s, const Pose& rel)
      : center(rel.translation), radius(s.radius), box{rel.translation, Mat3::Identity(), Vec3::Constant(s.radius)} {}

  [[nodiscard]] Measure measure(const Vec3& a, const Vec3& b, const Vec3& c) const {
    const TrianglePoint p = closest_point_on_triangle(center, a, b, c);
    return rounded_measure(center, p.point, p.distance, radius);
  }
  // The distance from the center to the node's float slab box { x : |a_i . (x - c)| <= e_i } (for x
  // in it, |a_i . (x - p)| >= |a_i . (p - c)| - e_i), shrunk for the float axes and less the
  // allowance as point_query.cpp's bound, then less the radius: a point–box bound, tighter and
  // cheaper than the box–box one.
  [[nodiscard]] double lower_bound(const CompactBox& node, double allowance) const {
    const Vec3 d = center - node.center_d();
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double s = std::abs(node.axes.col(i).cast<double>().dot(d)) - static_cast<double>(node.half_extents[i]);
      if (s > 0.0) sum += s * s;
    }
    return std::max(0.0, std::sqrt(sum) * (1.0 - kCompactBoxSlack) - allowance - radius);
  }
  // Nothing in the node is within `margin`: its lower bound says so (collide's culling test;
  // cheaper and tighter than the sphere's box against the node's).
  [[nodiscard]] bool apart(const CompactBox& node, double allowance, double margin) const {
    return lower_bound(node, allowance) > margin;
  }
  // measure(a, b, c).distance <= margin, with the same arithmetic.
  [[nodiscard]] bool within(const Vec3& a, const Vec3& b, const Vec3& c, double margin) const {
    const double d = closest_point_on_triangle(center, a, b, c).distance;
    return d <= radius || d - radius <= margin;
  }
};

// A capsule in the mesh frame: its axis segment pq.
struct PlacedCapsule {
  Vec3 p, q;
  Vec3 mid, half;  // (p + q) / 2, (q - p) / 2
  double half_squared;  // |half|^2 > 0 (else the segment is its midpoint: half is then unused)
  double radius;
  Obb box;

  PlacedCapsule(const Capsule& s, const Pose& rel)
      : p(rel.apply(Vec3(0.0, 0.0, -0.5 * s.length))),
        q(rel.apply(Vec3(0.0, 0.0, 0.5 * s.length))),
        mid(0.5 * (p + q)),
        half(0.5 * (q - p)),
        half_squared(half.squaredNorm() > 0.0 ? half.squaredNorm() : 1.0),
        radius(s.radius),
        box{rel.translation, rel.rotation, Vec3(s.radius, s.radius, 0.5 * s.length + s.radius)} {}

  // The distance from the axis segment to the triangle, exactly 0 iff they touch. When both
  // endpoints are strictly on one side of the triangle's plane (by more than kPlaneSideSlack of
  // the scale of the side's computation, far above its rounding), they are disjoint and closest
  // at an endpoint against the triangle (closest_point_on_triangle, Ericson §5.1.5) or at the
  // segment against an edge (Ericson §5.1.9; a corner against the segment backs up nearly
  // parallel edges, as in tri_distance.cpp): a tenth of tri_tri_distance's work on the
  // degenerate triangle (p, q, q). Otherwise (crossing the plane, near it, or a degenerate
  // triangle) tri_tri_distance decides exactly.
  [[nodiscard]] TriangleDistance segment_distance(const Vec3& a, const Vec3& b, const Vec3& c) const {
    const Vec3 ab = b - a, ac = c - a, ap = p - a, aq = q - a;
    const Vec3 n = ab.cross(ac);
    const double sp = n.dot(ap), sq = n.dot(aq);
    const double size = ab.cwiseAbs().sum() * ac.cwiseAbs().sum() + n.cwiseAbs().sum();
    const double slack_p = kPlaneSideSlack * size * ap.cwiseAbs().sum(),
                 slack_q = kPlaneSideSlack * size * aq.cwiseAbs().sum();
    if (!((sp > slack_p && sq > slack_q) || (sp < -slack_p && sq < -slack_q))) return tri_tri_distance(p, q, q, a, b, c);
    double best = std::numeric_limits<double>::infinity();
    Vec3 on_segment = p, on_triangle = a;
    const auto offer = [&](const Vec3& x, const Vec3& y) {
      const double d2 = (x - y).squaredNorm();
      if (d2 < best) best = d2, on_segment = x, on_triangle = y;
    };
    offer(p, closest_point_on_triangle(p, a, b, c).point);
    offer(q, closest_point_on_triangle(q, a, b, c).point);
    const double s0[3] = {p.x(), p.y(), p.z()}, s1[3] = {q.x(), q.y(), q.z()};
    const Vec3 pq = q - p;
    const double length2 = pq.squaredNorm();
    const std::array<const Vec3*, 3> corners = {&a, &b, &c};
    for (int j = 0; j < 3; ++j) {
      const Vec3& e0 = *corners[j];
      const Vec3& e1 = *corners[(j + 1) % 3];
      const double f0[3] = {e0.x(), e0.y(), e0.z()}, f1[3] = {e1.x(), e1.y(), e1.z()};
      double xp[3], xq[3];
      bool parallel = false;
      (void)query_detail::tri_segment_segment<double, bool>(s0, s1, f0, f1, xp, xq, parallel);
      offer(Vec3(xp[0], xp[1], xp[2]), Vec3(xq[0], xq[1], xq[2]));
      const double t = length2 > 0.0 ? std::clamp((e0 - p).dot(pq) / length2, 0.0, 1.0) : 0.0;
      offer(p + t * pq, e0);
    }
    TriangleDistance d;
    d.distance = std::max(std::sqrt(best), std::numeric_limits<double>::min());  // disjoint: never 0
    d.point_p = on_segment;
    d.point_q = on_triangle;
    return d;
  }

  [[nodiscard]] Measure measure(const Vec3& a, const Vec3& b, const Vec3& c) const {
    const TriangleDistance t = segment_distance(a, b, c);
    return rounded_measure(t.point_p, t.point_q, t.distance, radius);
  }
  // The distance from the axis segment to the node's float slab box, bounded two ways. Per axis
  // a_i: the segment's projection is mid_i -+ half_i, the box's c_i -+ e_i, so any two of their
  // points are at least max(0, |mid_i - c_i| - half_i - e_i) apart along a_i, combined as the
  // sphere's bound. Across the segment: along the unit u from the segment toward the box's center,
  // square to the segment (v = c - mid less its part along the segment, u = v / |v|), the whole
  // segment projects to one point |v| short of the center and the box reaches sum_i e_i |a_i . u|
  // toward it, so the gap is |v| - sum_i e_i |a_i . u| (compared squared, scaled by |v|, before the
  // one root). The larger, less the radius. The second is the sphere's bound for a long segment
  // seen from its side, where the per-axis one is weakest.
  [[nodiscard]] double lower_bound(const CompactBox& node, double allowance) const {
    const Vec3 to_center = node.center_d() - mid;
    double sum = 0.0, reach = 0.0;
    const Vec3 v = to_center - (to_center.dot(half) / half_squared) * half;
    for (int i = 0; i < 3; ++i) {
      const Vec3 axis = node.axes.col(i).cast<double>();
      const double e = static_cast<double>(node.half_extents[i]);
      const double s = std::abs(axis.dot(to_center)) - std::abs(axis.dot(half)) - e;
      if (s > 0.0) sum += s * s;
      reach += e * std::abs(axis.dot(v));
    }
    const double v2 = v.squaredNorm(), across = v2 - reach;  // |v| times the gap across
    if (across > 0.0 && across * across > sum * v2) sum = across * across / v2;
    return std::max(0.0, std::sqrt(sum) * (1.0 - kCompactBoxSlack) - allowance - radius);
  }
  // Whether measure(a, b, c).distance is surely not below `limit`, far cheaper than measuring:
  // the gap between the triangle's and the axis segment's bounding boxes, then the axis segment's
  // gap to the triangle's plane (over |n|), against the radius plus the limit (needed_gap()).
  // Squared, without a root or a division.
  [[nodiscard]] bool ruled_out(const Vec3& a, const Vec3& b, const Vec3& c, double limit) const {
    if (!(limit < std::numeric_limits<double>::infinity())) return false;
    const Vec3 lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
    const Vec3 slo = p.cwiseMin(q), shi = p.cwiseMax(q);
    double boxes = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double g = interval_gap(lo[k], hi[k], slo[k], shi[k]);
      boxes += g * g;
    }
    const double scale = std::max({hi.cwiseAbs().maxCoeff(), lo.cwiseAbs().maxCoeff(), shi.cwiseAbs().maxCoeff(),
                                   slo.cwiseAbs().maxCoeff()});
    const double need = needed_gap(limit, radius, scale);
    if (boxes >= need * need) return true;
    const Vec3 n = (b - a).cross(c - a);
    const double dp = n.dot(p - a), dq = n.dot(q - a);
    return plane_rules_out(n, std::min(dp, dq), std::max(dp, dq), need);
  }
  // As the sphere's: the segment–box bound against the margin.
  [[nodiscard]] bool apart(const CompactBox& node, double allowance, double margin) const {
    return lower_bound(node, allowance) > margin;
  }
  [[nodiscard]] bool within(const Vec3& a, const Vec3& b, const Vec3& c, double margin) const {
    const double d = segment_distance(a, b, c).distance;
    return d <= radius || d - radius <= margin;
  }
};

// A box in the mesh frame; triangles are mapped into its own frame (`to_box`), where it is
// [-h, h] and its surface is 12 triangles.
struct PlacedBox {
  Pose to_box;  // mesh frame to box frame: the inverse of the shape's relative pose
  Pose to_mesh;
  Vec3 h;
  Obb box;

  PlacedBox(const Box& s, const Pose& rel)
      : to_box(rel.inverse()), to_mesh(rel), h(0.5 * s.size), box{rel.translation, rel.rotation, 0.5 * s.size} {}

  // Surface triangle s (0..11), made when needed rather than per query (collide rarely needs
  // one): triangles 2f and 2f + 1 cover face f, which is x_k = -h_k for f = 2k and x_k = h_k for
  // f = 2k + 1; with (i, j) = (k + 1, k + 2) mod 3, the face's corners (-,-), (+,-), (+,+), (-,+)
  // in (x_i, x_j) are split along the diagonal from the first to the third.
  [[nodiscard]] std::array<Vec3, 3> surface(int s) const {
    const int f = s / 2, k = f / 2, i = (k + 1) % 3, j = (k + 2) % 3;
    const double side = (f % 2 == 0 ? -1.0 : 1.0) * h[k];
    const auto corner = [&](double si, double sj) {
      Vec3 q;
      q[k] = side;
      q[i] = si * h[i];
      q[j] = sj * h[j];
      return q;
    };
    if (s % 2 == 0) return {corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0)};
    return {corner(-1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)};
  }

  [[nodiscard]] std::array<Vec3, 3> mapped(const Vec3& a, const Vec3& b, const Vec3& c) const {
    return {map_point(to_box, a), map_point(to_box, b), map_point(to_box, c)};
  }

  // Akenine-Möller (2001), "Fast 3D triangle-box overlap testing": the box and the triangle are
  // disjoint iff one of 13 axes separates them: the box's 3 face normals, the triangle's normal
  // and the 9 cross products of a box edge and a triangle edge. Here only a reject: true when an
  // axis separates them by more than `margin` plus the rounding allowance (kSeparationSlack), so
  // true means exactly disjoint beyond the margin (any vector that separates is a proof, however
  // rounded); a false leaves the decision to the exact test.
  [[nodiscard]] bool separated(const std::array<Vec3, 3>& v, double margin) const {
    const double scale = std::max({v[0].cwiseAbs().maxCoeff(), v[1].cwiseAbs().maxCoeff(), v[2].cwiseAbs().maxCoeff(),
                                   h.maxCoeff()}) + margin;
    const auto apart = [&](const Vec3& axis) {
      const double p0 = axis.dot(v[0]), p1 = axis.dot(v[1]), p2 = axis.dot(v[2]);
      const double lo = std::min({p0, p1, p2}), hi = std::max({p0, p1, p2});
      const Vec3 a = axis.cwiseAbs();
      const double reach = h.dot(a) + (margin > 0.0 ? margin * axis.norm() : 0.0) + kSeparationSlack * a.sum() * scale;
      return lo > reach || hi < -reach;
    };
    for (int k = 0; k < 3; ++k)
      if (apart(Vec3::Unit(k))) return true;
    const Vec3 e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
    if (apart(e[0].cross(-e[2]))) return true;
    for (const Vec3& ej : e) {
      // ej x (1,0,0), ej x (0,1,0), ej x (0,0,1)
      if (apart(Vec3(0.0, ej.z(), -ej.y())) || apart(Vec3(-ej.z(), 0.0, ej.x())) || apart(Vec3(ej.y(), -ej.x(), 0.0)))
        return true;
    }
    return false;
  }

  // Exact on the box-frame coordinates: a corner inside the closed box, or the triangle touching
  // the box surface (a triangle that touches the solid box without a corner in it crosses its
  // surface). Returns the index of the corner (0..2) or the surface triangle (3..14) found, -1
  // when they do not touch.
  [[nodiscard]] int touching(const std::array<Vec3, 3>& v) const {
    for (int i = 0; i < 3; ++i)
      if ((v[i].cwiseAbs().array() <= h.array()).all()) return i;
    for (int s = 0; s < 12; ++s) {
      const std::array<Vec3, 3> t = surface(s);
      if (tri_tri_overlap(t[0], t[1], t[2], v[0], v[1], v[2])) return 3 + s;
    }
    return -1;
  }

  // The faces (bit 2k for x_k = -h_k, 2k + 1 for x_k = h_k: surface triangles 2f and 2f + 1) with
  // a corner of the triangle strictly outside their plane. For a triangle disjoint from the box,
  // the closest points x (box) and y (triangle) have y - x in the normal cone at x, so x lies on a
  // face whose plane y, hence a corner, is strictly outside of: the least distance over these
  // faces is the least over all 12 surface triangles. Never empty for a disjoint triangle (each of
  // its corners is outside the box).
  [[nodiscard]] unsigned facing(const std::array<Vec3, 3>& v) const {
    unsigned faces = 0;
    for (int k = 0; k < 3; ++k) {
      const double lo = std::min({v[0][k], v[1][k], v[2][k]}), hi = std::max({v[0][k], v[1][k], v[2][k]});
      if (lo < -h[k]) faces |= 1u << (2 * k);
      if (hi > h[k]) faces |= 1u << (2 * k + 1);
    }
    return faces;
  }

  // The closest points of the box and a disjoint triangle (box frame, `faces` = facing(v)).
  // Two disjoint convex polytopes are closest at a vertex of one against the other or at an edge
  // of each (a face-interior pair is parallel and its distance is also met on a boundary), and the
  // box's closest point lies on a facing face (above). So the candidates are: each triangle corner
  // against the solid box (clamped to [-h, h], exact); each box corner of a facing face against
  // the triangle (closest_point_on_triangle, Ericson §5.1.5); each box edge of a facing face
  // against each triangle edge (Ericson §5.1.9, tri_lanes.hpp). Where two edges are nearly
  // parallel the segment solve may lose digits, but its points still lie on the segments, and the
  // pair's closest points are then at (or next to) an endpoint: a box edge's endpoints are corner
  // candidates, a triangle edge's are clamp candidates, each against the whole other solid. The
  // same minimum as the 12 surface triangles' tri_tri_distance, without their diagonals and face
  // projections.
  [[nodiscard]] TriangleDistance disjoint_distance(const std::array<Vec3, 3>& v, unsigned faces) const {
    double best = std::numeric_limits<double>::infinity();
    Vec3 on_box = Vec3::Zero(), on_triangle = Vec3::Zero();
    const auto offer = [&](const Vec3& x, const Vec3& y) {
      const double d2 = (x - y).squaredNorm();
      if (d2 < best) best = d2, on_box = x, on_triangle = y;
    };
    for (const Vec3& corner : v) offer(corner.cwiseMax(-h).cwiseMin(h), corner);
    // Corner m has x_k = h_k where bit k of m is set; face (k, side) holds the corners whose bit
    // k equals side.
    const auto corner = [&](unsigned m) {
      return Vec3((m & 1u) != 0 ? h.x() : -h.x(), (m & 2u) != 0 ? h.y() : -h.y(), (m & 4u) != 0 ? h.z() : -h.z());
    };
    const auto on_face = [&](unsigned m) {
      for (int k = 0; k < 3; ++k)
        if ((faces >> (2 * k + ((m >> k) & 1u)) & 1u) != 0) return true;
      return false;
    };
    // A candidate is skipped when the bounding boxes of its two parts are already at least the
    // best distance apart (squared, no root): most corners and edges of the box are.
    const auto boxes_gap2 = [](const Vec3& lo_a, const Vec3& hi_a, const Vec3& lo_b, const Vec3& hi_b) {
      double sum = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double g = interval_gap(lo_a[k], hi_a[k], lo_b[k], hi_b[k]);
        sum += g * g;
      }
      return sum;
    };
    const Vec3 lo = v[0].cwiseMin(v[1]).cwiseMin(v[2]), hi = v[0].cwiseMax(v[1]).cwiseMax(v[2]);
    for (unsigned m = 0; m < 8; ++m) {
      if (!on_face(m)) continue;
      const Vec3 x = corner(m);
      if (boxes_gap2(x, x, lo, hi) >= best) continue;
      offer(x, closest_point_on_triangle(x, v[0], v[1], v[2]).point);
    }
    // The edge along axis k from corner m (bit k clear) to m | (1 << k): on a facing face when
    // either of its corners' other two faces faces the triangle.
    for (int k = 0; k < 3; ++k) {
      for (unsigned m = 0; m < 8; ++m) {
        if ((m >> k & 1u) != 0) continue;
        bool facing_edge = false;
        for (int i = 0; i < 3; ++i)
          if (i != k && (faces >> (2 * i + ((m >> i) & 1u)) & 1u) != 0) facing_edge = true;
        if (!facing_edge) continue;
        const Vec3 p0 = corner(m), p1 = corner(m | (1u << k));
        const double e0[3] = {p0.x(), p0.y(), p0.z()}, e1[3] = {p1.x(), p1.y(), p1.z()};
        for (int j = 0; j < 3; ++j) {
          const Vec3& q0 = v[j];
          const Vec3& q1 = v[(j + 1) % 3];
          if (boxes_gap2(p0, p1, q0.cwiseMin(q1), q0.cwiseMax(q1)) >= best) continue;
          const double f0[3] = {q0.x(), q0.y(), q0.z()}, f1[3] = {q1.x(), q1.y(), q1.z()};
          double xp[3], xq[3];
          bool parallel = false;
          (void)query_detail::tri_segment_segment<double, bool>(e0, e1, f0, f1, xp, xq, parallel);
          offer(Vec3(xp[0], xp[1], xp[2]), Vec3(xq[0], xq[1], xq[2]));
        }
      }
    }
    TriangleDistance d;
    d.distance = std::max(std::sqrt(best), std::numeric_limits<double>::min());  // disjoint: never 0
    d.point_p = on_box;
    d.point_q = on_triangle;
    return d;
  }

  [[nodiscard]] Measure measure(const Vec3& a, const Vec3& b, const Vec3& c) const {
    const std::array<Vec3, 3> v = mapped(a, b, c);
    const int touch = separated(v, 0.0) ? -1 : touching(v);
    if (touch >= 0) {
      Vec3 point = touch < 3 ? v[touch] : tri_tri_distance(surface(touch - 3), v).point_q;
      point = to_mesh.apply(point);
      return {0.0, point, point};
    }
    const TriangleDistance best = disjoint_distance(v, facing(v));
    return {best.distance, to_mesh.apply(best.point_p), to_mesh.apply(best.point_q)};
  }
  [[nodiscard]] double lower_bound(const CompactBox& node, double allowance) const {
    return box_bound(node, box, allowance);
  }
  // Nothing in the node is within `margin`: the box test of obb_overlap() (exact for two boxes,
  // up to the allowance) separates the node's box from the shape's grown by the margin.
  [[nodiscard]] bool apart(const CompactBox& node, double allowance, double margin) const {
    const query_detail::BoxFrame f = frame_of(node, box);
    return !obb_overlap(f.c, f.d, node.half_extents_d(), box.half_extents, allowance + margin);
  }
  // Whether measure(a, b, c).distance is surely not below `limit` (box frame), as the capsule's:
  // the gap between the triangle's bounding box and the box, then the box's gap to the
  // triangle's plane (its extent along the normal n is n . 0 -+ |n| . h).
  [[nodiscard]] bool ruled_out(const Vec3& a, const Vec3& b, const Vec3& c, double limit) const {
    if (!(limit < std::numeric_limits<double>::infinity())) return false;
    const std::array<Vec3, 3> v = mapped(a, b, c);
    const Vec3 lo = v[0].cwiseMin(v[1]).cwiseMin(v[2]), hi = v[0].cwiseMax(v[1]).cwiseMax(v[2]);
    double boxes = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double g = interval_gap(lo[k], hi[k], -h[k], h[k]);
      boxes += g * g;
    }
    const double scale = std::max({hi.cwiseAbs().maxCoeff(), lo.cwiseAbs().maxCoeff(), h.maxCoeff()});
    const double need = needed_gap(limit, 0.0, scale);
    if (boxes >= need * need) return true;
    const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]);
    const double reach = n.cwiseAbs().dot(h), at = -n.dot(v[0]);
    return plane_rules_out(n, at - reach, at + reach, need);
  }
  [[nodiscard]] bool within(const Vec3& a, const Vec3& b, const Vec3& c, double margin) const {
    const std::array<Vec3, 3> v = mapped(a, b, c);
    if (separated(v, margin)) return false;
    if (touching(v) >= 0) return true;
    if (margin == 0.0) return false;
    return disjoint_distance(v, facing(v)).distance <= margin;  // measure()'s arithmetic
  }
};

#include "shape_convex.hpp"

template <class S>
struct Placed;
template <>
struct Placed<Sphere> {
  using type = PlacedSphere;
};
template <>
struct Placed<Capsule> {
  using type = PlacedCapsule;
};
template <>
struct Placed<Box> {
  using type = PlacedBox;
};
template <>
struct Placed<Cylinder> {
  using type = PlacedCylinder;
};
template <>
struct Placed<Convex> {
  using type = PlacedConvex;
};

void check_shape(const char* who, const Sphere& s) { require_size(who, "sphere radius", s.radius); }
void check_shape(const char* who, const Capsule& s) {
  require_size(who, "capsule radius", s.radius);
  require_size(who, "capsule length", s.length);
}
void check_shape(const char* who, const Cylinder& s) {
  require_size(who, "cylinder radius", s.radius);
  require_size(who, "cylinder length", s.length);
}
void check_shape(const char* who, const Convex& s) {
  if (s.vertices.size() < 4 || s.faces.size() < 4)
    throw InputError(std::string(who) + ": the convex shape has no solid hull (made by Convex(points))");
}
void check_shape(const char* who, const Box& s) {
  require_size(who, "box size x", s.size.x());
  require_size(who, "box size y", s.size.y());
  require_size(who, "box size z", s.size.z());
}

template <class S>
[[nodiscard]] typename Placed<S>::type place(const char* who, const S& shape, const Pose& ps, const Pose& pm) {
  check_shape(who, shape);
  require_valid_pose(ps, who, "the shape pose");
  require_valid_pose(pm, who, "the mesh pose");
  return typename Placed<S>::type(shape, relative_pose(pm, ps));
}

void check_options(const char* who, const QueryOptions& options) {
  if (!(options.margin >= 0.0) || !std::isfinite(options.margin))
    throw InputError(std::string(who) + ": margin must be finite and >= 0, got " + number(options.margin));
  if (options.solid) throw InputError(std::string(who) + ": the solid option is not available for shapes");
  if (options.contacts) throw InputError(std::string(who) + ": the contacts option is not available for shapes");
}

void check_options(const char* who, const DistanceOptions& options) {
  if (!(options.absolute_error >= 0.0) || !std::isfinite(options.absolute_error))
    throw InputError(std::string(who) + ": absolute_error must be finite and >= 0, got " +
                     number(options.absolute_error));
  if (!(options.relative_error >= 0.0) || !std::isfinite(options.relative_error))
    throw InputError(std::string(who) + ": relative_error must be finite and >= 0, got " +
                     number(options.relative_error));
  if (!(options.upper_bound >= 0.0))
    throw InputError(std::string(who) + ": upper_bound must be >= 0 (or infinity), got " + number(options.upper_bound));
  if (options.solid || options.signed_distance)
    throw InputError(std::string(who) + ": the solid and signed_distance options are not available for shapes");
}

void check_tree(const char* who, const Tree& tree, const Mesh& mesh) {
  if (tree.triangle_order.size() != mesh.triangles.size())
    throw InputError(std::string(who) + ": the tree was built over " + std::to_string(tree.triangle_order.size()) +
                     " triangles but the mesh has " + std::to_string(mesh.triangles.size()));
}

// The node box tests' allowance (as collide's box_allowance, collide.hpp): kBoxMargin for the
// rounding of the transform, kCompactBoxSlack for the float boxes' axes, kShapeSkew for the
// shape pose's rotation.
[[nodiscard]] double shape_allowance(const Tree& tree, const Obb& box) {
  const CompactBox& root = tree.nodes[0].box;
  return kBoxMargin * (query_detail::box_scale(root) + box.center.cwiseAbs().maxCoeff() + box.half_extents.maxCoeff()) +
         kCompactBoxSlack * (root.half_extents_d().maxCoeff() + box.half_extents.maxCoeff()) +
         kShapeSkew * box.half_extents.sum();
}

template <class P>
[[nodiscard]] ShapeQueryResult collide_tree(const P& placed, const Tree& tree, const Mesh& mesh,
                                            const QueryOptions& options) {
  ShapeQueryResult result;
  if (tree.nodes.empty()) return result;
  const double allowance = shape_allowance(tree, placed.box);
  const bool all = options.mode == QueryMode::all_pairs;
  query_detail::BasicPairStack<std::uint32_t> stack;
  stack.push(0);
  while (!stack.empty()) {
    const Node& node = tree.nodes[stack.pop()];
    ++result.stats.box_tests;
    if (placed.apart(node.box, allowance, options.margin)) continue;
    if (!node.is_leaf()) {
      // first_hit: the child whose center is nearer the shape's goes on top, as it is likelier to
      // hold a touching triangle (all_pairs visits both anyway).
      std::uint32_t near = node.first, far = node.first + 1;
      if (!all && (tree.nodes[far].box.center_d() - placed.box.center).squaredNorm() <
                      (tree.nodes[near].box.center_d() - placed.box.center).squaredNorm())
        std::swap(near, far);
      stack.push(far);
      stack.push(near);
      continue;
    }
    for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
      const std::uint32_t t = tree.triangle_order[k];
      const auto [a, b, c] = mesh.corners(t);
      ++result.stats.triangle_tests;
      if (!placed.within(a, b, c, options.margin)) continue;
      result.hit = true;
      result.triangles.push_back(t);
      if (!all) return result;
    }
  }
  std::sort(result.triangles.begin(), result.triangles.end());
  return result;
}

template <class P>
[[nodiscard]] ShapeQueryResult collide_all(const P& placed, const Mesh& mesh, const QueryOptions& options) {
  ShapeQueryResult result;
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto [a, b, c] = mesh.corners(t);
    ++result.stats.triangle_tests;
    if (!placed.within(a, b, c, options.margin)) continue;
    result.hit = true;
    result.triangles.push_back(t);
    if (options.mode == QueryMode::first_hit) break;
  }
  return result;
}

// The best triangle so far, mesh frame.
struct Best {
  bool found = false;
  std::uint32_t triangle = 0;
  Measure at;
};

[[nodiscard]] ShapeDistanceResult to_result(const Best& best, const Pose& pm, double upper_bound,
                                            const DistanceStats& stats) {
  ShapeDistanceResult r;
  r.stats = stats;
  if (!best.found) {
    r.distance = upper_bound;
    r.beyond_upper_bound = true;
    return r;
  }
  r.distance = best.at.distance;
  r.intersecting = best.at.distance == 0.0;
  r.triangle = best.triangle;
  r.point_shape = pm.apply(best.at.point_shape);
  r.point_mesh = pm.apply(best.at.point_mesh);
  return r;
}

// Best first (the node of least bound next): the shape's lower_bound() of the node (box_bound(),
// or the sphere's and capsule's point– and segment–box bounds), which never exceeds the distance from the shape to the node's
// triangles. A node is skipped when
// its bound is at least the upper bound, or when the best so far is within the allowed error of
// it; the search ends at a touching triangle.
template <class P>
[[nodiscard]] ShapeDistanceResult distance_tree(const P& placed, const Tree& tree, const Mesh& mesh, const Pose& pm,
                                                const DistanceOptions& options) {
  Best best;
  DistanceStats stats;
  if (tree.nodes.empty()) {
    ShapeDistanceResult r;
    return r;
  }
  if (!(options.upper_bound > 0.0)) return to_result(best, pm, options.upper_bound, stats);
  const double allowance = shape_allowance(tree, placed.box);
  const auto bound = [&](std::uint32_t n) {
    ++stats.node_pairs;
    return placed.lower_bound(tree.nodes[n].box, allowance);
  };
  const auto skip = [&](double b) {
    if (b >= options.upper_bound) return true;
    return best.found && best.at.distance <= b * (1.0 + options.relative_error) + options.absolute_error;
  };
  using Pending = std::pair<double, std::uint32_t>;
  const auto later = [](const Pending& x, const Pending& y) { return x.first > y.first; };
  std::vector<Pending> heap;
  heap.reserve(64);
  const auto push = [&](const Pending& p) {
    heap.push_back(p);
    std::push_heap(heap.begin(), heap.end(), later);
  };
  // `next` always has the least bound of the nodes left: the nearer child of an internal node is
  // taken straight on when no queued node is nearer, without a trip through the heap.
  Pending next{bound(0), 0};
  for (;;) {
    if (skip(next.first)) break;  // the least bound left: every other node is skipped too
    const Node& node = tree.nodes[next.second];
    if (!node.is_leaf()) {
      Pending near{bound(node.first), node.first}, far{bound(node.first + 1), node.first + 1};
      if (far.first < near.first) std::swap(near, far);
      if (!skip(far.first)) push(far);
      if (!skip(near.first)) {
        if (heap.empty() || near.first <= heap.front().first) {
          next = near;
          continue;
        }
        push(near);
      }
    } else {
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        const std::uint32_t t = tree.triangle_order[k];
        const auto [a, b, c] = mesh.corners(t);
        if constexpr (requires { placed.ruled_out(a, b, c, 0.0); }) {
          if (placed.ruled_out(a, b, c, best.found ? best.at.distance : options.upper_bound)) continue;
        }
        ++stats.triangle_pairs;
        const Measure m = placed.measure(a, b, c);
        if (best.found ? m.distance < best.at.distance : m.distance < options.upper_bound) best = {true, t, m};
      }
      if (best.found && best.at.distance == 0.0) break;  // touching: nothing is closer
    }
    if (heap.empty()) break;
    std::pop_heap(heap.begin(), heap.end(), later);
    next = heap.back();
    heap.pop_back();
  }
  return to_result(best, pm, options.upper_bound, stats);
}

template <class P>
[[nodiscard]] ShapeDistanceResult distance_all(const P& placed, const Mesh& mesh, const Pose& pm) {
  Best best;
  DistanceStats stats;
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto [a, b, c] = mesh.corners(t);
    ++stats.triangle_pairs;
    const Measure m = placed.measure(a, b, c);
    if (!best.found || m.distance < best.at.distance) best = {true, t, m};
  }
  if (!best.found) return {};
  return to_result(best, pm, 0.0, stats);
}

template <class S>
ShapeQueryResult collide_impl(const S& shape, const Pose& ps, const Tree& tree, const Mesh& mesh, const Pose& pm,
                              const QueryOptions& options) {
  constexpr const char* who = "collide";
  check_options(who, options);
  check_tree(who, tree, mesh);
  return collide_tree(place(who, shape, ps, pm), tree, mesh, options);
}

template <class S>
ShapeDistanceResult distance_impl(const S& shape, const Pose& ps, const Tree& tree, const Mesh& mesh, const Pose& pm,
                                  const DistanceOptions& options) {
  constexpr const char* who = "distance";
  check_options(who, options);
  check_tree(who, tree, mesh);
  return distance_tree(place(who, shape, ps, pm), tree, mesh, pm, options);
}

template <class S>
ShapeQueryResult collide_brute_impl(const S& shape, const Pose& ps, const Mesh& mesh, const Pose& pm,
                                    const QueryOptions& options) {
  constexpr const char* who = "collide_brute_force";
  check_options(who, options);
  return collide_all(place(who, shape, ps, pm), mesh, options);
}

template <class S>
ShapeDistanceResult distance_brute_impl(const S& shape, const Pose& ps, const Mesh& mesh, const Pose& pm,
                                        const DistanceOptions& options) {
  constexpr const char* who = "distance_brute_force";
  check_options(who, options);
  return distance_all(place(who, shape, ps, pm), mesh, pm);
}

}  // namespace

Sphere::Sphere(double r) : radius(r) { require_size("Sphere", "radius", r); }

Box::Box(double x, double y, double z) : Box(Vec3(x, y, z)) {}

Box::Box(const Vec3& s) : size(s) {
  require_size("Box", "size x", s.x());
  require_size("Box", "size y", s.y());
  require_size("Box", "size z", s.z());
}

Capsule::Capsule(double r, double l) : radius(r), length(l) {
  require_size("Capsule", "radius", r);
  require_size("Capsule", "length", l);
}

Obb bounding_box(const Sphere& shape) { return {Vec3::Zero(), Mat3::Identity(), Vec3::Constant(shape.radius)}; }
Obb bounding_box(const Box& shape) { return {Vec3::Zero(), Mat3::Identity(), 0.5 * shape.size}; }
Obb bounding_box(const Capsule& shape) {
  return {Vec3::Zero(), Mat3::Identity(), Vec3(shape.radius, shape.radius, 0.5 * shape.length + shape.radius)};
}

// The overloads: one template per query, instantiated for each shape.
#define TIGHTBVH_SHAPE_QUERIES(S)                                                                                   \
  ShapeQueryResult collide(const S& shape, const Pose& ps, const Tree& tree, const Mesh& mesh, const Pose& pm,     \
                           const QueryOptions& options) {                                                          \
    return collide_impl(shape, ps, tree, mesh, pm, options);                                                       \
  }                                                                                                                \
  ShapeQueryResult collide(const S& shape, const Pose& ps, const Model& model, const Pose& pm,                     \
                           const QueryOptions& options) {                                                          \
    return collide_impl(shape, ps, model.tree(), model.mesh(), pm, options);                                       \
  }                                                                                                                \
  ShapeDistanceResult distance(const S& shape, const Pose& ps, const Tree& tree, const Mesh& mesh, const Pose& pm, \
                               const DistanceOptions& options) {                                                   \
    return distance_impl(shape, ps, tree, mesh, pm, options);                                                      \
  }                                                                                                                \
  ShapeDistanceResult distance(const S& shape, const Pose& ps, const Model& model, const Pose& pm,                 \
                               const DistanceOptions& options) {                                                   \
    return distance_impl(shape, ps, model.tree(), model.mesh(), pm, options);                                      \
  }                                                                                                                \
  ShapeQueryResult collide_brute_force(const S& shape, const Pose& ps, const Mesh& mesh, const Pose& pm,           \
                                       const QueryOptions& options) {                                              \
    return collide_brute_impl(shape, ps, mesh, pm, options);                                                       \
  }                                                                                                                \
  ShapeDistanceResult distance_brute_force(const S& shape, const Pose& ps, const Mesh& mesh, const Pose& pm,       \
                                           const DistanceOptions& options) {                                       \
    return distance_brute_impl(shape, ps, mesh, pm, options);                                                      \
  }

TIGHTBVH_SHAPE_QUERIES(Sphere)
TIGHTBVH_SHAPE_QUERIES(Box)
TIGHTBVH_SHAPE_QUERIES(Capsule)
TIGHTBVH_SHAPE_QUERIES(Cylinder)
TIGHTBVH_SHAPE_QUERIES(Convex)

#undef TIGHTBVH_SHAPE_QUERIES

}  // namespace tightbvh
