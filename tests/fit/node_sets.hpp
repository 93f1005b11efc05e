#pragma once
// The triangles of a pca tree's nodes as point sets: the inputs the tree builder gives a fitter
// (tests of approx-kernel and normal-bopt, the `auto` tree fitter's tiers).
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "test_util.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/tree_walk.hpp"

namespace tightbvh::test {

struct NodeSet {
  std::vector<Vec3> corners;
  std::vector<Vec3> vertices;  // the distinct mesh vertices of the same triangles
};

// The nodes of a pca tree of a shipped mesh with `min_triangles` to `max_triangles` triangles.
inline std::vector<NodeSet> node_sets(const std::string& relative, std::size_t min_triangles,
                                      std::size_t max_triangles = SIZE_MAX) {
  const Mesh mesh = load_mesh(source_dir() / relative);
  const Tree tree = build(mesh, {.fitter = FitMethod::pca, .threads = 1});
  const std::vector<TriangleRange> ranges = triangle_ranges(tree);
  std::vector<NodeSet> out;
  for (const TriangleRange& r : ranges) {
    if (r.size() < min_triangles || r.size() > max_triangles) continue;
    const auto triangles = std::span(tree.triangle_order).subspan(r.begin, r.size());
    NodeSet set;
    triangle_corners(mesh, triangles, set.corners);
    std::vector<std::uint32_t> ids;
    for (const std::uint32_t t : triangles) ids.insert(ids.end(), mesh.triangles[t].begin(), mesh.triangles[t].end());
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    for (const std::uint32_t v : ids) set.vertices.push_back(mesh.vertices[v]);
    out.push_back(std::move(set));
  }
  return out;
}

}  // namespace tightbvh::test
