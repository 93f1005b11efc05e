#include "bopt.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "frame.hpp"

namespace tightbvh::fit_detail {

namespace {

// The Bopt box: first axis a, the rectangle (in the (u, w) plane) as the other two.
AxisBox box_from(const Mat3& frame, const Rect2& rect, double lo, double hi) {
  const Vec3 a = frame.col(0), u = frame.col(1), w = frame.col(2);
  AxisBox box;
  box.axes.col(0) = a;
  box.axes.col(1) = rect.axis.x() * u + rect.axis.y() * w;
  box.axes.col(2) = a.cross(box.axes.col(1));
  box.lo = Vec3(lo, rect.min.x(), rect.min.y());
  box.hi = Vec3(hi, rect.max.x(), rect.max.y());
  return box;
}

}  // namespace

namespace {

// Projects every point; `small_without_hull`: sets of at most kMinAreaRectOfPointsMax points get
// their rectangle from min_area_rect_of_points, without the 2D hull.
AxisBox project_all(std::span<const Vec3> points, const Vec3& origin, const Vec3& v, BoptScratch& s,
                    bool small_without_hull) {
  const Mat3 frame = frame_from_axis(v);
  const Vec3 a = frame.col(0), u = frame.col(1), w = frame.col(2);
  s.projected.resize(points.size());
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 p = points[i] - origin;
    const double t = a.dot(p);
    lo = std::min(lo, t);
    hi = std::max(hi, t);
    s.projected[i] = Vec2(u.dot(p), w.dot(p));
  }
  if (small_without_hull && points.size() <= kMinAreaRectOfPointsMax)
    return box_from(frame, min_area_rect_of_points(s.projected), lo, hi);
  const std::size_t m = convex_hull_2d(s.projected, s.chain);
  return box_from(frame, min_area_rect(std::span<const Vec2>(s.projected.data(), m)), lo, hi);
}

// Bopt for a geometry without hull: project every point, extents along v by a scan.
AxisBox bopt_points(const HullGeometry& g, const Vec3& v, BoptScratch& s) {
  return project_all(g.local, Vec3::Zero(), v, s, false);
}

}  // namespace

AxisBox bopt_of_points(std::span<const Vec3> points, const Vec3& origin, const Vec3& v, BoptScratch& s) {
  return project_all(points, origin, v, s, true);
}

AxisBox bopt(const HullGeometry& g, const Vec3& v, BoptScratch& s) {
  ++s.calls;
  if (g.hull == nullptr) return bopt_points(g, v, s);
  const ConvexHull3& hull = *g.hull;
  const Mat3 frame = frame_from_axis(v);
  const Vec3 a = frame.col(0), u = frame.col(1), w = frame.col(2);

  // Silhouette: edges between a face facing +a and a face facing -a (with a small tolerance
  // so that faces parallel to a never hide a silhouette vertex). The projection of the
  // silhouette's vertices contains every vertex of the projected hull.
  const std::size_t nf = hull.faces.size();
  s.face_dot.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) s.face_dot[f] = a.dot(hull.face_normals[f]);
  if (s.stamp.size() != g.local.size()) {
    s.stamp.assign(g.local.size(), 0);
    s.epoch = 0;
  }
  if (++s.epoch == 0) {
    std::fill(s.stamp.begin(), s.stamp.end(), 0);
    s.epoch = 1;
  }
  s.projected.clear();
  constexpr double tol = 1e-12;
  for (const HullEdge& e : hull.edges) {
    const double d0 = s.face_dot[e.face[0]], d1 = s.face_dot[e.face[1]];
    if ((d0 > tol && d1 > tol) || (d0 < -tol && d1 < -tol)) continue;
    for (std::uint32_t vi : e.vertex) {
      if (s.stamp[vi] == s.epoch) continue;
      s.stamp[vi] = s.epoch;
      const Vec3& p = g.local[vi];
      s.projected.emplace_back(u.dot(p), w.dot(p));
    }
  }
  const std::size_t m = convex_hull_2d(s.projected, s.chain);
  const Rect2 rect = min_area_rect(std::span<const Vec2>(s.projected.data(), m));

  // The extent along a by a scan of all hull vertices, not by hill climbing on the hull graph:
  // a climb can stop at a vertex whose better neighbour ties with it in floating point (a vertex
  // bulging out of a flat facet by less than the rounding), far from the true extreme. The scan
  // costs less than the silhouette pass above (V < E).
  const Extent along = extent_along(g, a);
  return box_from(frame, rect, along.lo, along.hi);
}

AxisBox improve(const HullGeometry& g, AxisBox box, BoptScratch& scratch, double min_gain, int max_rounds,
                bool from_bopt) {
  double volume = box.volume();
  // A box made by Bopt(S, {v}) has v as its first axis, and re-solving along it gives the same
  // box again: skip that axis when the box came from Bopt, and after any accepted candidate
  // (which is a Bopt box along the axis it was made from).
  bool skip_first = from_bopt;
  for (int round = 0; round < max_rounds; ++round) {
    const double start = volume;
    for (int axis = 0; axis < 3; ++axis) {
      if (axis == 0 && skip_first) continue;
      const AxisBox candidate = bopt(g, box.axes.col(axis), scratch);
      const double cv = candidate.volume();
      if (cv < volume) {
        box = candidate;
        volume = cv;
        skip_first = true;
      }
    }
    if (!(volume < start * (1.0 - min_gain))) break;
  }
  return box;
}

}  // namespace tightbvh::fit_detail
