#pragma once
// The bounding-volume hierarchy: a flat node array, root at 0, the two children of an internal
// node adjacent (left = first, right = first + 1), leaves owning a contiguous range of
// `triangle_order` (indices into the mesh's triangles). Boxes are in the mesh frame.
#include <cstdint>
#include <vector>

#include "tightbvh/obb.hpp"

namespace tightbvh {

struct Node {
  Obb box;
  std::uint32_t first = 0;  // leaf: offset into Tree::triangle_order; internal: left child index
  std::uint32_t count = 0;  // leaf: number of triangles (> 0); internal: 0

  [[nodiscard]] bool is_leaf() const { return count != 0; }
};

struct Tree {
  std::vector<Node> nodes;
  std::vector<std::uint32_t> triangle_order;
};

}  // namespace tightbvh
