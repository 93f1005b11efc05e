#pragma once
/// @file
/// Shape statistics of a tree: what the builder reports and `tightbvh inspect` prints.
#include <cstddef>
#include <vector>

#include "tightbvh/tree.hpp"

namespace tightbvh {

/// The shape of a tree (tree_stats()).
struct TreeStats {
  std::size_t nodes = 0;      ///< Number of nodes.
  std::size_t leaves = 0;     ///< Number of leaves.
  std::size_t depth_min = 0;  ///< of the leaves; the root has depth 0
  std::size_t depth_max = 0;  ///< of the leaves
  std::size_t leaf_triangles_min = 0;  ///< Fewest triangles in a leaf.
  std::size_t leaf_triangles_max = 0;  ///< Most triangles in a leaf.
  double leaf_triangles_avg = 0.0;     ///< Mean triangles per leaf.
  double sum_volume = 0.0;                ///< over every node
  std::vector<double> volume_per_level;   ///< [depth] -> sum of the volumes of the nodes at that depth
  std::size_t bytes = 0;                  ///< nodes * sizeof(Node) + triangle_order * 4
  double bytes_per_triangle = 0.0;        ///< bytes / triangle_order.size()
};

/// The statistics of `tree`. Requires a structurally sound tree (see check_structure in
/// validate_tree.hpp); an empty tree gives zeros.
[[nodiscard]] TreeStats tree_stats(const Tree& tree);

}  // namespace tightbvh
