

// 3D convex hull by Quickhull (Barber, Dobkin & Huhdanpaa 1996, "The Quickhull algorithm for
// convex hulls", ACM TOMS 22(4); the class is in quickhull.cpp) with exact orientation
// predicates; 2D hull by Andrew's monotone chain. This file: the driver convex_hull(), the
// conversion to ConvexHull3, planar and lower-dimensional sets, affine_dimension().
//
// Robustness: a point is above a face only when orient3d is strictly positive, evaluated
// exactly (src/geometry/predicates.hpp). The hull under construction is then always convex in exact
// arithmetic, the faces a point sees form a disk whose boundary (the horizon) is a simple cycle,
// and the new faces of the cone are never degenerate. Floating point only ranks the outside
// points of a face (to pick the farthest) and gives the face normals.
#include "tightbvh/hull.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "predicates.hpp"
#include "quickhull.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh {

void ConvexHull3::clear() {
  dimension = 0;
  vertices.clear();
  input_index.clear();
  faces.clear();
  face_normals.clear();
  edges.clear();
  neighbor_offsets.clear();
  neighbors.clear();
  plane_normal = Vec3::UnitZ();
}

HullWorkspace::HullWorkspace() : state_(std::make_unique<State>()) {}
HullWorkspace::~HullWorkspace() = default;
HullWorkspace::HullWorkspace(HullWorkspace&&) noexcept = default;
HullWorkspace& HullWorkspace::operator=(HullWorkspace&&) noexcept = default;

namespace {

using quickhull::Face;
using quickhull::kNone;
using quickhull::OutsidePoint;
using quickhull::Quickhull;
using State = HullWorkspace::State;


std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// The vertex of `face` that is not on its edge shared with face `other`.
std::uint32_t vertex_opposite(const Face& face, std::uint32_t other) {
  for (std::uint32_t k = 0; k < 3; ++k)
    if (face.adjacent[k] == other) return face.vertex[k];
  return face.vertex[0];
}

// Converts the quickhull faces into `out` (vertices in input order, faces, edges, one normal
// per coplanar group). Returns false when some vertex is not strictly extreme: a vertex is a
// corner of the polytope iff at least three of its edges join faces on different planes (with
// none it lies inside a flat facet; with two, both edges lie on the line where the two planes
// meet, so it lies inside an edge).
bool convert(std::span<const Vec3> points, State& s, ConvexHull3& out) {
  const std::size_t slots = s.faces.size();
  if (s.vertex_of.size() < points.size()) s.vertex_of.resize(points.size(), kNone);
  out.vertices.clear();
  out.input_index.clear();
  out.faces.clear();
  out.face_normals.clear();
  out.edges.clear();
  s.face_index.assign(slots, kNone);
  for (std::uint32_t f = 0; f < slots; ++f) {
    const Face& face = s.faces[f];
    if (!face.alive) continue;
    s.face_index[f] = static_cast<std::uint32_t>(out.faces.size());
    out.faces.push_back(face.vertex);  // point ids for now
    for (std::uint32_t v : face.vertex)
      if (s.vertex_of[v] == kNone) s.vertex_of[v] = 0, out.input_index.push_back(v);
  }
  std::sort(out.input_index.begin(), out.input_index.end());
  for (std::size_t i = 0; i < out.input_index.size(); ++i) {
    s.vertex_of[out.input_index[i]] = static_cast<std::uint32_t>(i);
    out.vertices.push_back(points[out.input_index[i]]);
  }
  for (auto& face : out.faces)
    for (std::uint32_t& v : face) v = s.vertex_of[v];
  for (std::uint32_t id : out.input_index) s.vertex_of[id] = kNone;  // clean for the next call

  // Edges; coplanar neighbours (exactly) join one group.
  s.group.resize(slots);
  for (std::uint32_t f = 0; f < slots; ++f) s.group[f] = f;
  s.sharp_edges.assign(out.vertices.size(), 0);
  for (std::uint32_t f = 0; f < slots; ++f) {
    const Face& face = s.faces[f];
    if (!face.alive) continue;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t g = face.adjacent[k];
      if (g < f) continue;
      const std::uint32_t fi = s.face_index[f], gi = s.face_index[g];
      HullEdge e;
      e.vertex = {out.faces[fi][(k + 1) % 3], out.faces[fi][(k + 2) % 3]};
      e.face = {fi, gi};
      out.edges.push_back(e);
      if (face.plane_id == s.faces[g].plane_id || face.plane.sign(points[vertex_opposite(s.faces[g], f)]) == 0) {
        s.group[find_root(s.group, f)] = find_root(s.group, g);
      } else {
        ++s.sharp_edges[e.vertex[0]];
        ++s.sharp_edges[e.vertex[1]];
      }
    }
  }
  bool all_extreme = true;
  for (std::uint32_t count : s.sharp_edges) all_extreme = all_extreme && count >= 3;
  if (!all_extreme) return false;

  // One normal per group, from its best-conditioned triangle (the longest rounded cross product).
  s.group_best.assign(slots, kNone);
  for (std::uint32_t f = 0; f < slots; ++f) {
    if (!s.faces[f].alive) continue;
    std::uint32_t& best = s.group_best[find_root(s.group, f)];
    if (best == kNone || s.faces[f].plane.normal.squaredNorm() > s.faces[best].plane.normal.squaredNorm()) best = f;
  }
  // Its normal from the accurate cross product: a group that is a single sliver has a rounded
  // normal that is noise or zero.
  s.group_normal.resize(slots);
  for (std::uint32_t f = 0; f < slots; ++f) {
    if (!s.faces[f].alive || s.group_best[f] == kNone) continue;
    const auto& v = s.faces[s.group_best[f]].vertex;
    s.group_normal[f] = detail::accurate_normal(points[v[0]], points[v[1]], points[v[2]]).normalized();
  }
  for (std::uint32_t f = 0; f < slots; ++f)
    if (s.faces[f].alive) out.face_normals.push_back(s.group_normal[find_root(s.group, f)]);
  return true;
}

// The strictly extreme vertices of a hull that convert() rejected, as the next candidates.
void keep_extreme_vertices(const ConvexHull3& out, State& s) {
  s.candidates.clear();
  for (std::size_t v = 0; v < out.vertices.size(); ++v)
    if (s.sharp_edges[v] >= 3) s.candidates.push_back(out.input_index[v]);
}

// Four candidates spanning a tetrahedron (exactly): the first point, the first different one,
// the first not on their line, the first not on their plane. False when there are none.
bool exact_simplex(std::span<const Vec3> points, std::span<const std::uint32_t> ids,
                   std::array<std::uint32_t, 4>& t) {
  std::size_t i = 0;
  const auto find = [&](auto&& accept) {
    for (; i < ids.size(); ++i)
      if (accept(points[ids[i]])) return true;
    return false;
  };
  if (ids.empty()) return false;
  t[0] = ids[0];
  const Vec3 &a = points[t[0]];
  if (!find([&](const Vec3& q) { return q != a; })) return false;
  t[1] = ids[i];
  const Vec3& b = points[t[1]];
  if (!find([&](const Vec3& q) { return !detail::collinear(a, b, q); })) return false;
  t[2] = ids[i];
  const detail::OrientPlane plane(a, b, points[t[2]]);
  if (!find([&](const Vec3& q) { return plane.sign(q) != 0; })) return false;
  t[3] = ids[i];
  return true;
}

void build_adjacency(ConvexHull3& out, State& s) {
  const std::size_t n = out.vertices.size();
  s.degree.assign(n, 0);
  for (const HullEdge& e : out.edges) {
    ++s.degree[e.vertex[0]];
    ++s.degree[e.vertex[1]];
  }
  out.neighbor_offsets.assign(n + 1, 0);
  for (std::size_t v = 0; v < n; ++v) out.neighbor_offsets[v + 1] = out.neighbor_offsets[v] + s.degree[v];
  out.neighbors.assign(out.neighbor_offsets[n], 0);
  for (std::size_t v = 0; v < n; ++v) s.degree[v] = out.neighbor_offsets[v];
  for (const HullEdge& e : out.edges) {
    out.neighbors[s.degree[e.vertex[0]]++] = e.vertex[1];
    out.neighbors[s.degree[e.vertex[1]]++] = e.vertex[0];
  }
}

// Planar (or nearly planar) input: the 2D hull in the plane through the set.
void planar_hull(std::span<const Vec3> points, const Vec3& origin, const Vec3& normal, State& s, ConvexHull3& out) {
  const Vec3 u = normal.unitOrthogonal();
  const Vec3 w = normal.cross(u);
  s.plane_points.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 d = points[i] - origin;
    s.plane_points[i] = Vec2(u.dot(d), w.dot(d));
  }
  // Monotone chain on the in-plane coordinates, carrying the input ids along.
  s.plane_ids.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) s.plane_ids[i] = static_cast<std::uint32_t>(i);
  const auto& pp = s.plane_points;
  std::sort(s.plane_ids.begin(), s.plane_ids.end(), [&](std::uint32_t a, std::uint32_t b) {
    return pp[a].x() < pp[b].x() || (pp[a].x() == pp[b].x() && pp[a].y() < pp[b].y());
  });
  const auto cross = [&](std::uint32_t o, std::uint32_t a, std::uint32_t b) {
    const Vec2 oa = pp[a] - pp[o], ob = pp[b] - pp[o];
    return oa.x() * ob.y() - oa.y() * ob.x();
  };
  std::vector<std::uint32_t>& h = s.degree;  // reused as the chain buffer
  h.assign(2 * points.size() + 1, 0);
  std::size_t k = 0;
  for (std::uint32_t id : s.plane_ids) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], id) <= 0) --k;
    h[k++] = id;
  }
  const std::size_t lower = k + 1;
  for (std::size_t i = s.plane_ids.size(); i-- > 0;) {
    const std::uint32_t id = s.plane_ids[i];
    while (k >= lower && cross(h[k - 2], h[k - 1], id) <= 0) --k;
    h[k++] = id;
  }
  if (k > 1) --k;
  for (std::size_t i = 0; i < k; ++i) {
    out.vertices.push_back(points[h[i]]);
    out.input_index.push_back(h[i]);
  }
  out.plane_normal = normal;
  out.dimension = out.vertices.size() >= 3 ? 2 : static_cast<int>(out.vertices.size()) - 1;
}

}  // namespace

ConvexHull3 convex_hull(std::span<const Vec3> points) {
  ConvexHull3 out;
  HullWorkspace workspace;
  convex_hull(points, out, workspace);
  return out;
}

void convex_hull(std::span<const Vec3> points, ConvexHull3& out, HullWorkspace& workspace) {
  out.clear();
  if (points.empty()) throw InputError("convex_hull: empty point set");
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<int>::max() / 4))
    throw InputError("convex_hull: too many points");
  State& s = workspace.state();
  const AffineDimension shape = affine_dimension(points);
  const std::uint32_t ia = shape.simplex[0];
  if (shape.dimension == 0) {
    out.dimension = 0;
    out.vertices.push_back(points[ia]);
    out.input_index.push_back(ia);
    return;
  }
  if (shape.dimension == 1) {
    // The two extreme points along the line.
    const Vec3& dir = shape.direction;
    std::uint32_t lo = ia, hi = ia;
    double t_lo = 0.0, t_hi = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double t = (points[i] - points[ia]).dot(dir);
      if (t < t_lo) t_lo = t, lo = static_cast<std::uint32_t>(i);
      if (t > t_hi) t_hi = t, hi = static_cast<std::uint32_t>(i);
    }
    out.dimension = 1;
    out.vertices = {points[lo], points[hi]};
    out.input_index = {lo, hi};
    return;
  }
  if (shape.dimension == 2) {
    planar_hull(points, shape.bounds.center(), shape.normal, s, out);
    return;
  }

  s.candidates.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) s.candidates[i] = static_cast<std::uint32_t>(i);
  Quickhull hull(points, shape.bounds.extents(), s);
  hull.run(shape.simplex);
  if (!hull.remove_non_extreme_vertices() || !convert(points, s, out)) {
    // Some vertices lie inside a flat facet or an edge of the hull (ties for the farthest point
    // on coplanar sets) and removing them locally failed: rebuild from the strictly extreme
    // vertices only, whose hull is the same polytope and has no other vertices. A failed local
    // removal may have left the faces half edited, so their hull is first built anew.
    hull.run(shape.simplex);
    if (convert(points, s, out)) {
      out.dimension = 3;
      build_adjacency(out, s);
      return;
    }
    keep_extreme_vertices(out, s);
    std::array<std::uint32_t, 4> t{};
    // The strictly extreme points of a solid set span it, so both failures are internal errors.
    if (!exact_simplex(points, s.candidates, t))
      throw std::logic_error("convex_hull: no solid simplex among the strictly extreme points");
    hull.run(t);
    if (!convert(points, s, out)) throw std::logic_error("convex_hull: a vertex is not extreme after the rebuild");
  }
  out.dimension = 3;
  build_adjacency(out, s);
}

AffineDimension affine_dimension(std::span<const Vec3> points) {
  if (points.empty()) throw InputError("affine_dimension: empty point set");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("point " + std::to_string(i) + " has a non-finite coordinate (NaN or Inf)");
  AffineDimension out;
  // Two extreme points a, b along the longest bounding-box axis, the point c farthest from line
  // ab, the point d farthest from plane abc.
  const Aabb& bounds = out.bounds = bounds_of(points);
  int axis = 0;
  bounds.extents().maxCoeff(&axis);
  std::size_t ia = 0, ib = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i][axis] < points[ia][axis]) ia = i;
    if (points[i][axis] > points[ib][axis]) ib = i;
  }
  out.simplex = {static_cast<std::uint32_t>(ia), static_cast<std::uint32_t>(ib), 0, 0};
  const double length = (points[ib] - points[ia]).norm();
  // Differences at the rounding level of the coordinates themselves count as a single point.
  if (!(length > 1e-15 * bounds.center().cwiseAbs().maxCoeff()) || length == 0.0) return out;
  out.direction = (points[ib] - points[ia]) / length;
  const auto [ic, best] = farthest_from_line(points, points[ia], out.direction);
  out.simplex[2] = static_cast<std::uint32_t>(ic);
  out.dimension = 1;
  if (!(std::sqrt(best) > kFlatTolerance * length)) return out;
  out.normal = (points[ib] - points[ia]).cross(points[ic] - points[ia]).normalized();
  double height = 0.0;
  std::size_t id = ia;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double h = std::abs((points[i] - points[ia]).dot(out.normal));
    if (h > height) height = h, id = i;
  }
  out.simplex[3] = static_cast<std::uint32_t>(id);
  out.dimension = 2;
  if (!(height > kFlatTolerance * length) || detail::orient3d(points[ia], points[ib], points[ic], points[id]) == 0)
    return out;
  out.dimension = 3;
  return out;
}

FarthestFromLine farthest_from_line(std::span<const Vec3> points, const Vec3& through, const Vec3& dir) {
  FarthestFromLine out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 d = points[i] - through;
    const double dist = (d - d.dot(dir) * dir).squaredNorm();
    if (dist > out.squared_distance) out = {i, dist};
  }
  return out;
}

std::size_t convex_hull_2d(std::span<Vec2> points) {
  std::vector<Vec2> chain;
  return convex_hull_2d(points, chain);
}

std::size_t convex_hull_2d(std::span<Vec2> points, std::vector<Vec2>& chain) {
  const std::size_t n = points.size();
  if (n == 0) return 0;
  std::sort(points.begin(), points.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  chain.resize(2 * n + 1);
  // The exact sign, not the rounded cross product: with rounded signs a nearly collinear point
  // can be kept by both the lower and the upper chain, and the chain outgrows the input.
  const auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return detail::orient2d(o.x(), o.y(), a.x(), a.y(), b.x(), b.y());
  };
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (k >= 2 && cross(chain[k - 2], chain[k - 1], points[i]) <= 0) --k;
    chain[k++] = points[i];
  }
  const std::size_t lower = k + 1;
  for (std::size_t i = n - 1; i-- > 0;) {
    while (k >= lower && cross(chain[k - 2], chain[k - 1], points[i]) <= 0) --k;
    chain[k++] = points[i];
  }
  if (k > 1) --k;  // the last point repeats the first
  // All points equal: the chain is [p, p]; collapse.
  if (k == 2 && chain[0] == chain[1]) k = 1;
  std::copy(chain.begin(), chain.begin() + static_cast<std::ptrdiff_t>(k), points.begin());
  return k;
}

}  // namespace tightbvh
