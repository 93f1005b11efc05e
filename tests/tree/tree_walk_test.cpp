#include "tightbvh/tree_walk.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "build_test_util.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/tree_obj.hpp"
#include "tightbvh/tree_stats.hpp"

namespace tightbvh {
namespace {

Mesh knot() { return load_mesh(test::source_dir() / "meshes/knot1.off"); }

// A tree of five nodes over three triangles: root 0 -> (1, 2), node 2 -> (3, 4).
Tree small_tree() {
  Tree tree;
  tree.nodes.resize(5);
  tree.nodes[0] = {CompactBox{}, 1, 0};
  tree.nodes[1] = {CompactBox{}, 0, 1};
  tree.nodes[2] = {CompactBox{}, 3, 0};
  tree.nodes[3] = {CompactBox{}, 1, 1};
  tree.nodes[4] = {CompactBox{}, 2, 1};
  tree.triangle_order = {0, 1, 2};
  return tree;
}

TEST(TreeWalk, PreorderLeftFirstWithParentAndDepth) {
  std::vector<std::uint32_t> index, parent;
  std::vector<std::size_t> depth;
  for_each_node(small_tree(), [&](const NodeVisit& v) {
    index.push_back(v.index);
    parent.push_back(v.parent);
    depth.push_back(v.depth);
  });
  EXPECT_EQ(index, (std::vector<std::uint32_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(parent, (std::vector<std::uint32_t>{kNoParent, 0, 0, 2, 2}));
  EXPECT_EQ(depth, (std::vector<std::size_t>{0, 1, 1, 2, 2}));
}

TEST(TreeWalk, FalsePrunesTheChildren) {
  std::vector<std::uint32_t> index;
  for_each_node(small_tree(), [&](const NodeVisit& v) {
    index.push_back(v.index);
    return v.index != 2;
  });
  EXPECT_EQ(index, (std::vector<std::uint32_t>{0, 1, 2}));
}

TEST(TreeWalk, EmptyTreeVisitsNothing) {
  int visits = 0;
  for_each_node(Tree{}, [&](const NodeVisit&) { ++visits; });
  EXPECT_EQ(visits, 0);
}

TEST(TreeWalk, TriangleRanges) {
  const std::vector<TriangleRange> r = triangle_ranges(small_tree());
  ASSERT_EQ(r.size(), 5u);
  const std::pair<std::size_t, std::size_t> expected[] = {{0, 3}, {0, 1}, {1, 3}, {1, 2}, {2, 3}};
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(std::pair(r[i].begin, r[i].end), expected[i]) << "node " << i;
}

TEST(TreeWalk, RangesOfABuiltTreeHoldTheirLeaves) {
  const Mesh mesh = knot();
  const Tree tree = build(mesh, {.fitter = FitMethod::pca, .leaf_size = 4});
  const std::vector<TriangleRange> r = triangle_ranges(tree);
  EXPECT_EQ(r[0].begin, 0u);
  EXPECT_EQ(r[0].end, mesh.triangles.size());
  std::size_t visits = 0;
  for_each_node(tree, [&](const NodeVisit& v) {
    ++visits;
    const std::size_t expected =
        v.node.is_leaf() ? v.node.count : r[v.node.first].size() + r[v.node.first + 1].size();
    EXPECT_EQ(r[v.index].size(), expected) << "node " << v.index;
  });
  EXPECT_EQ(visits, tree.nodes.size());
}

// Counts the OBJ's lines by their first word.
struct ObjCounts {
  std::size_t vertices = 0, lines = 0, comments = 0, other = 0;
  std::size_t max_index = 0;
};

ObjCounts read_obj(std::istream& in) {
  ObjCounts c;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string head;
    words >> head;
    if (head == "v") {
      double x, y, z;
      EXPECT_TRUE(words >> x >> y >> z) << line;
      ++c.vertices;
    } else if (head == "l") {
      std::size_t a = 0, b = 0;
      EXPECT_TRUE(words >> a >> b) << line;
      c.max_index = std::max({c.max_index, a, b});
      ++c.lines;
    } else if (head == "#") {
      ++c.comments;
    } else {
      ++c.other;
    }
  }
  return c;
}

TEST(TreeObj, OneBoxPerNodeOfTheLevel) {
  const Mesh mesh = knot();
  const Tree tree = build(mesh, {.fitter = FitMethod::pca});
  const TreeStats stats = tree_stats(tree);
  const auto path = std::filesystem::temp_directory_path() / "tightbvh_tree_obj_test.obj";
  for (const std::size_t level : {std::size_t{0}, std::size_t{3}, stats.depth_max}) {
    std::size_t at_level = 0;
    for_each_node(tree, [&](const NodeVisit& v) { at_level += v.depth == level; });
    ASSERT_EQ(write_boxes_obj(tree, level, path), at_level);
    std::ifstream in(path);
    const ObjCounts c = read_obj(in);
    EXPECT_EQ(c.vertices, 8 * at_level) << "level " << level;
    EXPECT_EQ(c.lines, 12 * at_level) << "level " << level;
    EXPECT_EQ(c.max_index, 8 * at_level);  // edges name only this file's vertices
    EXPECT_EQ(c.comments, 1u);
    EXPECT_EQ(c.other, 0u);
  }
  std::filesystem::remove(path);
}

TEST(TreeObj, CornersAreTheBoxCorners) {
  Tree tree;
  tree.nodes.push_back({CompactBox{}, 0, 1});
  tree.nodes[0].box.center = Eigen::Vector3f(1, 2, 3);
  tree.nodes[0].box.half_extents = Eigen::Vector3f(0.5, 0.25, 2);
  tree.triangle_order = {0};
  std::stringstream text;
  ASSERT_EQ(write_boxes_obj(tree, 0, text), 1u);
  std::string line;
  std::getline(text, line);
  EXPECT_EQ(line, "# tightbvh: boxes of tree level 0");
  for (const Vec3& corner : tree.nodes[0].box.obb().corners()) {
    std::getline(text, line);
    std::istringstream words(line);
    std::string v;
    Vec3 p;
    words >> v >> p.x() >> p.y() >> p.z();
    EXPECT_EQ(v, "v");
    EXPECT_EQ(p, corner);  // 17 digits: exact
  }
}

TEST(TreeObj, UnwritablePathIsAnInputError) {
  const Tree tree = build(knot(), {.fitter = FitMethod::aabb});
  EXPECT_THROW((void)write_boxes_obj(tree, 0, std::filesystem::path("/nonexistent-dir/boxes.obj")), InputError);
}

}  // namespace
}  // namespace tightbvh
