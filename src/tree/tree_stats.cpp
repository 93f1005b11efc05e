#include "tightbvh/tree_stats.hpp"

#include <algorithm>
#include <limits>
#include <utility>

namespace tightbvh {

TreeStats tree_stats(const Tree& tree) {
  TreeStats s;
  s.nodes = tree.nodes.size();
  s.bytes = tree.nodes.size() * sizeof(Node) + tree.triangle_order.size() * sizeof(std::uint32_t);
  if (!tree.triangle_order.empty())
    s.bytes_per_triangle = static_cast<double>(s.bytes) / static_cast<double>(tree.triangle_order.size());
  if (tree.nodes.empty()) return s;
  s.depth_min = std::numeric_limits<std::size_t>::max();
  s.leaf_triangles_min = std::numeric_limits<std::size_t>::max();
  std::size_t leaf_triangles = 0;
  std::vector<std::pair<std::uint32_t, std::size_t>> stack{{0, 0}};  // node, depth
  while (!stack.empty()) {
    const auto [index, depth] = stack.back();
    stack.pop_back();
    const Node& node = tree.nodes[index];
    if (s.volume_per_level.size() <= depth) s.volume_per_level.resize(depth + 1, 0.0);
    s.volume_per_level[depth] += node.box.volume();
    s.sum_volume += node.box.volume();
    if (node.is_leaf()) {
      ++s.leaves;
      s.depth_min = std::min(s.depth_min, depth);
      s.depth_max = std::max(s.depth_max, depth);
      s.leaf_triangles_min = std::min<std::size_t>(s.leaf_triangles_min, node.count);
      s.leaf_triangles_max = std::max<std::size_t>(s.leaf_triangles_max, node.count);
      leaf_triangles += node.count;
    } else {
      stack.push_back({node.first + 1, depth + 1});
      stack.push_back({node.first, depth + 1});
    }
  }
  s.leaf_triangles_avg = static_cast<double>(leaf_triangles) / static_cast<double>(s.leaves);
  return s;
}

}  // namespace tightbvh
