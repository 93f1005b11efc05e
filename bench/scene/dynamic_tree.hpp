#pragma once
// The alternative the scene's top level was measured against (top_level_bench.cpp): a dynamic
// AABB tree in the style of Bullet's btDbvt and FCL's DynamicAABBTreeCollisionManager. Leaves hold
// "fat" boxes, each object's box enlarged by a margin; a move whose new box stays inside the fat
// box changes nothing, any other move removes the leaf and inserts it again, descending from the
// root towards the child whose box grows least in surface area. Candidate pairs come from a self
// walk over the fat boxes, filtered by the exact boxes.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "scene/top_tree.hpp"  // Aabb helpers: boxes_within, surface_area

namespace tightbvh::bench {

class DynamicTree {
 public:
  explicit DynamicTree(double margin) : margin_(margin) {}

  void insert(std::uint32_t item, const Aabb& box) {
    if (leaf_of_.size() <= item) leaf_of_.resize(item + 1, kNone);
    const int leaf = allocate();
    nodes_[leaf].box = fattened(box);
    nodes_[leaf].item = static_cast<int>(item);
    leaf_of_[item] = leaf;
    insert_leaf(leaf);
  }

  // The object's new exact box; true when the tree changed (the box left its fat box).
  bool move(std::uint32_t item, const Aabb& box) {
    const int leaf = leaf_of_[item];
    if ((nodes_[leaf].box.min.array() <= box.min.array()).all() && (box.max.array() <= nodes_[leaf].box.max.array()).all())
      return false;
    remove_leaf(leaf);
    nodes_[leaf].box = fattened(box);
    insert_leaf(leaf);
    return true;
  }

  // fn(item_x, item_y) for each unordered pair of different items whose fat boxes are within gap.
  template <class Fn>
  void self_pairs(double gap, Fn&& fn) const {
    if (root_ == kNone) return;
    std::vector<WalkPair>& stack = stack_;
    stack.clear();
    stack.push_back({root_, root_});
    while (!stack.empty()) {
      const WalkPair p = stack.back();
      stack.pop_back();
      const Node& a = nodes_[p.i];
      if (p.i == p.j) {
        if (a.item >= 0) continue;
        stack.push_back({a.child[0], a.child[0]});
        stack.push_back({a.child[1], a.child[1]});
        stack.push_back({a.child[0], a.child[1]});
        continue;
      }
      const Node& b = nodes_[p.j];
      if (!scene_detail::boxes_within(a.box, b.box, gap)) continue;
      if (a.item >= 0 && b.item >= 0) {
        fn(static_cast<std::uint32_t>(a.item), static_cast<std::uint32_t>(b.item));
      } else if (b.item >= 0 || (a.item < 0 && scene_detail::surface_area(a.box) >= scene_detail::surface_area(b.box))) {
        stack.push_back({a.child[0], p.j});
        stack.push_back({a.child[1], p.j});
      } else {
        stack.push_back({p.i, b.child[0]});
        stack.push_back({p.i, b.child[1]});
      }
    }
  }

 private:
  static constexpr int kNone = -1;
  struct Node {
    Aabb box;
    int parent = kNone;
    int child[2] = {kNone, kNone};
    int item = -1;  // >= 0: a leaf
  };

  [[nodiscard]] Aabb fattened(const Aabb& box) const {
    Aabb fat = box;
    fat.min.array() -= margin_;
    fat.max.array() += margin_;
    return fat;
  }

  static Aabb joined(const Aabb& a, const Aabb& b) {
    Aabb box;
    box.min = a.min.cwiseMin(b.min);
    box.max = a.max.cwiseMax(b.max);
    return box;
  }

  int allocate() {
    if (!free_.empty()) {
      const int i = free_.back();
      free_.pop_back();
      nodes_[i] = Node{};
      return i;
    }
    nodes_.emplace_back();
    return static_cast<int>(nodes_.size()) - 1;
  }

  void refit_up(int i) {
    for (; i != kNone; i = nodes_[i].parent)
      nodes_[i].box = joined(nodes_[nodes_[i].child[0]].box, nodes_[nodes_[i].child[1]].box);
  }

  void insert_leaf(int leaf) {
    nodes_[leaf].parent = kNone;
    if (root_ == kNone) {
      root_ = leaf;
      return;
    }
    // Descend towards the child whose box grows least in area (ties: the first).
    int sibling = root_;
    const Aabb& box = nodes_[leaf].box;
    while (nodes_[sibling].item < 0) {
      const int c0 = nodes_[sibling].child[0], c1 = nodes_[sibling].child[1];
      const double g0 = scene_detail::surface_area(joined(nodes_[c0].box, box)) - scene_detail::surface_area(nodes_[c0].box);
      const double g1 = scene_detail::surface_area(joined(nodes_[c1].box, box)) - scene_detail::surface_area(nodes_[c1].box);
      sibling = g0 <= g1 ? c0 : c1;
    }
    const int parent = allocate();
    const int grand = nodes_[sibling].parent;
    nodes_[parent].parent = grand;
    nodes_[parent].child[0] = sibling;
    nodes_[parent].child[1] = leaf;
    nodes_[sibling].parent = parent;
    nodes_[leaf].parent = parent;
    if (grand == kNone) {
      root_ = parent;
    } else {
      nodes_[grand].child[nodes_[grand].child[0] == sibling ? 0 : 1] = parent;
    }
    refit_up(parent);
  }

  void remove_leaf(int leaf) {
    if (leaf == root_) {
      root_ = kNone;
      return;
    }
    const int parent = nodes_[leaf].parent;
    const int grand = nodes_[parent].parent;
    const int sibling = nodes_[parent].child[nodes_[parent].child[0] == leaf ? 1 : 0];
    nodes_[sibling].parent = grand;
    if (grand == kNone) {
      root_ = sibling;
    } else {
      nodes_[grand].child[nodes_[grand].child[0] == parent ? 0 : 1] = sibling;
      refit_up(grand);
    }
    free_.push_back(parent);
  }

  double margin_;
  std::vector<Node> nodes_;
  std::vector<int> free_;
  std::vector<int> leaf_of_;
  int root_ = kNone;
  struct WalkPair {
    int i, j;
  };
  mutable std::vector<WalkPair> stack_;  // the walk's scratch, kept between frames
};

}  // namespace tightbvh::bench
