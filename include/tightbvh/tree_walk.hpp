#pragma once
/// @file
/// The one depth-first walk over a tree: preorder, left child before right. Stats, the OBJ
/// writer, the FCL export and the CLI all visit nodes through it.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "tightbvh/tree.hpp"

namespace tightbvh {

/// NodeVisit::parent of the root.
inline constexpr std::uint32_t kNoParent = std::numeric_limits<std::uint32_t>::max();

/// What for_each_node() passes to its visitor for each node.
struct NodeVisit {
  const Node& node;                  ///< The node.
  std::uint32_t index = 0;           ///< Its index in Tree::nodes.
  std::uint32_t parent = kNoParent;  ///< kNoParent for the root
  std::size_t depth = 0;             ///< the root has depth 0
};

/// Calls visit(const NodeVisit&) for every node reachable from the root, in preorder. A visitor
/// returning bool prunes: false skips the node's children. Requires a structurally sound tree
/// (check_structure in validate_tree.hpp): a cycle would never end, so the checker keeps its
/// own guarded walk. An empty tree visits nothing.
template <class Visit>
void for_each_node(const Tree& tree, Visit&& visit) {
  if (tree.nodes.empty()) return;
  struct Pending {
    std::uint32_t index, parent;
    std::size_t depth;
  };
  std::vector<Pending> stack{{0, kNoParent, 0}};
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    const Node& node = tree.nodes[p.index];
    const NodeVisit v{node, p.index, p.parent, p.depth};
    if constexpr (std::is_same_v<std::invoke_result_t<Visit&, const NodeVisit&>, bool>) {
      if (!visit(v)) continue;
    } else {
      visit(v);
    }
    if (node.is_leaf()) continue;
    stack.push_back({node.first + 1, p.index, p.depth + 1});  // right popped after the left subtree
    stack.push_back({node.first, p.index, p.depth + 1});
  }
}

/// A node's triangles: positions [begin, end) of Tree::triangle_order.
struct TriangleRange {
  std::size_t begin = 0;  ///< First position.
  std::size_t end = 0;    ///< One past the last position.
  /// end - begin: the number of triangles.
  [[nodiscard]] std::size_t size() const { return end - begin; }
};

/// The triangle range of every node, by node index (internal nodes: the union of their
/// children's, which a sound tree keeps contiguous). Requires a structurally sound tree.
[[nodiscard]] std::vector<TriangleRange> triangle_ranges(const Tree& tree);

}  // namespace tightbvh
