// B*(S), Barequet & Har-Peled Lemma 6.3.1.
#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "fitters.hpp"
#include "frame.hpp"

namespace tightbvh::fit_detail {
namespace {

// An approximate diameter pair (Lemma 2.5.3 uses the extreme points of a fixed set of
// directions): the extreme pairs along D directions (the longest pair wins, the first on ties),
// then two rounds of "farthest point from the current end". `project(p, t)` writes the D
// projections of p. One pass over the points for all directions (point-major: the same
// comparisons in the same order per direction as a pass per direction, so the same pairs, at a
// fraction of the loads and loop overhead; lemma_box, its caller, runs on every node of an approx
// tree build).
template <int D, typename Point, typename Project>
std::array<std::size_t, 2> approx_diameter(std::span<const Point> pts, const Project& project) {
  double vlo[D], vhi[D];
  std::size_t lo[D] = {}, hi[D] = {};
  project(pts[0], vlo);
  std::copy(vlo, vlo + D, vhi);
  for (std::size_t i = 1; i < pts.size(); ++i) {
    double t[D];
    project(pts[i], t);
    // Strict comparisons: the first point reaching an extreme. As selects, not branches: which
    // point is extreme along which direction is a coin toss, and mispredicted branches here would be
    // a tenth of an approx tree build's (cachegrind --branch-sim).
    for (int d = 0; d < D; ++d) {
      const bool below = t[d] < vlo[d], above = t[d] > vhi[d];
      vlo[d] = below ? t[d] : vlo[d], lo[d] = below ? i : lo[d];
      vhi[d] = above ? t[d] : vhi[d], hi[d] = above ? i : hi[d];
    }
  }
  std::array<std::size_t, 2> best{0, 0};
  double best_len = -1.0;
  for (int d = 0; d < D; ++d) {
    const double len = (pts[hi[d]] - pts[lo[d]]).squaredNorm();
    if (len > best_len) best_len = len, best = {lo[d], hi[d]};
  }
  for (int round = 0; round < 2; ++round) {
    std::size_t far = best[0];
    double far_len = -1.0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double len = (pts[i] - pts[best[0]]).squaredNorm();
      const bool farther = len > far_len;
      far_len = farther ? len : far_len, far = farther ? i : far;
    }
    if (far_len > best_len) {
      best_len = far_len;
      best = {best[0], far};
    }
    std::swap(best[0], best[1]);
  }
  return best;
}

// The 13 directions of the cube's faces, edges and corners: (1,0,0), (0,1,0), (0,0,1), (1,1,0),
// (1,-1,0), (1,0,1), (1,0,-1), (0,1,1), (0,1,-1), (1,1,1), (1,1,-1), (1,-1,1), (-1,1,1). Their
// coordinates are 0 and +-1, so each projection (x dx + y dy) + z dz is a signed sum of
// coordinates with the same rounding (products by 0 and 1 are exact; a -0 from a product compares
// equal to 0): the same values as dot products with these directions, without the products.
constexpr int kCubeDirections = 13;
void cube_projections(const Vec3& p, double (&t)[kCubeDirections]) {
  const double x = p.x(), y = p.y(), z = p.z();
  const double xy = x + y, x_y = x - y;
  t[0] = x, t[1] = y, t[2] = z;
  t[3] = xy, t[4] = x_y, t[5] = x + z, t[6] = x - z, t[7] = y + z, t[8] = y - z;
  t[9] = xy + z, t[10] = xy - z, t[11] = x_y + z, t[12] = (y - x) + z;
}

// The 8 directions d pi / 8 of a plane, evaluated once (the same values as evaluating them at every
// call, which cost 16 sincos per fit: ~1% of an approx tree build).
constexpr int kPlaneDirections = 8;
struct PlaneDirections {
  double c[kPlaneDirections], s[kPlaneDirections];
  PlaneDirections() {
    for (int d = 0; d < kPlaneDirections; ++d) {
      const double angle = d * (3.14159265358979323846 / 8.0);
      c[d] = std::cos(angle), s[d] = std::sin(angle);
    }
  }
};

}  // namespace

AxisBox lemma_box(const HullGeometry& g, BoptScratch& scratch) {
  const auto& p = g.local;
  const auto st = approx_diameter<kCubeDirections>(std::span<const Vec3>(p), cube_projections);
  const Vec3 axis1 = (p[st[1]] - p[st[0]]).normalized();
  const Mat3 frame = frame_from_axis(axis1);
  const Vec3 u = frame.col(1), w = frame.col(2);
  // Projection onto the plane H orthogonal to st, in the (u, w) basis.
  std::vector<Vec2>& q = scratch.plane;
  q.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) q[i] = Vec2(u.dot(p[i]), w.dot(p[i]));
  static const PlaneDirections plane;
  const auto plane_projections = [](const Vec2& v, double (&t)[kPlaneDirections]) {
    for (int d = 0; d < kPlaneDirections; ++d) t[d] = plane.c[d] * v.x() + plane.s[d] * v.y();  // as Vec2's dot
  };
  const auto st2 = approx_diameter<kPlaneDirections>(std::span<const Vec2>(q), plane_projections);
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
