#include "hull_geometry.hpp"

#include <algorithm>
#include <limits>

#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#define TIGHTBVH_HULL_GEOMETRY_SSE2 1
#endif

namespace tightbvh::fit_detail {

void HullGeometry::reset(const ConvexHull3& h, const Vec3& o) {
  hull = &h;
  origin = o;
  local.resize(h.vertices.size());
  for (std::size_t i = 0; i < local.size(); ++i) local[i] = h.vertices[i] - o;
  face_adjacent.clear();
  vertex_face.clear();
  walk_hint = 0;
  if (h.faces.size() < kWalkFaces) return;
  // Each edge lists its vertices as its face[0] does (counter-clockwise seen from outside);
  // face[1] has them the other way round.
  constexpr std::uint32_t kNone = 0xffffffffu;
  face_adjacent.assign(h.faces.size(), {kNone, kNone, kNone});
  vertex_face.assign(h.vertices.size(), kNone);
  const auto slot_of = [&](std::uint32_t f, std::uint32_t from, std::uint32_t to) {
    const auto& v = h.faces[f];
    for (std::uint32_t k = 0; k < 3; ++k)
      if (v[(k + 1) % 3] == from && v[(k + 2) % 3] == to) return k;
    return kNone;
  };
  for (const HullEdge& e : h.edges) {
    const std::uint32_t k0 = slot_of(e.face[0], e.vertex[0], e.vertex[1]);
    const std::uint32_t k1 = slot_of(e.face[1], e.vertex[1], e.vertex[0]);
    if (k0 == kNone || k1 == kNone) {  // never expected: no walk on this hull
      face_adjacent.clear();
      vertex_face.clear();
      return;
    }
    face_adjacent[e.face[0]][k0] = e.face[1];
    face_adjacent[e.face[1]][k1] = e.face[0];
  }
  for (std::uint32_t f = 0; f < h.faces.size(); ++f)
    for (const std::uint32_t v : h.faces[f]) vertex_face[v] = f;
  for (const auto& adjacent : face_adjacent)
    for (const std::uint32_t g : adjacent)
      if (g == kNone) {
        face_adjacent.clear();
        vertex_face.clear();
        return;
      }
}

void HullGeometry::reset_points(std::span<const Vec3> points, const Vec3& o) {
  hull = nullptr;
  face_adjacent.clear();
  vertex_face.clear();
  walk_hint = 0;
  origin = o;
  local.resize(points.size());
  for (std::size_t i = 0; i < local.size(); ++i) local[i] = points[i] - o;
}

std::uint32_t extreme_vertex(const HullGeometry& g, const Vec3& dir, std::uint32_t start) {
  const auto& offsets = g.hull->neighbor_offsets;
  const auto& neighbors = g.hull->neighbors;
  std::uint32_t v = start;
  double best = dir.dot(g.local[v]);
  for (std::size_t steps = 0; steps <= g.local.size(); ++steps) {
    std::uint32_t next = v;
    for (std::uint32_t k = offsets[v]; k < offsets[v + 1]; ++k) {
      const std::uint32_t w = neighbors[k];
      const double d = dir.dot(g.local[w]);
      if (d > best) {
        best = d;
        next = w;
      }
    }
    if (next == v) break;
    v = next;
  }
  return v;
}

AxisBox box_of_hull(const HullGeometry& g, const Mat3& axes) {
  AxisBox box;
  box.axes = axes;
  box.lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  box.hi = -box.lo;
  const Mat3 rt = axes.transpose();
  for (const Vec3& p : g.local) {
    const Vec3 q = rt * p;
    box.lo = box.lo.cwiseMin(q);
    box.hi = box.hi.cwiseMax(q);
  }
  return box;
}

Extent extent_along(const HullGeometry& g, const Vec3& v) {
  Extent e{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  std::size_t i = 0;
#ifdef TIGHTBVH_HULL_GEOMETRY_SSE2
  // Two points per SSE2 instruction (the points are consecutive x, y, z triples): each projection
  // is (x vx + y vy) + z vz, as Eigen's dot, and min/max are exact, so the same extent as the
  // scalar loop (Bopt's extents and the volume bound are ~6% of an approx tree build).
  const std::size_t n = g.local.size();
  if (n >= 2) {
    const double* xyz = g.local.front().data();
    const __m128d vx = _mm_set1_pd(v.x()), vy = _mm_set1_pd(v.y()), vz = _mm_set1_pd(v.z());
    __m128d lo = _mm_set1_pd(e.lo), hi = _mm_set1_pd(e.hi);
    for (; i + 2 <= n; i += 2) {
      const double* p = xyz + 3 * i;
      const __m128d a = _mm_loadu_pd(p), b = _mm_loadu_pd(p + 2), c = _mm_loadu_pd(p + 4);
      const __m128d x = _mm_shuffle_pd(a, b, 2), y = _mm_shuffle_pd(a, c, 1), z = _mm_shuffle_pd(b, c, 2);
      const __m128d t = _mm_add_pd(_mm_add_pd(_mm_mul_pd(x, vx), _mm_mul_pd(y, vy)), _mm_mul_pd(z, vz));
      lo = _mm_min_pd(t, lo);
      hi = _mm_max_pd(t, hi);
    }
    alignas(16) double l[2], h[2];
    _mm_store_pd(l, lo);
    _mm_store_pd(h, hi);
    e.lo = std::min(l[0], l[1]);
    e.hi = std::max(h[0], h[1]);
  }
#endif
  for (const Vec3& p : std::span<const Vec3>(g.local).subspan(i)) {
    const double t = v.dot(p);
    e.lo = std::min(e.lo, t);
    e.hi = std::max(e.hi, t);
  }
  return e;
}

}  // namespace tightbvh::fit_detail
