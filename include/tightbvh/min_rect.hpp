#pragma once
/// @file
/// Minimum-area enclosing rectangle of a convex polygon by rotating calipers
/// (Toussaint 1983; Freeman & Shapira 1975: one rectangle side is flush with a polygon edge).
#include <span>

#include "tightbvh/hull.hpp"

namespace tightbvh {

/// A rectangle in the plane: the ranges [min, max] along `axis` and its perpendicular.
struct Rect2 {
  Vec2 axis = Vec2::UnitX();  ///< unit; the other axis is (-axis.y, axis.x)
  Vec2 min = Vec2::Zero();    ///< extents along (axis, perpendicular)
  Vec2 max = Vec2::Zero();    ///< upper ends of the extents (see min)
  /// The product of the two extents.
  [[nodiscard]] double area() const { return (max.x() - min.x()) * (max.y() - min.y()); }
};

/// The minimum-area rectangle enclosing `polygon`, a convex polygon in counter-clockwise order
/// without repeated or collinear vertices (as returned by convex_hull_2d). O(n) by the calipers;
/// small polygons (below) by a branch-free O(n^2) scan. One or two vertices give a zero-area rectangle along the segment.
[[nodiscard]] Rect2 min_area_rect(std::span<const Vec2> polygon);
/// Polygons of up to this many vertices take an O(n^2) scan of every edge's rectangle in AVX lanes
/// where the CPU has AVX (min_rect.cpp), larger ones the calipers.
inline constexpr std::size_t kMinAreaRectEdgeScanMax = 32;

/// The size up to which min_area_rect_of_points() is the cheaper way (the fitters' small sets
/// take it instead of a hull).
inline constexpr std::size_t kMinAreaRectOfPointsMax = 8;
/// The minimum-area rectangle of a few points in any order (no hull needed): one side of it is
/// flush with a hull edge (Freeman & Shapira), and every direction through two of the points gives
/// a rectangle containing them all, so the smallest over the n(n-1)/2 pair directions is the
/// minimum. O(n^3) but without branches on the data: cheaper than convex_hull_2d + min_area_rect
/// up to about kMinAreaRectOfPointsMax points. Zero-area rectangles for collinear or coincident
/// points, as min_area_rect.
[[nodiscard]] Rect2 min_area_rect_of_points(std::span<const Vec2> points);

}  // namespace tightbvh
