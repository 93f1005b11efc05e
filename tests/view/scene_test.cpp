// view/scene and view/page: the JSON a page draws matches the trees, meshes and contacts it
// shows, and the page text is safe to open.
#include "view/scene.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include <Eigen/Geometry>

#include "tightbvh/collide_trace.hpp"
#include "tightbvh/tree_walk.hpp"
#include "view/embedded.hpp"
#include "view/page.hpp"

namespace tightbvh::view {
namespace {

Mesh shipped(const char* name) { return load_mesh(std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/" + name); }

Vec3 at(const nlohmann::json& numbers, std::size_t i) {
  return {numbers[i].get<double>(), numbers[i + 1].get<double>(), numbers[i + 2].get<double>()};
}

// The page's boxCorner(), in C++: corner i of the box stored at `offset`.
Vec3 corner(const nlohmann::json& boxes, std::size_t offset, int i) {
  const Vec3 sign((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0);
  Vec3 p = at(boxes, offset);
  for (int axis = 0; axis < 3; ++axis)
    p += sign[axis] * boxes[offset + 12 + axis].get<double>() * at(boxes, offset + 3 + 3 * axis);
  return p;
}

TEST(ViewScene, BoxJsonGivesTheBoxCorners) {
  Obb box;
  box.center = Vec3(0.5, -2, 3);
  box.axes = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  box.half_extents = Vec3(1, 0.25, 2);
  const nlohmann::json j = box_json(box);
  ASSERT_EQ(j.size(), 15u);
  const auto corners = box.corners();
  // Rounded to 1e-5 (the box's size is between 1 and 10): a few steps times the extents.
  for (int i = 0; i < 8; ++i) EXPECT_LT((corner(j, 0, i) - corners[i]).norm(), 1e-4) << i;
  EXPECT_GT((corner(j, 0, 7) - corners[0]).norm(), 1.0);
}

TEST(ViewScene, TreeJsonLevelsAreTheTreesNodes) {
  const Mesh mesh = shipped("knot1.off");
  const BuildResult built = build_with_stats(mesh, {.fitter = FitMethod::pca});
  const nlohmann::json t = tree_json("pca", built, 2);
  EXPECT_EQ(t["fitter"], "pca");
  EXPECT_EQ(t["volume_per_level"].get<std::vector<double>>(), built.stats.tree.volume_per_level);
  const auto boxes_per_level = t["boxes_per_level"].get<std::vector<std::size_t>>();
  std::size_t nodes = 0;
  for (const std::size_t n : boxes_per_level) nodes += n;
  EXPECT_EQ(nodes, built.tree.nodes.size());
  // Levels up to kMaxDrawnBoxes boxes in total: all 2^l boxes of the first levels, each the node's box.
  const nlohmann::json& levels = t["levels"];
  ASSERT_GE(levels.size(), 10u);
  std::size_t drawn = 0;
  for (std::size_t l = 0; l < levels.size(); ++l) {
    EXPECT_EQ(levels[l].size(), 15 * boxes_per_level[l]) << l;
    drawn += boxes_per_level[l];
  }
  EXPECT_LE(drawn, kMaxDrawnBoxes);
  std::vector<std::size_t> seen(levels.size(), 0);
  for_each_node(built.tree, [&](const NodeVisit& v) {
    if (v.depth >= levels.size()) return false;
    const std::size_t offset = 15 * seen[v.depth]++;
    EXPECT_LT((corner(levels[v.depth], offset, 7) - v.node.box.obb().corners()[7]).norm(), 1e-5);
    return true;
  });
}

TEST(ViewScene, TreeJsonBoxLimitKeepsTheAskedLevel) {
  const BuildResult built = build_with_stats(shipped("knot1.off"), {.fitter = FitMethod::aabb});
  EXPECT_EQ(tree_json("aabb", built, 0, 7)["levels"].size(), 3u);  // 1 + 2 + 4 boxes
  const nlohmann::json deep = tree_json("aabb", built, 6, 7);
  ASSERT_EQ(deep["levels"].size(), 7u);
  EXPECT_EQ(deep["levels"][6].size(), 15 * deep["boxes_per_level"][6].get<std::size_t>());
}

TEST(ViewScene, MeshJsonIsPosed) {
  const Mesh mesh = shipped("knot1.off");
  Pose pose;
  pose.rotation = Eigen::AngleAxisd(1.1, Vec3(0, 0, 1)).toRotationMatrix();
  pose.translation = Vec3(0.3, -1, 2);
  const nlohmann::json j = mesh_json(mesh, pose);
  EXPECT_FALSE(j["decimated"].get<bool>());
  EXPECT_EQ(j["drawn_triangles"], mesh.triangles.size());
  ASSERT_EQ(j["positions"].size(), 3 * mesh.vertices.size());
  ASSERT_EQ(j["indices"].size(), 3 * mesh.triangles.size());
  for (std::size_t v = 0; v < mesh.vertices.size(); v += 97)
    EXPECT_LT((at(j["positions"], 3 * v) - pose.apply(mesh.vertices[v])).norm(), 1e-5);
  const nlohmann::json small = mesh_json(mesh, pose, 500);
  EXPECT_TRUE(small["decimated"].get<bool>());
  EXPECT_LE(small["drawn_triangles"].get<std::size_t>(), 500u);
  EXPECT_EQ(small["triangles"], mesh.triangles.size());
}

TEST(ViewScene, ContactsAreTheTouchingTriangles) {
  // Two small patches of the knot, B shifted so that some triangles cross.
  Mesh a = shipped("knot1.off");
  a.triangles.resize(300);
  Pose pose_b;
  pose_b.translation = Vec3(0.01, 0.005, 0);
  const QueryResult result = collide_brute_force(a, Pose{}, a, pose_b, {.mode = QueryMode::all_pairs});
  ASSERT_TRUE(result.hit);
  const nlohmann::json scene = contacts_scene("t", {a, a, pose_b, result, true});
  std::set<std::uint32_t> ta, tb;
  for (const TrianglePair& p : result.pairs) ta.insert(p.a), tb.insert(p.b);
  ASSERT_EQ(scene["contacts"][0].size(), 9 * ta.size());
  ASSERT_EQ(scene["contacts"][1].size(), 9 * tb.size());
  EXPECT_LT((at(scene["contacts"][1], 0) - pose_b.apply(a.corners(*tb.begin())[0])).norm(), 1e-6);
  EXPECT_EQ(scene["result"]["pairs"], result.pairs.size());
  EXPECT_EQ(scene["result"]["mode"], "all_pairs");
}

TEST(ViewScene, DescentStepsAreTheVisitedNodePairs) {
  Mesh a = shipped("knot1.off");
  a.triangles.resize(400);
  const Tree tree = build(a, {.fitter = FitMethod::pca, .threads = 1});
  Pose pose_b;
  pose_b.rotation = Eigen::AngleAxisd(0.3, Vec3::UnitZ()).toRotationMatrix();
  pose_b.translation = Vec3(0.01, 0.005, 0);
  const CollideTrace trace = collide_trace(tree, a, Pose{}, tree, a, pose_b, {.mode = QueryMode::all_pairs});
  ASSERT_TRUE(trace.result.hit);
  const std::size_t max_drawn = 50;
  ASSERT_GT(trace.pairs.size(), max_drawn);
  const nlohmann::json d = descent_json(trace, tree, tree, pose_b, max_drawn);
  EXPECT_EQ(d["visited"], trace.visited);
  EXPECT_EQ(d["drawn"], max_drawn);
  ASSERT_EQ(d["steps"].size(), 4 * max_drawn);
  EXPECT_EQ(d["per_level"].size(), trace.per_level.size());
  // Each step's boxes are its nodes' boxes (B's posed), outcome and level as traced.
  for (std::size_t i = 0; i < max_drawn; ++i) {
    const VisitedPair& p = trace.pairs[i];
    const std::size_t ia = d["steps"][4 * i], ib = d["steps"][4 * i + 1];
    EXPECT_EQ(d["steps"][4 * i + 2], static_cast<int>(p.outcome));
    EXPECT_EQ(d["steps"][4 * i + 3], p.level);
    const auto box_a = tree.nodes[p.a].box.obb().corners();
    const auto box_b = tree.nodes[p.b].box.obb().transformed(pose_b).corners();
    for (int k = 0; k < 8; ++k) {
      EXPECT_LT((corner(d["boxes_a"], 15 * ia, k) - box_a[k]).norm(), 1e-4);
      EXPECT_LT((corner(d["boxes_b"], 15 * ib, k) - box_b[k]).norm(), 1e-4);
    }
  }
  EXPECT_LE(d["boxes_a"].size(), 15 * max_drawn);
}

TEST(ViewPage, SelfContainedAndEscaped) {
  const Mesh mesh = shipped("knot1.off");
  const BuildResult built = build_with_stats(mesh, {.fitter = FitMethod::aabb});
  const std::string hostile = "</script><script>document.body.dataset.status='error: injected'</script><!--";
  const std::string page =
      render_page(trees_scene(hostile, mesh, 1, nlohmann::json::array({tree_json("aabb", built, 1)})));
  const auto count = [](const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  };
  // The template's own elements only: the title went in escaped.
  EXPECT_EQ(count(page, "</script"), count(page_template(), "</script"));
  EXPECT_EQ(count(page, "<!--"), count(page_template(), "<!--"));
  EXPECT_EQ(page.find("@@"), std::string::npos);
  EXPECT_NE(page.find("\\u003c/script>\\u003cscript>"), std::string::npos);
  // Nothing from the network.
  EXPECT_EQ(page.find("src=\"http"), std::string::npos);
  EXPECT_EQ(page.find("href=\"http"), std::string::npos);
  if (three_js_source().empty()) GTEST_SKIP() << "three.js not installed (scripts/setup): canvas fallback only";
  EXPECT_NE(page.find("Three.js Authors"), std::string::npos);
}

TEST(ViewPage, WriteFailsWithAClearError) {
  const auto file = std::filesystem::temp_directory_path() / "tightbvh_view_test_not_a_dir";
  std::ofstream(file) << "x";
  try {
    (void)write_page(file / "sub", nlohmann::json::object());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tightbvh_view_test_not_a_dir"), std::string::npos) << e.what();
  }
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace tightbvh::view
