#pragma once
// Internal (builder and refit): the closed-form box of one triangle, so that a refitted leaf gets
// exactly the box the builder gives it.
#include <array>
#include <cmath>
#include <optional>

#include "tightbvh/obb.hpp"

namespace tightbvh::detail {

// The box of a single non-degenerate triangle: axes = longest edge, in-plane normal to it, triangle
// normal (right-handed); nullopt for a degenerate triangle (left to the fitter).
[[nodiscard]] inline std::optional<Obb> triangle_box(const std::array<Vec3, 3>& c) {
  const Vec3 edges[3] = {c[1] - c[0], c[2] - c[1], c[0] - c[2]};
  const double len2[3] = {edges[0].squaredNorm(), edges[1].squaredNorm(), edges[2].squaredNorm()};
  const int longest = len2[0] >= len2[1] ? (len2[0] >= len2[2] ? 0 : 2) : (len2[1] >= len2[2] ? 1 : 2);
  const Vec3 normal = edges[0].cross(edges[1]);
  const double normal_norm = normal.norm();
  // Degenerate (zero or tiny area relative to the edges): the fitter handles it robustly.
  if (!(normal_norm > 1e-12 * len2[longest])) return std::nullopt;
  Obb box;
  box.axes.col(0) = edges[longest] / std::sqrt(len2[longest]);
  box.axes.col(2) = normal / normal_norm;
  box.axes.col(1) = box.axes.col(2).cross(box.axes.col(0));
  const Vec3 origin = c[0];
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // c[0] is at the local origin
  for (int i = 1; i < 3; ++i) {
    const Vec3 q = box.axes.transpose() * (c[i] - origin);
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  box.half_extents = 0.5 * (hi - lo);
  box.center = origin + box.axes * (0.5 * (hi + lo));
  return box;
}

}  // namespace tightbvh::detail
