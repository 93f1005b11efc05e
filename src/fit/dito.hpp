#pragma once
// Internal: DiTO-14 (Larsson & Källberg 2011), see dito.cpp.
#include <cstddef>
#include <span>

#include "tightbvh/obb.hpp"

namespace tightbvh::fit_detail {

// Sets of at most this many points score the candidate frames on all their points.
inline constexpr std::size_t kDitoScoreAllMax = 16;

// The DiTO-14 box of `points` (not empty, finite): the best of the ditetrahedron's face-and-edge
// frames, with extents over all points. Never NaN; a point set gives a zero box, collinear
// extremes a box along their line.
[[nodiscard]] Obb dito_box(std::span<const Vec3> points);

}  // namespace tightbvh::fit_detail
