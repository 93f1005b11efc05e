#pragma once
// Internal: Bopt(S, {v}) of Barequet & Har-Peled (Section 6.3): the minimum-volume box of
// the hull with one axis along v, by projecting the hull's silhouette and rotating calipers.
#include <cstdint>
#include <span>
#include <vector>

#include "tightbvh/hull.hpp"
#include "tightbvh/min_rect.hpp"

namespace tightbvh::fit_detail {

// A solid (dimension 3) hull seen from a local origin: vertices are relative to `origin`
// so that sets far from the coordinate origin keep their precision.
// Without a hull (`hull == nullptr`, see reset_points) `local` holds a small point set whose
// hull was never computed: Bopt then projects every point instead of the silhouette. That is
// still exact for the direction (the 2D hull of the projection is the projection of the 3D
// hull), and for a dozen points cheaper than building the hull (see kSmallSetApprox in fit.cpp).
struct HullGeometry {
  const ConvexHull3* hull = nullptr;
  Vec3 origin = Vec3::Zero();
  std::vector<Vec3> local;  // hull->vertices[i] - origin

  void reset(const ConvexHull3& h, const Vec3& o);
  void reset_points(std::span<const Vec3> points, const Vec3& o);
  [[nodiscard]] std::size_t size() const { return local.size(); }
};

// The vertex maximising dir . p, by hill climbing on the hull's vertex graph from `start`
// (a local maximum of a linear function over a convex polytope's graph is global).
[[nodiscard]] std::uint32_t extreme_vertex(const HullGeometry& g, const Vec3& dir, std::uint32_t start);

// min and max of v . p over the geometry's points (a scan: see bopt() for why not hill climbing).
struct Extent {
  double lo, hi;
};
[[nodiscard]] Extent extent_along(const HullGeometry& g, const Vec3& v);

// A box given by orthonormal right-handed axes and its extents along them (local frame).
struct AxisBox {
  Mat3 axes = Mat3::Identity();
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Zero();
  [[nodiscard]] double volume() const { return (hi - lo).prod(); }
};

struct BoptScratch {
  std::vector<Vec2> projected;
  std::vector<Vec2> chain;  // convex_hull_2d's scratch
  std::vector<std::uint32_t> stamp;
  std::vector<double> face_dot;
  std::uint32_t epoch = 0;
  std::size_t calls = 0;
  std::vector<std::pair<double, std::uint32_t>> grid_order;  // grid_search: (bound, direction)
  std::vector<Vec2> plane;  // lemma_box: the points projected onto the plane orthogonal to st
};

// Bopt(S, {v}) for the solid hull `g` (v need not be unit; a zero v gives an infinite box).
[[nodiscard]] AxisBox bopt(const HullGeometry& g, const Vec3& v, BoptScratch& scratch);

// The local improvement step of Section 6.5: re-solve Bopt along each axis of the box while
// a round lowers the volume by more than the relative `min_gain` (at most `max_rounds` rounds;
// near a local minimum the gains shrink geometrically, coordinate-descent style).
// `from_bopt`: `box` was returned by bopt() (its first axis is the Bopt direction, not re-solved).
[[nodiscard]] AxisBox improve(const HullGeometry& g, AxisBox box, BoptScratch& scratch, double min_gain = 1e-12,
                              int max_rounds = 64, bool from_bopt = false);

// The extents of the hull along given axes (exact, by scanning all hull vertices).
[[nodiscard]] AxisBox box_of_hull(const HullGeometry& g, const Mat3& axes);

}  // namespace tightbvh::fit_detail
