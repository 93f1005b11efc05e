// B*(S), Barequet & Har-Peled Lemma 6.3.1.
#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "fitters.hpp"
#include "frame.hpp"

namespace tightbvh::fit_detail {
namespace {

// The last two steps of approx_diameter: two rounds of "farthest point from the current end".
template <typename Points>
std::array<std::size_t, 2> farthest_rounds(const Points& pts, std::size_t n, std::array<std::size_t, 2> best,
                                           double best_len) {
  for (int round = 0; round < 2; ++round) {
    std::size_t far = best[0];
    double far_len = -1.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double len = (pts[i] - pts[best[0]]).squaredNorm();
      if (len > far_len) far_len = len, far = i;
    }
    if (far_len > best_len) {
      best_len = far_len;
      best = {best[0], far};
    }
    std::swap(best[0], best[1]);
  }
  return best;
}

// An approximate diameter pair (Lemma 2.5.3 uses the extreme points of a fixed set of
// directions): the extreme pairs along the given directions (the longest pair wins, the first on
// ties), then two rounds of "farthest point from the current end".
template <typename Points, typename DirectionAt>
std::array<std::size_t, 2> approx_diameter(const Points& pts, std::size_t n, int dirs_count,
                                           const DirectionAt& dir_at) {
  std::array<std::size_t, 2> best{0, 0};
  double best_len = -1.0;
  for (int d = 0; d < dirs_count; ++d) {
    const auto dir = dir_at(d);
    std::size_t lo = 0, hi = 0;
    double vlo = dir.dot(pts[0]), vhi = vlo;
    for (std::size_t i = 1; i < n; ++i) {
      const double v = dir.dot(pts[i]);
      if (v < vlo) vlo = v, lo = i;
      if (v > vhi) vhi = v, hi = i;
    }
    const double len = (pts[hi] - pts[lo]).squaredNorm();
    if (len > best_len) best_len = len, best = {lo, hi};
  }
  return farthest_rounds(pts, n, best, best_len);
}

// approx_diameter along the 13 directions of the cube's faces, edges and corners, in one pass
// over the points. Their coordinates are 0 and +-1, so each projection (x dx + y dy) + z dz is a
// signed sum of coordinates with the same rounding (products by 0 and 1 are exact; a -0 from a
// product compares equal to 0): the same extremes and pair as approx_diameter with these
// directions, at a tenth of the arithmetic (lemma_box was 7% of an approx tree build).
constexpr int kCubeDirections = 13;
std::array<std::size_t, 2> cube_diameter(std::span<const Vec3> pts) {
  const auto project = [](const Vec3& p, double (&t)[kCubeDirections]) {
    const double x = p.x(), y = p.y(), z = p.z();
    const double xy = x + y, x_y = x - y;
    t[0] = x, t[1] = y, t[2] = z;
    t[3] = xy, t[4] = x_y, t[5] = x + z, t[6] = x - z, t[7] = y + z, t[8] = y - z;
    t[9] = xy + z, t[10] = xy - z, t[11] = x_y + z, t[12] = (y - x) + z;
  };
  double vlo[kCubeDirections], vhi[kCubeDirections];
  std::size_t lo[kCubeDirections] = {}, hi[kCubeDirections] = {};
  project(pts[0], vlo);
  std::copy(vlo, vlo + kCubeDirections, vhi);
  for (std::size_t i = 1; i < pts.size(); ++i) {
    double t[kCubeDirections];
    project(pts[i], t);
    for (int d = 0; d < kCubeDirections; ++d) {
      if (t[d] < vlo[d]) vlo[d] = t[d], lo[d] = i;
      if (t[d] > vhi[d]) vhi[d] = t[d], hi[d] = i;
    }
  }
  std::array<std::size_t, 2> best{0, 0};
  double best_len = -1.0;
  for (int d = 0; d < kCubeDirections; ++d) {
    const double len = (pts[hi[d]] - pts[lo[d]]).squaredNorm();
    if (len > best_len) best_len = len, best = {lo[d], hi[d]};
  }
  return farthest_rounds(pts, pts.size(), best, best_len);
}

}  // namespace

AxisBox lemma_box(const HullGeometry& g, BoptScratch& scratch) {
  const auto& p = g.local;
  const auto st = cube_diameter(p);
  const Vec3 axis1 = (p[st[1]] - p[st[0]]).normalized();
  const Mat3 frame = frame_from_axis(axis1);
  const Vec3 u = frame.col(1), w = frame.col(2);
  // Projection onto the plane H orthogonal to st, in the (u, w) basis.
  std::vector<Vec2>& q = scratch.plane;
  q.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) q[i] = Vec2(u.dot(p[i]), w.dot(p[i]));
  // The 8 directions d pi / 8 of the plane, evaluated once (the same values as evaluating them
  // at every call, which cost 16 sincos per fit: ~1% of an approx tree build).
  static const std::array<Vec2, 8> kPlaneDirs = [] {
    std::array<Vec2, 8> dirs;
    for (int d = 0; d < 8; ++d) {
      const double angle = d * (3.14159265358979323846 / 8.0);
      dirs[d] = Vec2(std::cos(angle), std::sin(angle));
    }
    return dirs;
  }();
  const auto st2 = approx_diameter(q, q.size(), 8, [](int d) { return kPlaneDirs[d]; });
  Vec2 d2 = q[st2[1]] - q[st2[0]];
  if (!(d2.norm() > 0.0)) d2 = Vec2::UnitX();
  d2.normalize();
  Mat3 axes;
  axes.col(0) = axis1;
  axes.col(1) = d2.x() * u + d2.y() * w;
  axes.col(2) = axis1.cross(axes.col(1));
  return box_of_hull(g, orthonormalize(axes));
}

}  // namespace tightbvh::fit_detail

namespace tightbvh::fit_detail {

AxisBox diameter_box(const HullGeometry& g, BoptScratch& scratch) {
  const AxisBox lemma = lemma_box(g, scratch);
  // Bopt(S, {st}) is never larger than the lemma's box (it shares the axis st and then takes
  // the optimal rectangle), and is what Section 6.5 reports as B*(S).
  const AxisBox along = bopt(g, lemma.axes.col(0), scratch);
  return along.volume() <= lemma.volume() ? along : lemma;
}

}  // namespace tightbvh::fit_detail
