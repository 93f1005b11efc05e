#include "tightbvh/tree_stats.hpp"

#include <algorithm>
#include <limits>

#include "tightbvh/tree_walk.hpp"

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
  for_each_node(tree, [&](const NodeVisit& v) {
    const double volume = v.node.box.volume();
    if (s.volume_per_level.size() <= v.depth) s.volume_per_level.resize(v.depth + 1, 0.0);
    s.volume_per_level[v.depth] += volume;
    s.sum_volume += volume;
    if (!v.node.is_leaf()) return;
    ++s.leaves;
    s.depth_min = std::min(s.depth_min, v.depth);
    s.depth_max = std::max(s.depth_max, v.depth);
    s.leaf_triangles_min = std::min<std::size_t>(s.leaf_triangles_min, v.node.count);
    s.leaf_triangles_max = std::max<std::size_t>(s.leaf_triangles_max, v.node.count);
    leaf_triangles += v.node.count;
  });
  s.leaf_triangles_avg = static_cast<double>(leaf_triangles) / static_cast<double>(s.leaves);
  return s;
}

}  // namespace tightbvh
