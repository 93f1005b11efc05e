#pragma once
// Internal: Bopt(S, {v}) of Barequet & Har-Peled (Section 6.3): the minimum-volume box of
// the hull with one axis along v, by projecting the hull's silhouette and rotating calipers.
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "hull_geometry.hpp"
#include "tightbvh/min_rect.hpp"

namespace tightbvh::fit_detail {

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

// Bopt(S, {v}) of the points themselves (no hull: every point projected), relative to `origin`:
// the box of bopt() on a HullGeometry reset_points(points, origin), without the copy; sets of at
// most kMinAreaRectOfPointsMax points take their rectangle from min_area_rect_of_points (the same
// rectangle up to rounding and ties between equal areas, without the 2D hull).
[[nodiscard]] AxisBox bopt_of_points(std::span<const Vec3> points, const Vec3& origin, const Vec3& v,
                                     BoptScratch& scratch);

// The local improvement step of Section 6.5: re-solve Bopt along each axis of the box while
// a round lowers the volume by more than the relative `min_gain` (at most `max_rounds` rounds;
// near a local minimum the gains shrink geometrically, coordinate-descent style).
// `from_bopt`: `box` was returned by bopt() (its first axis is the Bopt direction, not re-solved).
[[nodiscard]] AxisBox improve(const HullGeometry& g, AxisBox box, BoptScratch& scratch, double min_gain = 1e-12,
                              int max_rounds = 64, bool from_bopt = false);

}  // namespace tightbvh::fit_detail
