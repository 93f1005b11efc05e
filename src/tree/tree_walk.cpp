#include "tightbvh/tree_walk.hpp"

namespace tightbvh {

std::vector<TriangleRange> triangle_ranges(const Tree& tree) {
  std::vector<std::uint32_t> preorder;
  preorder.reserve(tree.nodes.size());
  for_each_node(tree, [&](const NodeVisit& v) { preorder.push_back(v.index); });
  // Reverse preorder reaches both children before their parent.
  std::vector<TriangleRange> ranges(tree.nodes.size());
  for (auto it = preorder.rbegin(); it != preorder.rend(); ++it) {
    const Node& node = tree.nodes[*it];
    ranges[*it] = node.is_leaf() ? TriangleRange{node.first, std::size_t{node.first} + node.count}
                                 : TriangleRange{ranges[node.first].begin, ranges[node.first + 1].end};
  }
  return ranges;
}

}  // namespace tightbvh
