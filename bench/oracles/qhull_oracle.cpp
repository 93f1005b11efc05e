// A qhull-based 3D hull (see qhull_oracle.hpp): probe, Akl-Toussaint prefilter, qhull 'Qt Q8'
// (then 'QJ'), conversion to our graph.
#include "qhull_oracle.hpp"

#include "tightbvh/aabb.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace tightbvh::oracle {

struct QhullWorkspace::State {
  qhT qh;
  FILE* errfile = nullptr;
  std::vector<coordT> coords;
  std::vector<std::int64_t> vertex_map;  // qhull vertex id -> our index
  std::vector<std::int64_t> facet_map;   // qhull facet id -> our index
  std::vector<std::uint32_t> degree;
  std::vector<std::uint32_t> ids;  // qhull point index -> input index
  std::vector<Vec3> inner_planes;  // prefilter: normals of the inner polytope
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

QhullWorkspace::QhullWorkspace() : state_(std::make_unique<State>()) {}
QhullWorkspace::~QhullWorkspace() = default;

namespace {

using State = QhullWorkspace::State;

bool run_qhull(std::span<const Vec3> points, State& s, const char* options, ConvexHull3& out) {
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

void prefilter(std::span<const Vec3> points, const Vec3& origin, State& s) {
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

bool qhull_hull(std::span<const Vec3> points, ConvexHull3& out, QhullWorkspace& workspace, const char* options) {
  out.clear();
  if (points.empty()) return false;
  State& s = *workspace.state_;
  // The dimension probe (solid sets only reach qhull).
  const Aabb bounds = bounds_of(points);
  const Vec3 origin = bounds.center();
  int axis = 0;
  bounds.extents().maxCoeff(&axis);
  std::size_t ia = 0, ib = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i][axis] < points[ia][axis]) ia = i;
    if (points[i][axis] > points[ib][axis]) ib = i;
  }
  const double length = (points[ib] - points[ia]).norm();
  const double tiny = 1e-13;
  if (!(length > 1e-15 * origin.cwiseAbs().maxCoeff()) || length == 0.0) return false;
  const Vec3 dir = (points[ib] - points[ia]) / length;
  const auto [ic, best] = farthest_from_line(points, points[ia], dir);
  if (!(std::sqrt(best) > tiny * length)) return false;
  const Vec3 normal = (points[ib] - points[ia]).cross(points[ic] - points[ia]).normalized();
  double height = 0.0;
  for (const Vec3& p : points) height = std::max(height, std::abs((p - points[ia]).dot(normal)));
  if (!(height > tiny * length)) return false;

  prefilter(points, origin, s);
  if (run_qhull(points, s, options != nullptr ? options : "Qt Q8", out) || run_qhull(points, s, "QJ", out)) {
    out.dimension = 3;
    build_adjacency(out, s);
    return true;
  }
  out.clear();
  return false;
}

}  // namespace tightbvh::oracle
