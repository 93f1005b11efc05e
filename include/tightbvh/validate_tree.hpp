#pragma once
/// @file
/// Checks of a tree against its invariants (tree.hpp) and against its mesh.
#include <string>
#include <vector>

#include "tightbvh/mesh.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh {

/// The problems check_structure() or validate() found.
struct TreeCheck {
  std::vector<std::string> errors;  ///< each names the node (or the triangle) and the problem
  /// Whether no problem was found.
  [[nodiscard]] bool ok() const { return errors.empty(); }
  [[nodiscard]] std::string summary() const;  ///< first errors, one per line
};

/// Structure only (no mesh): a non-empty node array; every node reachable from the root exactly
/// once (no cycles, no orphans); child indices in range; leaves with count > 0 and their range
/// inside triangle_order; the two children's triangle ranges adjacent, together the parent's;
/// the root covering all of triangle_order, which is a permutation of 0..n-1; boxes finite, with
/// orthonormal right-handed axes and non-negative half extents.
[[nodiscard]] TreeCheck check_structure(const Tree& tree);

/// check_structure plus: triangle_order has one entry per mesh triangle, and every node's box
/// contains the corners of all its triangles (tolerance: containment_tolerance of the box).
/// Stops after `max_errors` errors.
[[nodiscard]] TreeCheck validate(const Tree& tree, const Mesh& mesh, std::size_t max_errors = 20);

}  // namespace tightbvh
