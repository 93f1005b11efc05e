#pragma once
// Internal: what the tree-vs-tree queries (collide.cpp, distance.cpp) must compute identically.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "tightbvh/collide.hpp"
#include "tightbvh/compact_box.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/obb.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/tree.hpp"
#include "tightbvh/tri_distance.hpp"

namespace tightbvh::query_detail {

// B's vertex in A's frame. Written out so that the queries and their brute-force references
// evaluate exactly the same expression (same operation order) and hence see the same triangles.
[[nodiscard]] inline Vec3 map_point(const Pose& rel, const Vec3& v) {
  const Mat3& r = rel.rotation;
  const Vec3& t = rel.translation;
  return {r(0, 0) * v.x() + r(0, 1) * v.y() + r(0, 2) * v.z() + t.x(),
          r(1, 0) * v.x() + r(1, 1) * v.y() + r(1, 2) * v.z() + t.y(),
          r(2, 0) * v.x() + r(2, 1) * v.y() + r(2, 2) * v.z() + t.z()};
}

// Leaves test B's triangles in chunks of this many, mapped into A's frame once per leaf pair and
// chunk, against each of A's triangles: the order collide() and collide_trace() share.
inline constexpr std::uint32_t kLeafChunk = 32;
using MappedChunk = std::array<std::array<Vec3, 3>, kLeafChunk>;

// B's triangles [first, first + min(kLeafChunk, nb.count - first)) of leaf `nb` mapped into A's
// frame; returns how many.
inline std::uint32_t map_leaf_chunk(const Pose& rel, const Mesh& mb, const Tree& tb, const Node& nb,
                                    std::uint32_t first, MappedChunk& mapped) {
  const std::uint32_t n = std::min(kLeafChunk, nb.count - first);
  for (std::uint32_t j = 0; j < n; ++j) {
    const Triangle& tri = mb.triangles[tb.triangle_order[nb.first + first + j]];
    for (int k = 0; k < 3; ++k) mapped[j][k] = map_point(rel, mb.vertices[tri[k]]);
  }
  return n;
}

// The size that scales the box tests' allowance.
[[nodiscard]] inline double box_scale(const CompactBox& box) {
  return box.center_d().cwiseAbs().maxCoeff() + box.half_extents_d().cwiseAbs().maxCoeff();
}

// What every box test of a query adds to the projected radii: kBoxMargin for the rounding in the
// transform, relative to the coordinates (the two roots' scales and the relative translation),
// and kCompactBoxSlack for the float boxes' skew axes, whose error grows with the boxes' extents
// only (compact_box.hpp), relative to the two roots' largest half extents. So meshes far from
// the origin are not tested with boxes grown by their distance from it.
[[nodiscard]] inline double box_allowance(const Tree& ta, const Tree& tb, const Pose& rel) {
  const CompactBox& a = ta.nodes[0].box;
  const CompactBox& b = tb.nodes[0].box;
  return kBoxMargin * (box_scale(a) + box_scale(b) + rel.translation.cwiseAbs().maxCoeff()) +
         kCompactBoxSlack * (a.half_extents_d().maxCoeff() + b.half_extents_d().maxCoeff());
}

// B's mapped box in A's box frame, obb_overlap()'s frame: C = Aa^T (R Bb), d = Aa^T (R cb + t - ca).
struct BoxFrame {
  Mat3 c;
  Vec3 d;
};
[[nodiscard]] inline BoxFrame in_box_frame(const CompactBox& a, const Mat3& b_axes, const Vec3& b_center) {
  const Mat3 axes_t = a.axes_d().transpose();
  return {axes_t * b_axes, axes_t * (b_center - a.center_d())};
}

// O(1) guard against the common mistake of pairing a tree with another mesh, which would
// otherwise index out of range in the leaves. (Full checking is validate(tree, mesh).)
inline void check_tree_fits_mesh(const char* query, const Tree& tree, const Mesh& mesh, const char* which) {
  if (tree.triangle_order.size() != mesh.triangles.size())
    throw InputError(std::string(query) + ": tree " + which + " was built over " +
                     std::to_string(tree.triangle_order.size()) + " triangles but mesh " + which + " has " +
                     std::to_string(mesh.triangles.size()));
}

// The margin every collide query takes: finite and >= 0, else an InputError naming the query.
inline void check_margin(const char* query, double margin) {
  if (!(margin >= 0.0) || !std::isfinite(margin))
    throw InputError(std::string(query) + ": margin must be finite and >= 0, got " + std::to_string(margin));
}

// The safety-margin predicate of collide() and collide_brute_force() (margin > 0): the exact
// triangle distance, after a cheap rejection when the triangles' bounding boxes are more than
// `margin` apart along an axis (then so are the triangles). Shared, so both decide alike.
[[nodiscard]] inline bool within_margin(const Vec3& p0, const Vec3& p1, const Vec3& p2,  //
                                        const Vec3& q0, const Vec3& q1, const Vec3& q2, double margin) {
  const Vec3 p_lo = p0.cwiseMin(p1).cwiseMin(p2), p_hi = p0.cwiseMax(p1).cwiseMax(p2);
  const Vec3 q_lo = q0.cwiseMin(q1).cwiseMin(q2), q_hi = q0.cwiseMax(q1).cwiseMax(q2);
  if (((q_lo - p_hi).array() > margin).any() || ((p_lo - q_hi).array() > margin).any()) return false;
  return tri_tri_within(p0, p1, p2, q0, q1, q2, margin);
}

// Depth of every node of `tree` (root 0): collide_trace's levels.
[[nodiscard]] inline std::vector<std::uint32_t> node_depths(const Tree& tree) {
  std::vector<std::uint32_t> depth(tree.nodes.size(), 0);
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    const Node& n = tree.nodes[i];
    if (n.is_leaf()) continue;
    for (const std::uint32_t c : {n.first, n.first + 1}) {
      depth[c] = depth[i] + 1;
      stack.push_back(c);
    }
  }
  return depth;
}

}  // namespace tightbvh::query_detail
