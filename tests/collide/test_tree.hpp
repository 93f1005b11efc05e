#pragma once
// TEST-ONLY: a trivially built tree (recursive median split of centroids along the longest
// axis, boxes from fit_triangles) used by the collide tests until tightbvh::build lands from
// the tree branch. Delete once the real builder is merged.
#include <algorithm>
#include <numeric>
#include <vector>

#include "tightbvh/fit.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh::test {

inline Tree median_split_tree(const Mesh& mesh, FitMethod fitter, std::uint32_t leaf_size = 4) {
  Tree tree;
  tree.triangle_order.resize(mesh.triangles.size());
  std::iota(tree.triangle_order.begin(), tree.triangle_order.end(), 0u);
  const auto centroid = [&](std::uint32_t t) {
    const auto c = mesh.corners(t);
    return Vec3((c[0] + c[1] + c[2]) / 3.0);
  };
  const auto fit = [&](std::uint32_t first, std::uint32_t count) {
    std::vector<Vec3> corners;
    for (std::uint32_t i = first; i < first + count; ++i)
      for (const Vec3& v : mesh.corners(tree.triangle_order[i])) corners.push_back(v);
    return fit_triangles(corners, {.method = fitter});
  };
  struct Item {
    std::uint32_t node, first, count;
  };
  tree.nodes.push_back({});
  std::vector<Item> todo{{0, 0, static_cast<std::uint32_t>(mesh.triangles.size())}};
  while (!todo.empty()) {
    const Item it = todo.back();
    todo.pop_back();
    tree.nodes[it.node].box = fit(it.first, it.count);
    if (it.count <= leaf_size) {
      tree.nodes[it.node].first = it.first;
      tree.nodes[it.node].count = it.count;
      continue;
    }
    Aabb bounds;
    for (std::uint32_t i = it.first; i < it.first + it.count; ++i) bounds.extend(centroid(tree.triangle_order[i]));
    int axis = 0;
    bounds.extents().maxCoeff(&axis);
    const auto begin = tree.triangle_order.begin() + it.first;
    std::nth_element(begin, begin + it.count / 2, begin + it.count,
                     [&](std::uint32_t x, std::uint32_t y) { return centroid(x)[axis] < centroid(y)[axis]; });
    const auto left = static_cast<std::uint32_t>(tree.nodes.size());
    tree.nodes[it.node].first = left;
    tree.nodes[it.node].count = 0;
    tree.nodes.push_back({});
    tree.nodes.push_back({});
    todo.push_back({left, it.first, it.count / 2});
    todo.push_back({left + 1, it.first + it.count / 2, it.count - it.count / 2});
  }
  return tree;
}

}  // namespace tightbvh::test
