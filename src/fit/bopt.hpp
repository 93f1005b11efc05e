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
  std::vector<std::uint8_t> front;     // silhouette_cycle: by face, whether it faces +v
  std::vector<std::uint32_t> next;     // silhouette_cycle: by vertex, the next one on the cycle
  std::vector<std::uint32_t> cycle;    // silhouette_cycle: the silhouette's vertices in order
  std::uint32_t epoch = 0;
  std::size_t calls = 0;
  std::size_t sorted_silhouettes = 0;  // Bopt calls that fell back to sorting the silhouette
  std::vector<std::pair<double, std::uint32_t>> grid_order;  // grid_search: (bound, direction)
  std::vector<Vec2> plane;  // lemma_box: the points projected onto the plane orthogonal to st
};

// Bopt(S, {v}) for the solid hull `g` (v need not be unit; a zero v gives an infinite box).
[[nodiscard]] AxisBox bopt(const HullGeometry& g, const Vec3& v, BoptScratch& scratch);

// The silhouette of the solid hull `g` seen along a (unit; (a, u, w) right-handed, as
// frame_from_axis gives), projected onto (u, w), into scratch.projected: the convex polygon
// convex_hull_2d would make of the projected hull vertices (counter-clockwise from the
// lexicographically smallest point, no collinear points). The edges between the faces facing +a
// and the others form one cycle, which the hull's edge list gives in order, so no sort is
// needed: O(F + E); on hulls with a face adjacency (HullGeometry::kWalkFaces) the cycle is walked
// on it instead, O(m d) for m silhouette vertices of degree d. False when rounding in the face classification breaks that cycle (a vertex
// with two outgoing silhouette edges, a right turn, a polygon wound twice): then nothing is
// promised about scratch.projected, and bopt() sorts the silhouette's points instead.
[[nodiscard]] bool silhouette_cycle(const HullGeometry& g, const Vec3& a, const Vec3& u, const Vec3& w,
                                    BoptScratch& scratch);
// The same polygon by the sorting path (bopt()'s fallback): the vertices of every edge between
// faces facing +a and -a (with a tolerance for faces parallel to a), projected, then
// convex_hull_2d. Returns the number of polygon points at the front of scratch.projected.
[[nodiscard]] std::size_t silhouette_sorted(const HullGeometry& g, const Vec3& a, const Vec3& u, const Vec3& w,
                                            BoptScratch& scratch);

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
