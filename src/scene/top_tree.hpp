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
#include <utility>
#include <vector>

#include "tightbvh/aabb.hpp"

namespace tightbvh::scene_detail {

struct TopNode {
  Aabb box;
  std::uint32_t first = 0;  // leaf: the item; internal: the left child's index
  bool leaf = false;
};

// The largest per-axis gap between two boxes (<= 0 when they overlap).
inline double box_gap(const Aabb& a, const Aabb& b) {
  return (a.min - b.max).cwiseMax(b.min - a.max).maxCoeff();
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

  void build(std::span<const Aabb> boxes) {
    nodes_.clear();
    if (boxes.empty()) return;
    nodes_.reserve(2 * boxes.size() - 1);
    std::vector<std::uint32_t> items(boxes.size());
    for (std::uint32_t i = 0; i < items.size(); ++i) items[i] = i;
    struct Range {
      std::uint32_t node, begin, end;
    };
    nodes_.emplace_back();
    std::vector<Range> stack{{0, 0, static_cast<std::uint32_t>(items.size())}};
    while (!stack.empty()) {
      const Range r = stack.back();
      stack.pop_back();
      if (r.end - r.begin == 1) {
        nodes_[r.node].leaf = true;
        nodes_[r.node].first = items[r.begin];
        nodes_[r.node].box = boxes[items[r.begin]];
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
      stack.push_back({left + 1, mid, r.end});
      stack.push_back({left, r.begin, mid});
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
        n.box = nodes_[n.first].box;
        n.box.extend(nodes_[n.first + 1].box.min);
        n.box.extend(nodes_[n.first + 1].box.max);
      }
    }
  }

  // Sum of the internal nodes' surface areas: how loose the tree is (the SAH's numerator).
  [[nodiscard]] double cost() const {
    double sum = 0.0;
    for (const TopNode& n : nodes_)
      if (!n.leaf) sum += surface_area(n.box);
    return sum;
  }

  [[nodiscard]] std::size_t bytes() const { return nodes_.capacity() * sizeof(TopNode); }

 private:
  std::vector<TopNode> nodes_;
};

// fn(item_x, item_y) for every leaf pair whose boxes are at most `gap` apart on every axis. With
// `self` (x and y the same tree), each unordered pair of different items once.
template <class Fn>
void close_pairs(const TopTree& x, const TopTree& y, bool self, double gap, Fn&& fn) {
  if (x.empty() || y.empty()) return;
  const auto& nx = x.nodes();
  const auto& ny = y.nodes();
  struct Pair {
    std::uint32_t i, j;
    bool same;  // self: the node paired with itself
  };
  std::vector<Pair> stack{{0, 0, self}};
  while (!stack.empty()) {
    const Pair p = stack.back();
    stack.pop_back();
    const TopNode& a = nx[p.i];
    if (p.same) {
      if (a.leaf) continue;
      stack.push_back({a.first, a.first, true});
      stack.push_back({a.first + 1, a.first + 1, true});
      stack.push_back({a.first, a.first + 1, false});
      continue;
    }
    const TopNode& b = ny[p.j];
    if (box_gap(a.box, b.box) > gap) continue;
    if (a.leaf && b.leaf) {
      fn(a.first, b.first);
    } else if (b.leaf || (!a.leaf && surface_area(a.box) >= surface_area(b.box))) {
      stack.push_back({a.first, p.j, false});
      stack.push_back({a.first + 1, p.j, false});
    } else {
      stack.push_back({p.i, b.first, false});
      stack.push_back({p.i, b.first + 1, false});
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
    } else if (b.leaf || (!a.leaf && surface_area(a.box) >= surface_area(b.box))) {
      for (std::uint32_t c : {a.first, a.first + 1}) queue.push({box_distance(nx[c].box, b.box), c, p.j, false});
    } else {
      for (std::uint32_t c : {b.first, b.first + 1}) queue.push({box_distance(a.box, ny[c].box), p.i, c, false});
    }
  }
}

}  // namespace tightbvh::scene_detail
