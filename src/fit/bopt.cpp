#include "bopt.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "frame.hpp"
#include "../geometry/predicates.hpp"

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
// their rectangle from min_area_rect_of_points, without the 2D hull (the callers pass it only for
// sets small enough to gain from that).
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
// Hull-free sets of at most this many points take their rectangle from min_area_rect_of_points
// (its <= 15 pair directions four per AVX instruction, two per SSE2 one) instead of the 2D hull's
// sort and the calipers: the same minimum area up to rounding. Measured on approx trees
// (instructions of build(), AVX): 6 points: knot1 -1.4%, cow -2.2%; 5: -1.0%, -1.6%; 7 and 8
// gain no more, and with SSE2 lanes alone 6 is where the pairs stop paying. One threshold for all
// CPUs, so that trees do not depend on the instruction set (docs/design-notes/fitters.md,
// "Bopt: the silhouette as one cycle, small polygons by an edge scan").
constexpr std::size_t kPairSearchMax = 6;
static_assert(kPairSearchMax <= kMinAreaRectOfPointsMax);

AxisBox bopt_points(const HullGeometry& g, const Vec3& v, BoptScratch& s) {
  return project_all(g.local, Vec3::Zero(), v, s, g.local.size() <= kPairSearchMax);
}

}  // namespace

AxisBox bopt_of_points(std::span<const Vec3> points, const Vec3& origin, const Vec3& v, BoptScratch& s) {
  return project_all(points, origin, v, s, true);
}

namespace {

// A fresh epoch for scratch.stamp (sized to the geometry's vertices).
void next_epoch(const HullGeometry& g, BoptScratch& s) {
  if (s.stamp.size() != g.local.size()) {
    s.stamp.assign(g.local.size(), 0);
    s.epoch = 0;
  }
  if (++s.epoch == 0) {
    std::fill(s.stamp.begin(), s.stamp.end(), 0);
    s.epoch = 1;
  }
}

int orient(const Vec2& a, const Vec2& b, const Vec2& c) {
  return detail::orient2d(a.x(), a.y(), b.x(), b.y(), c.x(), c.y());
}

// Appends q to the convex chain `poly` (the silhouette walk): drops repeated points and points
// exactly on the line of their neighbours (as convex_hull_2d does); false on a right turn or a
// chain that doubles back on its line (rounding broke the cycle).
bool push_convex(std::vector<Vec2>& poly, const Vec2& q) {
  if (!poly.empty() && poly.back() == q) return true;
  while (poly.size() >= 2) {
    const Vec2& a = poly[poly.size() - 2];
    const Vec2& b = poly.back();
    const int o = orient(a, b, q);
    if (o > 0) break;
    if (o < 0 || (b - a).dot(q - b) <= 0.0) return false;
    poly.pop_back();  // b lies on the segment from a to q
  }
  poly.push_back(q);
  return true;
}

}  // namespace

namespace {

// The silhouette's vertices in cycle order into s.cycle, by classifying every face and edge:
// O(F + E). False when the boundary of the front faces is not one cycle.
bool cycle_by_edges(const HullGeometry& g, const Vec3& a, BoptScratch& s) {
  const ConvexHull3& hull = *g.hull;
  const std::size_t nf = hull.faces.size();
  s.front.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) s.front[f] = a.dot(hull.face_normals[f]) > 0.0 ? 1 : 0;
  next_epoch(g, s);
  if (s.next.size() < g.local.size()) s.next.resize(g.local.size());
  // Each edge is listed counter-clockwise as seen from outside its face[0]; a silhouette edge is
  // walked as its front face lists it, which is counter-clockwise in the (u, w) plane.
  std::size_t count = 0;
  std::uint32_t start = 0;
  for (const HullEdge& e : hull.edges) {
    const std::uint8_t f0 = s.front[e.face[0]], f1 = s.front[e.face[1]];
    if (f0 == f1) continue;
    const std::uint32_t from = f0 ? e.vertex[0] : e.vertex[1];
    if (s.stamp[from] == s.epoch) return false;  // two outgoing edges: a pinched boundary
    s.stamp[from] = s.epoch;
    s.next[from] = f0 ? e.vertex[1] : e.vertex[0];
    start = from;
    ++count;
  }
  if (count < 3) return false;
  s.cycle.clear();
  std::uint32_t v = start;
  for (std::size_t step = 0; step < count; ++step) {
    if (s.stamp[v] != s.epoch || (step > 0 && v == start)) return false;  // not one cycle through all edges
    s.cycle.push_back(v);
    v = s.next[v];
  }
  return v == start;
}

// The same cycle by walking it on the face adjacency (g.face_adjacent): from the vertex farthest
// along u (its projection is on the outline, so it is on the silhouette), each next silhouette
// edge is found by turning around the current end vertex through the front faces. O(m d) for m
// silhouette vertices of degree d, instead of O(F + E). The faces are classified as in
// cycle_by_edges (the same expression), so the cycle is the same; unlike the edge pass the walk
// cannot see a second loop through a pinched vertex, which only rounding of faces seen edge on
// makes (their projections have no area, so the outline loses nothing of note).
bool cycle_by_walk(const HullGeometry& g, const Vec3& a, const Vec3& u, BoptScratch& s) {
  const ConvexHull3& hull = *g.hull;
  const auto front = [&](std::uint32_t f) { return a.dot(hull.face_normals[f]) > 0.0; };
  // The farthest vertex by hill climbing on the hull's vertex graph from the last walk's start on
  // this geometry (a local maximum of a linear function on a convex polytope's graph is global),
  // not by a scan of every vertex (-2% of an approx tree build). Where rounding stops the climb
  // short, the vertex is not on the silhouette within rounding either: the turn below finds no
  // silhouette edge there and bopt() sorts. The hint lives in the geometry, reset with it, so a
  // fit does not depend on what the same scratch fitted before (thread counts).
  const std::uint32_t start = extreme_vertex(g, u, g.walk_hint < g.local.size() ? g.walk_hint : 0);
  g.walk_hint = start;
  const auto position = [&](std::uint32_t f, std::uint32_t v) {
    const auto& fv = hull.faces[f];
    return fv[0] == v ? 0u : fv[1] == v ? 1u : 2u;
  };
  constexpr int kMaxTurn = 256;
  // The silhouette edge leaving `start`: turn around it until a front face has a non-front face
  // across its edge that leaves `start` (slot: the edge from vertex slot + 1 to slot + 2).
  std::uint32_t f = g.vertex_face[start];
  std::uint32_t slot = (position(f, start) + 2) % 3;
  bool found = false;
  for (int turn = 0; turn < kMaxTurn && !found; ++turn) {
    const std::uint32_t across = g.face_adjacent[f][slot];
    if (front(f) && !front(across)) {
      found = true;
      break;
    }
    f = across;
    slot = (position(f, start) + 2) % 3;
  }
  if (!found) return false;
  s.cycle.clear();
  for (std::size_t step = 0; step <= g.local.size(); ++step) {
    s.cycle.push_back(hull.faces[f][(slot + 1) % 3]);
    const std::uint32_t t = hull.faces[f][(slot + 2) % 3];
    if (t == start) return s.cycle.size() >= 3;
    // The next silhouette edge leaves t: from the edge of f that leaves t, turn through front faces.
    slot = (slot + 1) % 3;
    int turn = 0;
    for (; turn < kMaxTurn; ++turn) {
      const std::uint32_t across = g.face_adjacent[f][slot];
      if (!front(across)) break;
      f = across;
      slot = (position(f, t) + 2) % 3;
    }
    if (turn == kMaxTurn) return false;
  }
  return false;
}

}  // namespace

bool silhouette_cycle(const HullGeometry& g, const Vec3& a, const Vec3& u, const Vec3& w, BoptScratch& s) {
  // A face is front when it faces +a strictly; coplanar triangles share one normal, so a facet
  // is never split. In exact arithmetic the front faces form a disk whose boundary projects
  // one to one onto the boundary of the projected hull (Section 6.3's Bopt needs only that).
  const bool walk = !g.face_adjacent.empty();
  if (!(walk ? cycle_by_walk(g, a, u, s) : cycle_by_edges(g, a, s))) return false;
  auto& poly = s.projected;
  poly.clear();
  for (const std::uint32_t v : s.cycle) {
    const Vec3& p = g.local[v];
    if (!push_convex(poly, Vec2(u.dot(p), w.dot(p)))) return false;
  }
  // Close the cycle: its first point may repeat the last or lie on the line of its neighbours.
  if (poly.size() >= 2 && poly.back() == poly.front()) poly.pop_back();
  for (;;) {
    const std::size_t m = poly.size();
    if (m < 3) return false;
    int o = orient(poly[m - 2], poly[m - 1], poly[0]);
    if (o < 0) return false;
    if (o == 0) {
      if ((poly[m - 1] - poly[m - 2]).dot(poly[0] - poly[m - 1]) <= 0.0) return false;
      poly.pop_back();
      continue;
    }
    o = orient(poly[m - 1], poly[0], poly[1]);
    if (o < 0) return false;
    if (o == 0) {
      if ((poly[0] - poly[m - 1]).dot(poly[1] - poly[0]) <= 0.0) return false;
      poly.erase(poly.begin());
      continue;
    }
    break;
  }
  // Every turn is now strictly left; the polygon is simple (wound once) iff x changes direction
  // exactly twice along it. Then start where convex_hull_2d starts: the smallest (x, y).
  const std::size_t m = poly.size();
  int changes = 0, last = 0;
  std::size_t lowest = 0;
  for (std::size_t i = 0; i < m; ++i) {
    const double dx = poly[i + 1 == m ? 0 : i + 1].x() - poly[i].x();
    const int dir = (dx > 0.0) - (dx < 0.0);
    if (dir != 0) {
      if (last != 0 && dir != last) ++changes;
      last = dir;
    }
    if (poly[i].x() < poly[lowest].x() || (poly[i].x() == poly[lowest].x() && poly[i].y() < poly[lowest].y()))
      lowest = i;
  }
  // The loop does not compare the last direction with the first: add that change.
  int first = 0;
  for (std::size_t i = 0; i < m && first == 0; ++i) {
    const double dx = poly[i + 1 == m ? 0 : i + 1].x() - poly[i].x();
    first = (dx > 0.0) - (dx < 0.0);
  }
  if (first != last) ++changes;
  if (changes != 2) return false;
  std::rotate(poly.begin(), poly.begin() + static_cast<std::ptrdiff_t>(lowest), poly.end());
  return true;
}

std::size_t silhouette_sorted(const HullGeometry& g, const Vec3& a, const Vec3& u, const Vec3& w, BoptScratch& s) {
  const ConvexHull3& hull = *g.hull;
  // Silhouette: edges between a face facing +a and a face facing -a (with a small tolerance
  // so that faces parallel to a never hide a silhouette vertex). The projection of the
  // silhouette's vertices contains every vertex of the projected hull.
  const std::size_t nf = hull.faces.size();
  s.face_dot.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) s.face_dot[f] = a.dot(hull.face_normals[f]);
  next_epoch(g, s);
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
  return convex_hull_2d(s.projected, s.chain);
}

AxisBox bopt(const HullGeometry& g, const Vec3& v, BoptScratch& s) {
  ++s.calls;
  if (g.hull == nullptr) return bopt_points(g, v, s);
  const Mat3 frame = frame_from_axis(v);
  const Vec3 a = frame.col(0), u = frame.col(1), w = frame.col(2);
  std::size_t m = 0;
  if (silhouette_cycle(g, a, u, w, s)) {
    m = s.projected.size();
  } else {
    ++s.sorted_silhouettes;
    m = silhouette_sorted(g, a, u, w, s);
  }
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
