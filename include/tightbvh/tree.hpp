#pragma once
/// @file
/// The bounding-volume hierarchy: a flat node array, root at 0, the two children of an internal
/// node adjacent (left = first, right = first + 1), leaves owning a contiguous range of
/// `triangle_order` (indices into the mesh's triangles). Boxes are in the mesh frame, stored in
/// single precision and rounded outward from the fitted double boxes (compact_box.hpp): 68 bytes
/// per node.
#include <cstdint>
#include <vector>

#include "tightbvh/compact_box.hpp"

namespace tightbvh {

/// One node of a Tree: its box, and either its children or its triangles.
struct Node {
  CompactBox box;  ///< Contains the corners of every triangle below the node (mesh frame).
  std::uint32_t first = 0;  ///< leaf: offset into Tree::triangle_order; internal: left child index
  std::uint32_t count = 0;  ///< leaf: number of triangles (> 0); internal: 0

  /// Whether the node owns triangles (count > 0) rather than children.
  [[nodiscard]] bool is_leaf() const { return count != 0; }
};

/// A bounding-volume hierarchy over one mesh's triangles (see the file comment). Build one with
/// build(), check one with validate().
struct Tree {
  std::vector<Node> nodes;                     ///< Root at 0; empty for an empty tree.
  std::vector<std::uint32_t> triangle_order;  ///< A permutation of the mesh's triangle indices.
};

}  // namespace tightbvh
