#include "hull_geometry.hpp"

#include <algorithm>
#include <limits>

namespace tightbvh::fit_detail {

void HullGeometry::reset(const ConvexHull3& h, const Vec3& o) {
  hull = &h;
  origin = o;
  local.resize(h.vertices.size());
  for (std::size_t i = 0; i < local.size(); ++i) local[i] = h.vertices[i] - o;
}

void HullGeometry::reset_points(std::span<const Vec3> points, const Vec3& o) {
  hull = nullptr;
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
  for (const Vec3& p : g.local) {
    const double t = v.dot(p);
    e.lo = std::min(e.lo, t);
    e.hi = std::max(e.hi, t);
  }
  return e;
}

}  // namespace tightbvh::fit_detail
