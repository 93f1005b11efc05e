#pragma once
// Internal (builder and refit): how one node's box is fitted, so that a refitted tree gets exactly
// the boxes the builder gives it: the closed-form box of one triangle, the fitter's method for
// the node's size, and `auto`'s AABB alternative.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <variant>
#include <vector>

#include "tightbvh/aabb.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/fit.hpp"
#include "tightbvh/obb.hpp"
#include "../fit/fitters.hpp"
#include "../fit/frame.hpp"

namespace tightbvh::detail {

// The box of a single non-degenerate triangle: axes = longest edge, in-plane normal to it, triangle
// normal (right-handed); nullopt for a degenerate triangle (left to the fitter).
[[nodiscard]] inline std::optional<Obb> triangle_box(const std::array<Vec3, 3>& c) {
  const Vec3 edges[3] = {c[1] - c[0], c[2] - c[1], c[0] - c[2]};
  const double len2[3] = {edges[0].squaredNorm(), edges[1].squaredNorm(), edges[2].squaredNorm()};
  // 0 if edge 0 is longest, else 1 if edge 1 is, else 2 (ties to the lower index), as arithmetic
  // on the comparisons: which edge is longest is a coin toss, and half of all nodes are single
  // triangles, so a branch here would be mispredicted at every other leaf.
  const int first_longest = (len2[0] >= len2[1]) & (len2[0] >= len2[2]);
  const int second_longest = (len2[0] < len2[1]) & (len2[1] >= len2[2]);
  const int longest = 2 - 2 * first_longest - second_longest;
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

// auto's threshold `min_triangles` on a mesh of `mesh_triangles` (AutoFit::scale_above).
[[nodiscard]] inline std::uint64_t scaled_threshold(const AutoFit& a, std::uint32_t min_triangles,
                                                    std::size_t mesh_triangles) {
  if (a.scale_above == 0 || mesh_triangles <= a.scale_above) return min_triangles;
  return std::uint64_t{min_triangles} * mesh_triangles / a.scale_above;
}

// The method a fitter runs on a node of `triangles` triangles of a mesh of `mesh_triangles`.
[[nodiscard]] inline FitMethod method_for(const Fitter& fitter, std::size_t triangles, std::size_t mesh_triangles) {
  if (const auto* method = std::get_if<FitMethod>(&fitter)) return *method;
  const AutoFit& a = std::get<AutoFit>(fitter);
  if (triangles >= scaled_threshold(a, a.tight_min_triangles, mesh_triangles)) return a.tight;
  return triangles >= scaled_threshold(a, a.medium_min_triangles, mesh_triangles) ? a.medium : a.cheap;
}

// For each of kColumns x kColumns columns of the points' axis-aligned bounds, taken along the
// longest axis, the lowest and the highest point along it. Every point lies between its column's
// two, so the hull of these is within one column width (1/64 of the two shorter extents) of the
// set's hull: a coarse version of Barequet & Har-Peled's grid approximation (Section 6.3), built
// in one pass, whose hull costs a few milliseconds where the hull of 600k vertices took 1.6 s.
inline void column_extremes(std::span<const Vec3> points, std::vector<Vec3>& out) {
  constexpr int kColumns = 64;
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  int along = 0;
  (hi - lo).maxCoeff(&along);
  const int u = (along + 1) % 3, v = (along + 2) % 3;
  const double su = kColumns / std::max(hi[u] - lo[u], 1e-300), sv = kColumns / std::max(hi[v] - lo[v], 1e-300);
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::vector<std::size_t> low(kColumns * kColumns, kNone), high(kColumns * kColumns, kNone);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    const int cu = std::clamp(static_cast<int>((p[u] - lo[u]) * su), 0, kColumns - 1);
    const int cv = std::clamp(static_cast<int>((p[v] - lo[v]) * sv), 0, kColumns - 1);
    const int c = cu * kColumns + cv;
    if (low[c] == kNone || p[along] < points[low[c]][along]) low[c] = i;
    if (high[c] == kNone || p[along] > points[high[c]][along]) high[c] = i;
  }
  out.clear();
  for (int c = 0; c < kColumns * kColumns; ++c) {
    if (low[c] == kNone) continue;
    out.push_back(points[low[c]]);
    if (high[c] != low[c]) out.push_back(points[high[c]]);
  }
}

// The box of a node given by its triangles' corners (three per triangle), in a mesh of
// `mesh_triangles`. `vertices()` returns the node's distinct vertices (or an empty span when the
// caller has none): the hull-based fitters work on them, pca on the corners; it is only called
// when needed. `pca_axes`, when given, are the node's PCA axes (from moments the builder derives
// along the tree), used by the methods that start from the PCA box instead of a pass of their own.
// `parent_axes`, when given, are the axes of the parent's box, where `auto` starts its search
// below the root (AutoFit::search_from_parent).
template <class Vertices>
[[nodiscard]] Obb fit_node(std::span<const Vec3> corners, std::size_t mesh_triangles, const Fitter& fitter,
                           const FitOptions& options, FitWorkspace& workspace, Vertices&& vertices,
                           const Mat3* pca_axes = nullptr, const Mat3* parent_axes = nullptr) {
  const std::size_t triangles = corners.size() / 3;
  const FitMethod method = method_for(fitter, triangles, mesh_triangles);
  if (triangles == 1 && method != FitMethod::aabb) {
    // One triangle: its minimum-volume box is flat, with its rectangle flush with the longest
    // edge (the minimum-area rectangle of a triangle). No fitter can do better, and it costs no
    // eigen-decomposition on half of the nodes. FCL's OBB fit3 does the same.
    if (const auto box = triangle_box({corners[0], corners[1], corners[2]})) return *box;
  }
  FitOptions fit = options;
  fit.method = method;
  Obb box;
  std::span<const Vec3> distinct;  // the node's distinct vertices, when the method asked for them
  if (method == FitMethod::pca || method == FitMethod::pca_vertex) {
    box = fit_triangles(corners, fit, workspace);
  } else {
    distinct = vertices();
    const auto* a = std::get_if<AutoFit>(&fitter);
    if (a && method == a->tight && a->column_extremes_above != 0 && distinct.size() > a->column_extremes_above) {
      std::vector<Vec3> extremes;
      column_extremes(distinct, extremes);
      const Obb oriented = fit_points(extremes, fit, workspace);
      box = fit_detail::box_with_axes(distinct, oriented.axes, oriented.center);  // contains every vertex
    } else if (const Mat3* from = a && a->search_from_parent ? parent_axes : nullptr;
               !distinct.empty() && (pca_axes != nullptr || from != nullptr) &&
               (fit_detail::uses_pca_axes(method) || method == FitMethod::approx)) {
      box = fit_detail::fit_triangles_with_pca_axes(corners, distinct, fit, workspace, pca_axes, from);
    } else if (method == FitMethod::approx && !distinct.empty()) {
      // The (1 + eps) grid scan at every node, its quality extras by the node's size.
      box = fit_detail::fit_tree_node_approx(corners, distinct, fit, workspace);
    } else {
      box = distinct.empty() ? fit_triangles(corners, fit, workspace) : fit_triangles(corners, distinct, fit, workspace);
    }
  }
  if (const auto* a = std::get_if<AutoFit>(&fitter); a && a->or_aabb && method != FitMethod::aabb) {
    // The axis-aligned box costs one pass and is often the smaller one (axis-aligned CAD parts,
    // nodes with a near-isotropic covariance where the PCA axes are arbitrary). The fit above has
    // checked the points, and the distinct vertices have the corners' bounds at a sixth of the
    // reads: the same box as fit_triangles(corners, aabb) without its finiteness pass.
    if (const Obb aabb = to_obb(bounds_of(distinct.empty() ? corners : distinct)); fit_detail::smaller_box(aabb, box))
      box = aabb;
  }
  return box;
}

}  // namespace tightbvh::detail
