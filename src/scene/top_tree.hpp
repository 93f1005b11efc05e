#pragma once
// Internal: the scene's top-level tree, a binary tree of axis-aligned boxes over items (object
// slots), one item per leaf. Flat array, root at 0, the children of an internal node adjacent
// (left = first, right = first + 1) and always after their parent, so a refit is one backward
// pass. Built top down by median splits of the box centers along the longest axis of their range
// (O(n log n)); the traversals below generate the candidate item pairs of the scene queries.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "tightbvh/aabb.hpp"

namespace tightbvh::scene_detail {

struct TopNode {
  Aabb box;
  double area = 0.0;        // surface_area(box): which node of a pair to descend
  std::uint32_t first = 0;  // leaf: the item; internal: the left child's index
  bool leaf = false;
};

// The largest per-axis gap between two boxes (<= 0 when they overlap).
inline double box_gap(const Aabb& a, const Aabb& b) {
  return (a.min - b.max).cwiseMax(b.min - a.max).maxCoeff();
}

// box_gap(a, b) <= gap, axis by axis with an early exit: most node pairs of a walk are apart
// along the first axis tested.
inline bool boxes_within(const Aabb& a, const Aabb& b, double gap) {
  for (int k = 0; k < 3; ++k)
    if (a.min[k] - b.max[k] > gap || b.min[k] - a.max[k] > gap) return false;
  return true;
}

// The Euclidean distance between two boxes (0 when they overlap).
inline double box_distance(const Aabb& a, const Aabb& b) {
  return (a.min - b.max).cwiseMax(b.min - a.max).cwiseMax(0.0).norm();
}

inline double surface_area(const Aabb& box) {
  const Vec3 e = box.extents();
  return 2.0 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
}

class TopTree {
 public:
  [[nodiscard]] const std::vector<TopNode>& nodes() const { return nodes_; }
  [[nodiscard]] bool empty() const { return nodes_.empty(); }
  // The number of node levels below the root (0 for one leaf). Median splits halve the items, so
  // it is at most ceil(log2(items)) <= 32: the walks below keep their stacks in fixed arrays.
  [[nodiscard]] int depth() const { return depth_; }

  void build(std::span<const Aabb> boxes) {
    nodes_.clear();
    depth_ = 0;
    if (boxes.empty()) return;
    nodes_.reserve(2 * boxes.size() - 1);
    std::vector<std::uint32_t> items(boxes.size());
    for (std::uint32_t i = 0; i < items.size(); ++i) items[i] = i;
    struct Range {
      std::uint32_t node, begin, end;
      int level;
    };
    nodes_.emplace_back();
    std::vector<Range> stack{{0, 0, static_cast<std::uint32_t>(items.size()), 0}};
    while (!stack.empty()) {
      const Range r = stack.back();
      stack.pop_back();
      depth_ = std::max(depth_, r.level);
      if (r.end - r.begin == 1) {
        nodes_[r.node].leaf = true;
        nodes_[r.node].first = items[r.begin];
        continue;
      }
      Aabb centers;
      for (std::uint32_t i = r.begin; i < r.end; ++i) centers.extend(boxes[items[i]].center());
      int axis = 0;
      centers.extents().maxCoeff(&axis);
      const std::uint32_t mid = r.begin + (r.end - r.begin) / 2;
      // Ties broken by item so that the tree does not depend on the standard library's nth_element.
      std::nth_element(items.begin() + r.begin, items.begin() + mid, items.begin() + r.end,
                       [&](std::uint32_t x, std::uint32_t y) {
                         const double cx = boxes[x].min[axis] + boxes[x].max[axis];
                         const double cy = boxes[y].min[axis] + boxes[y].max[axis];
                         return cx < cy || (cx == cy && x < y);
                       });
      const auto left = static_cast<std::uint32_t>(nodes_.size());
      nodes_[r.node].first = left;
      nodes_.emplace_back();
      nodes_.emplace_back();
      stack.push_back({left + 1, mid, r.end, r.level + 1});
      stack.push_back({left, r.begin, mid, r.level + 1});
    }
    refit(boxes);
  }

  // New boxes for the same items; the structure is kept.
  void refit(std::span<const Aabb> boxes) {
    for (std::size_t i = nodes_.size(); i-- > 0;) {
      TopNode& n = nodes_[i];
      if (n.leaf) {
        n.box = boxes[n.first];
      } else {
        n.box.min = nodes_[n.first].box.min.cwiseMin(nodes_[n.first + 1].box.min);
        n.box.max = nodes_[n.first].box.max.cwiseMax(nodes_[n.first + 1].box.max);
      }
      n.area = surface_area(n.box);
    }
  }

  // Sum of the internal nodes' surface areas: how loose the tree is (the SAH's numerator).
  [[nodiscard]] double cost() const {
    double sum = 0.0;
    for (const TopNode& n : nodes_)
      if (!n.leaf) sum += n.area;
    return sum;
  }

  [[nodiscard]] std::size_t bytes() const { return nodes_.capacity() * sizeof(TopNode); }

 private:
  std::vector<TopNode> nodes_;
  int depth_ = 0;
};

// A depth-first walk's stack in a fixed array. Each pop pushes at most three entries, each one
// level deeper in one of the trees (or both, for a node paired with itself), so the stack never
// holds more than 2 * (depth_x + depth_y) + 1 entries: at most 129 for trees of depth <= 32.
template <class T>
class WalkStack {
 public:
  static constexpr int kCapacity = 160;
  static void require_depths(int depth_x, int depth_y) {
    if (2 * (depth_x + depth_y) + 3 > kCapacity) throw std::length_error("scene: top-level tree too deep");
  }
  void push(const T& x) { items_[size_++] = x; }
  [[nodiscard]] T pop() { return items_[--size_]; }
  [[nodiscard]] bool empty() const { return size_ == 0; }

 private:
  T items_[kCapacity];
  int size_ = 0;
};

// fn(item_x, item_y) for every leaf pair whose boxes are at most `gap` apart on every axis. With
// `self` (x and y the same tree), each unordered pair of different items once.
template <class Fn>
void close_pairs(const TopTree& x, const TopTree& y, bool self, double gap, Fn&& fn) {
  if (x.empty() || y.empty()) return;
  const TopNode* nx = x.nodes().data();
  const TopNode* ny = y.nodes().data();
  struct Pair {
    std::uint32_t i, j;
    bool same;  // self: the node paired with itself
  };
  WalkStack<Pair>::require_depths(x.depth(), y.depth());
  WalkStack<Pair> stack;
  stack.push({0, 0, self});
  while (!stack.empty()) {
    const Pair p = stack.pop();
    const TopNode& a = nx[p.i];
    if (p.same) {
      if (a.leaf) continue;
      stack.push({a.first, a.first, true});
      stack.push({a.first + 1, a.first + 1, true});
      stack.push({a.first, a.first + 1, false});
      continue;
    }
    const TopNode& b = ny[p.j];
    if (!boxes_within(a.box, b.box, gap)) continue;
    if (a.leaf && b.leaf) {
      fn(a.first, b.first);
    } else if (b.leaf || (!a.leaf && a.area >= b.area)) {
      stack.push({a.first, p.j, false});
      stack.push({a.first + 1, p.j, false});
    } else {
      stack.push({p.i, b.first, false});
      stack.push({p.i, b.first + 1, false});
    }
  }
}

// fn(item) for every leaf whose box is at most `gap` from `box` on every axis.
template <class Fn>
void close_items(const TopTree& x, const Aabb& box, double gap, Fn&& fn) {
  if (x.empty()) return;
  const TopNode* nx = x.nodes().data();
  WalkStack<std::uint32_t>::require_depths(x.depth(), 0);
  WalkStack<std::uint32_t> stack;
  stack.push(0);
  while (!stack.empty()) {
    const TopNode& a = nx[stack.pop()];
    if (!boxes_within(a.box, box, gap)) continue;
    if (a.leaf) {
      fn(a.first);
    } else {
      stack.push(a.first + 1);
      stack.push(a.first);
    }
  }
}

// Best first over leaf pairs by box distance: fn(item_x, item_y, best) for every leaf pair whose
// box distance is <= best (fn lowers `best` as it finds closer pairs), nearest boxes first;
// stops when no pair left can be at distance <= best. With `self`, unordered pairs of different items.
template <class Fn>
void nearest_pairs(const TopTree& x, const TopTree& y, bool self, double& best, Fn&& fn) {
  if (x.empty() || y.empty()) return;
  const auto& nx = x.nodes();
  const auto& ny = y.nodes();
  struct Pair {
    double bound;
    std::uint32_t i, j;
    bool same;
    bool operator>(const Pair& o) const {
      return bound > o.bound || (bound == o.bound && std::pair(i, j) > std::pair(o.i, o.j));
    }
  };
  std::priority_queue<Pair, std::vector<Pair>, std::greater<>> queue;
  queue.push({self ? 0.0 : box_distance(nx[0].box, ny[0].box), 0, 0, self});
  while (!queue.empty()) {
    const Pair p = queue.top();
    queue.pop();
    if (p.bound > best) break;
    const TopNode& a = nx[p.i];
    if (p.same) {
      if (a.leaf) continue;
      queue.push({0.0, a.first, a.first, true});
      queue.push({0.0, a.first + 1, a.first + 1, true});
      queue.push({box_distance(nx[a.first].box, nx[a.first + 1].box), a.first, a.first + 1, false});
      continue;
    }
    const TopNode& b = ny[p.j];
    if (a.leaf && b.leaf) {
      fn(a.first, b.first, best);
    } else if (b.leaf || (!a.leaf && a.area >= b.area)) {
      for (std::uint32_t c : {a.first, a.first + 1}) queue.push({box_distance(nx[c].box, b.box), c, p.j, false});
    } else {
      for (std::uint32_t c : {b.first, b.first + 1}) queue.push({box_distance(a.box, ny[c].box), p.i, c, false});
    }
  }
}

}  // namespace tightbvh::scene_detail
