// 3D convex hull through qhull's reentrant C API, 2D hull by Andrew's monotone chain.
#include "tightbvh/hull.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "tightbvh/mesh.hpp"
#include "../predicates.hpp"

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

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

struct HullWorkspace::State {
  qhT qh;
  FILE* errfile = nullptr;
  std::vector<coordT> coords;
  std::vector<std::int64_t> vertex_map;  // qhull vertex id -> our index
  std::vector<std::int64_t> facet_map;   // qhull facet id -> our index
  std::vector<std::uint32_t> degree;
  std::vector<Vec2> plane_points;
  std::vector<std::uint32_t> plane_ids;
  std::vector<std::uint32_t> ids;          // qhull point index -> input index
  std::vector<Vec3> inner_planes;           // prefilter: normals of the inner polytope
  std::vector<double> inner_offsets;

  State() {
    errfile = std::fopen("/dev/null", "w");
    if (errfile == nullptr) errfile = stderr;
  }
  ~State() {
    if (errfile != nullptr && errfile != stderr) std::fclose(errfile);
  }
  State(const State&) = delete;
  State& operator=(const State&) = delete;
};

HullWorkspace::HullWorkspace() : state_(std::make_unique<State>()) {}
HullWorkspace::~HullWorkspace() = default;
HullWorkspace::HullWorkspace(HullWorkspace&&) noexcept = default;
HullWorkspace& HullWorkspace::operator=(HullWorkspace&&) noexcept = default;

namespace {

// Runs qhull on the centered coordinates and converts its triangulated facets. Returns false
// when qhull reports an error (then `out` is untouched apart from clear()).
// s.coords holds s.ids.size() points (centered); s.ids maps them to input indices.
bool run_qhull(std::span<const Vec3> points, HullWorkspace::State& s, const char* options, ConvexHull3& out) {
  qhT* qh = &s.qh;
  qh_zero(qh, s.errfile);
  std::string command = std::string("qhull ") + options;
  const int exitcode = qh_new_qhull(qh, 3, static_cast<int>(s.ids.size()), s.coords.data(), False,
                                    command.data(), nullptr, s.errfile);
  bool ok = exitcode == 0;
  if (ok) {
    vertexT* vertex;
    facetT* facet;
    s.vertex_map.assign(qh->vertex_id + 1, -1);
    s.facet_map.assign(qh->facet_id + 1, -1);
    out.vertices.clear();
    out.input_index.clear();
    FORALLvertices {
      const int local_id = qh_pointid(qh, vertex->point);
      if (local_id < 0 || static_cast<std::size_t>(local_id) >= s.ids.size()) continue;
      const std::uint32_t id = s.ids[static_cast<std::size_t>(local_id)];
      s.vertex_map[vertex->id] = static_cast<std::int64_t>(out.vertices.size());
      out.vertices.push_back(points[id]);
      out.input_index.push_back(id);
    }
    FORALLfacets {
      if (!facet->simplicial || qh_setsize(qh, facet->vertices) != 3) {
        ok = false;
        break;
      }
      s.facet_map[facet->id] = static_cast<std::int64_t>(out.faces.size());
      std::array<std::uint32_t, 3> f{};
      int k = 0;
      vertexT** vertexp;
      FOREACHvertex_(facet->vertices) f[k++] = static_cast<std::uint32_t>(s.vertex_map[vertex->id]);
      const Vec3 n(facet->normal[0], facet->normal[1], facet->normal[2]);
      out.faces.push_back(f);
      out.face_normals.push_back(n.normalized());
    }
    if (ok) {
      FORALLfacets {
        const auto self = static_cast<std::uint32_t>(s.facet_map[facet->id]);
        facetT* neighbor;
        facetT** neighborp;
        int k = 0;
        FOREACHneighbor_(facet) {
          // For a simplicial facet the k-th neighbor is opposite the k-th vertex.
          if (neighbor->id > facet->id && s.facet_map[neighbor->id] >= 0) {
            HullEdge e;
            const auto& f = out.faces[self];
            e.vertex = {f[(k + 1) % 3], f[(k + 2) % 3]};
            e.face = {self, static_cast<std::uint32_t>(s.facet_map[neighbor->id])};
            out.edges.push_back(e);
          }
          ++k;
        }
      }
      // A closed triangulated surface: E = 3F/2.
      ok = out.edges.size() * 2 == out.faces.size() * 3 && out.vertices.size() >= 4;
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  if (!ok) {
    out.vertices.clear();
    out.input_index.clear();
    out.faces.clear();
    out.face_normals.clear();
    out.edges.clear();
  }
  return ok;
}

void build_adjacency(ConvexHull3& out, HullWorkspace::State& s) {
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
void planar_hull(std::span<const Vec3> points, const Vec3& origin, const Vec3& normal, HullWorkspace::State& s,
                 ConvexHull3& out) {
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

// Akl-Toussaint prefilter: the extreme points along the 13 directions of the cube's faces,
// edges and corners (both signs) span an inner polytope; points strictly inside it cannot be
// hull vertices. Fills s.coords / s.ids with the survivors (all points for small sets).
void prefilter(std::span<const Vec3> points, const Vec3& origin, HullWorkspace::State& s) {
  const auto keep_all = [&] {
    s.ids.resize(points.size());
    s.coords.resize(points.size() * 3);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec3 d = points[i] - origin;
      s.ids[i] = static_cast<std::uint32_t>(i);
      s.coords[3 * i] = d.x(), s.coords[3 * i + 1] = d.y(), s.coords[3 * i + 2] = d.z();
    }
  };
  if (points.size() < 256) return keep_all();
  static const Vec3 kDirs[13] = {{1, 0, 0}, {0, 1, 0},  {0, 0, 1},  {1, 1, 0},  {1, -1, 0}, {1, 0, 1},  {1, 0, -1},
                                 {0, 1, 1}, {0, 1, -1}, {1, 1, 1},  {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}};
  std::array<std::uint32_t, 26> extreme{};
  std::array<double, 26> value;
  value.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 d = points[i] - origin;
    for (int k = 0; k < 13; ++k) {
      const double v = kDirs[k].dot(d);
      if (v > value[2 * k]) value[2 * k] = v, extreme[2 * k] = static_cast<std::uint32_t>(i);
      if (-v > value[2 * k + 1]) value[2 * k + 1] = -v, extreme[2 * k + 1] = static_cast<std::uint32_t>(i);
    }
  }
  std::sort(extreme.begin(), extreme.end());
  const auto end = std::unique(extreme.begin(), extreme.end());
  s.ids.assign(extreme.begin(), end);
  s.coords.resize(s.ids.size() * 3);
  for (std::size_t i = 0; i < s.ids.size(); ++i) {
    const Vec3 d = points[s.ids[i]] - origin;
    s.coords[3 * i] = d.x(), s.coords[3 * i + 1] = d.y(), s.coords[3 * i + 2] = d.z();
  }
  // The inner polytope's facet planes (qhull on at most 26 points).
  qhT* qh = &s.qh;
  qh_zero(qh, s.errfile);
  char command[] = "qhull";
  const int exitcode = qh_new_qhull(qh, 3, static_cast<int>(s.ids.size()), s.coords.data(), False, command,
                                    nullptr, s.errfile);
  s.inner_planes.clear();
  s.inner_offsets.clear();
  double scale = 0.0;
  if (exitcode == 0) {
    facetT* facet;
    FORALLfacets {
      s.inner_planes.emplace_back(facet->normal[0], facet->normal[1], facet->normal[2]);
      s.inner_offsets.push_back(facet->offset);
    }
    for (std::size_t i = 0; i < s.ids.size(); ++i) scale = std::max(scale, (points[s.ids[i]] - origin).norm());
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  if (exitcode != 0 || s.inner_planes.size() < 4) return keep_all();
  // Keep every point that is not strictly inside (with a relative margin, so rounding never
  // drops a hull vertex).
  const double margin = 1e-9 * scale;
  s.ids.clear();
  s.coords.clear();
  const std::size_t nplanes = s.inner_planes.size();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 d = points[i] - origin;
    bool inside = true;
    for (std::size_t f = 0; f < nplanes && inside; ++f) inside = s.inner_planes[f].dot(d) + s.inner_offsets[f] < -margin;
    if (inside) continue;
    s.ids.push_back(static_cast<std::uint32_t>(i));
    s.coords.push_back(d.x()), s.coords.push_back(d.y()), s.coords.push_back(d.z());
  }
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
  HullWorkspace::State& s = workspace.state();

  // Affine dimension, relative to the extent of the set: two extreme points a, b along the
  // longest bounding-box axis, the point c farthest from line ab, the point d farthest from
  // plane abc.
  Aabb bounds = bounds_of(points);
  const Vec3 origin = bounds.center();
  const Vec3 ext = bounds.extents();
  int axis = 0;
  ext.maxCoeff(&axis);
  std::size_t ia = 0, ib = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i][axis] < points[ia][axis]) ia = i;
    if (points[i][axis] > points[ib][axis]) ib = i;
  }
  const double length = (points[ib] - points[ia]).norm();
  const double tiny = 1e-13;
  // Differences at the rounding level of the coordinates themselves count as a single point.
  if (!(length > 1e-15 * origin.cwiseAbs().maxCoeff()) || length == 0.0) {
    out.dimension = 0;
    out.vertices.push_back(points[ia]);
    out.input_index.push_back(static_cast<std::uint32_t>(ia));
    return;
  }
  const Vec3 dir = (points[ib] - points[ia]) / length;
  const auto [ic, best] = farthest_from_line(points, points[ia], dir);
  if (!(std::sqrt(best) > tiny * length)) {
    // Collinear: the two extreme points along the line.
    std::size_t lo = ia, hi = ia;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double t = (points[i] - points[ia]).dot(dir);
      if (t < (points[lo] - points[ia]).dot(dir)) lo = i;
      if (t > (points[hi] - points[ia]).dot(dir)) hi = i;
    }
    out.dimension = 1;
    out.vertices = {points[lo], points[hi]};
    out.input_index = {static_cast<std::uint32_t>(lo), static_cast<std::uint32_t>(hi)};
    return;
  }
  const Vec3 normal = (points[ib] - points[ia]).cross(points[ic] - points[ia]).normalized();
  double height = 0.0;
  for (const Vec3& p : points) height = std::max(height, std::abs((p - points[ia]).dot(normal)));
  if (!(height > tiny * length)) {
    planar_hull(points, origin, normal, s, out);
    return;
  }

  prefilter(points, origin, s);
  // 'Qt': triangulated output (merged coplanar facets are split into triangles that share the
  // merged facet's normal). 'Q8': do not partition near-inside points to facets (they can never
  // be vertices; CAD meshes such as fandisk_large and blade have thousands of points on flat hull
  // faces: 25% and 13% less time for their approx box). If qhull reports a precision error, 'QJ'
  // joggles the input instead.
  if (run_qhull(points, s, "Qt Q8", out) || run_qhull(points, s, "QJ", out)) {
    out.dimension = 3;
    build_adjacency(out, s);
    return;
  }
  // Qhull could not build a solid hull: the set is flat within its precision.
  planar_hull(points, origin, normal, s, out);
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
  const std::size_t n = points.size();
  if (n == 0) return 0;
  std::sort(points.begin(), points.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  thread_local std::vector<Vec2> chain;
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
