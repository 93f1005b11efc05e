#include "tightbvh/build.hpp"
#include "tightbvh/tree_walk.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "build_test_util.hpp"
#include "tightbvh/hull.hpp"
#include "tightbvh/min_rect.hpp"
#include "tightbvh/refit.hpp"
#include "tightbvh/serialize.hpp"
#include "tightbvh/validate_tree.hpp"
#include "fit/frame.hpp"
#include "tree/node_fit.hpp"

namespace tightbvh {
namespace {

using test::all_fitters;
using test::available;

BuildOptions with(const Fitter& fitter, SplitMethod split = SplitMethod::rapid, std::uint32_t leaf_size = 1,
                  unsigned threads = 2) {
  BuildOptions options;
  options.fitter = fitter;
  options.split = split;
  options.leaf_size = leaf_size;
  options.threads = threads;
  return options;
}

// Builds and validates; checks the stats against the tree and the options.
void expect_valid_build(const Mesh& mesh, const BuildOptions& options, const std::string& what) {
  SCOPED_TRACE(what + ": fitter " + to_string(options.fitter) + ", split " + std::string(to_string(options.split)) +
               ", leaf size " + std::to_string(options.leaf_size));
  const BuildResult result = build_with_stats(mesh, options);
  const TreeCheck check = validate(result.tree, mesh);
  ASSERT_TRUE(check.ok()) << check.summary();
  const TreeStats& s = result.stats.tree;
  EXPECT_EQ(s.nodes, result.tree.nodes.size());
  EXPECT_EQ(s.nodes, 2 * s.leaves - 1);  // a full binary tree
  EXPECT_GE(s.leaf_triangles_min, 1u);
  EXPECT_LE(s.leaf_triangles_max, options.leaf_size);
  EXPECT_NEAR(s.leaf_triangles_avg * static_cast<double>(s.leaves), static_cast<double>(mesh.triangles.size()),
              1e-6 * static_cast<double>(mesh.triangles.size()));
  EXPECT_EQ(s.volume_per_level.size(), s.depth_max + 1);
  EXPECT_LE(s.depth_min, s.depth_max);
  EXPECT_GE(result.stats.seconds, 0.0);
}

Mesh load_relative(const std::string& relative) { return load_mesh(test::source_dir() / relative); }

// ------------------------------------------------------------------ every fitter, real meshes

TEST(BuildValidate, EveryFitterOnShippedMeshes) {
  for (const char* name : {"meshes/elephant.off", "meshes/knot1.off"}) {
    const Mesh mesh = load_relative(name);
    for (const Fitter& fitter : all_fitters()) {
      if (!available(fitter)) continue;
      expect_valid_build(test::first_triangles(mesh, test::triangle_budget(fitter)), with(fitter), name);
    }
  }
}

TEST(BuildValidate, EveryFitterOnCorpusMeshes) {
  // The hull-based fitters run on the first four (degtri_sliding has degenerate triangles).
  const std::vector<std::string> names{"cow.off",   "degtri_sliding.off", "couplingdown.off", "dragknob.off",
                                       "bones.off", "fandisk.off",        "mushroom.off",     "octahedron.off"};
  const auto dir = test::source_dir() / "meshes/corpus/cgal";
  if (!std::filesystem::exists(dir / names[0])) GTEST_SKIP() << "corpus not fetched (meshes/fetch-corpus)";
  for (std::size_t i = 0; i < names.size(); ++i) {
    const Mesh mesh = load_mesh(dir / names[i]);
    const std::string& name = names[i];
    for (const Fitter& fitter : all_fitters()) {
      if (!available(fitter) || (i >= 4 && !test::is_cheap(fitter))) continue;  // heavy ones: 4 meshes
      expect_valid_build(test::first_triangles(mesh, test::triangle_budget(fitter)), with(fitter), name);
    }
  }
}

TEST(BuildValidate, EverySplitAndLeafSize) {
  const Mesh mesh = load_relative("meshes/knot1.off");
  for (const SplitMethod split : {SplitMethod::rapid, SplitMethod::median, SplitMethod::binned})
    for (const std::uint32_t leaf : {1u, 2u, 3u, 8u, 100000u})
      expect_valid_build(mesh, with(FitMethod::pca, split, leaf), "knot1");
}

TEST(BuildShape, LeafSizeOneGivesTwoNMinusOneNodes) {
  const Mesh mesh = load_relative("meshes/elephant.off");
  const Tree tree = build(mesh, with(FitMethod::aabb));
  EXPECT_EQ(tree.nodes.size(), 2 * mesh.triangles.size() - 1);
  EXPECT_EQ(tree.triangle_order.size(), mesh.triangles.size());
}

TEST(BuildShape, MedianSplitIsBalanced) {
  const Mesh mesh = load_relative("meshes/knot1.off");  // 6400 triangles
  const TreeStats s = build_with_stats(mesh, with(FitMethod::pca, SplitMethod::median)).stats.tree;
  EXPECT_EQ(s.depth_max, 13u);  // ceil(log2(6400))
  EXPECT_EQ(s.depth_min, 12u);
}

TEST(BuildShape, LeafBoxesFitTheirOwnTriangle) {
  // A box is fitted from the node's corners (never merged from children): a leaf's box around
  // one non-degenerate triangle is flat for every fitter but aabb: its thickness is only the
  // float rounding of the box (compact_box.hpp): the axes' (about 1e-7 of the box size) and the
  // center's (about 6e-8 of its distance from the origin).
  const Mesh mesh = load_relative("meshes/elephant.off");
  const Tree tree = build(mesh, with(FitMethod::pca));
  for (const Node& node : tree.nodes)
    if (node.is_leaf())
      ASSERT_LT(node.box.half_extents.minCoeff(),
                1e-6 * node.box.half_extents.maxCoeff() + 1e-7 * node.box.center.cwiseAbs().maxCoeff())
          << node.box.half_extents.transpose();
}

TEST(BuildShape, SplitsAreRealSplits) {
  // Every internal node's children are both non-empty, also with all centroids equal.
  Mesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles.assign(37, Triangle{0, 1, 2});
  for (const SplitMethod split : {SplitMethod::rapid, SplitMethod::median, SplitMethod::binned}) {
    const BuildResult r = build_with_stats(mesh, with(FitMethod::aabb, split, 2));
    EXPECT_TRUE(validate(r.tree, mesh).ok());
    EXPECT_EQ(r.stats.tree.depth_max, 5u) << to_string(split);  // halves by count: 37 -> 19 -> 10 -> 5 -> 3 -> 2
  }
}

// ------------------------------------------------------------------ property tests on soups

TEST(BuildProperties, RandomSoupsWithDegenerateAndDuplicatedTriangles) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const std::size_t n = 50 + 97 * seed;
    const Mesh soup = test::random_soup(n, seed, /*degenerate=*/0.2, /*duplicated=*/0.2);
    for (const Fitter& fitter : all_fitters()) {
      if (!available(fitter)) continue;
      for (const SplitMethod split : {SplitMethod::rapid, SplitMethod::median, SplitMethod::binned}) {
        if (!test::is_cheap(fitter) && (split != SplitMethod::rapid || seed > 3)) continue;
        expect_valid_build(test::first_triangles(soup, test::triangle_budget(fitter)), with(fitter, split, 1 + seed % 3),
                           "soup " + std::to_string(seed));
      }
    }
  }
}

TEST(BuildProperties, AllDegenerateSoup) {
  const Mesh soup = test::random_soup(200, 42, /*degenerate=*/1.0, /*duplicated=*/0.3);
  for (const Fitter& fitter : all_fitters())
    if (available(fitter))
      expect_valid_build(test::first_triangles(soup, test::triangle_budget(fitter)), with(fitter), "all-degenerate soup");
}

TEST(BuildProperties, SingleTriangleAndTwoTriangles) {
  Mesh one;
  one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 5}};
  one.triangles = {{0, 1, 2}};
  Mesh two = one;
  two.triangles.push_back({1, 3, 2});
  Mesh point;  // one triangle collapsed to a point
  point.vertices = {{3, 3, 3}};
  point.triangles = {{0, 0, 0}};
  for (const Fitter& fitter : all_fitters()) {
    if (!available(fitter)) continue;
    const Tree t1 = build(one, with(fitter));
    ASSERT_EQ(t1.nodes.size(), 1u);
    EXPECT_EQ(t1.nodes[0].count, 1u);
    EXPECT_TRUE(validate(t1, one).ok()) << validate(t1, one).summary();
    const Tree t2 = build(two, with(fitter));
    ASSERT_EQ(t2.nodes.size(), 3u);
    EXPECT_EQ(t2.nodes[0].first, 1u);
    EXPECT_TRUE(validate(t2, two).ok()) << validate(t2, two).summary();
    const Tree t3 = build(point, with(fitter));
    EXPECT_TRUE(validate(t3, point).ok()) << validate(t3, point).summary();
  }
}

TEST(BuildProperties, RejectsBadInput) {
  EXPECT_THROW((void)build(Mesh{}), InputError);
  Mesh nan = test::random_soup(3, 1);
  nan.vertices[1].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)build(nan, with(FitMethod::aabb)), InputError);
  EXPECT_THROW((void)build(test::random_soup(3, 1), with(FitMethod::aabb, SplitMethod::rapid, 0)), InputError);
}

TEST(BuildProperties, BuildDoesNotDependOnTriangleStorageBeyondOrder) {
  // Pure: the same input twice gives the same tree.
  const Mesh mesh = test::random_soup(500, 9, 0.1, 0.1);
  const auto a = serialize(build(mesh, with(FitMethod::pca)));
  const auto b = serialize(build(mesh, with(FitMethod::pca)));
  EXPECT_EQ(a, b);
}

// ------------------------------------------------------------------ determinism

bool same_nodes(const Tree& a, const Tree& b) {
  return a.nodes.size() == b.nodes.size() && a.triangle_order == b.triangle_order &&
         std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(Node)) == 0;
}

TEST(BuildDeterminism, SameTreeForAnyThreadCount) {
  static_assert(sizeof(Node) == 68, "no padding: Node compares byte-wise");
  // Large enough that the top nodes are tasks of their own and the subtrees below the grain too.
  const Mesh mesh = test::random_soup(20000, 5, 0.05, 0.05);
  const Mesh knot = load_relative("meshes/knot1.off");
  // auto with a high threshold: approx at the top levels (slow tasks beside fast ones), pca below.
  std::vector<Fitter> fitters{FitMethod::aabb, FitMethod::pca, AutoFit{.tight_min_triangles = 3000}};
  for (const Fitter& fitter : fitters) {
    if (!available(fitter)) continue;
    for (const SplitMethod split : {SplitMethod::rapid, SplitMethod::binned}) {
      for (const Mesh* m : {&mesh, &knot}) {
        // leaf_size 3: subtrees use fewer slots than reserved, and the gaps are closed.
        for (const std::uint32_t leaf_size : {1u, 3u}) {
          const Tree one = build(*m, with(fitter, split, leaf_size, 1));
          for (const unsigned threads : {2u, 4u, 7u}) {
            const Tree many = build(*m, with(fitter, split, leaf_size, threads));
            EXPECT_TRUE(same_nodes(one, many)) << to_string(fitter) << " " << to_string(split) << " leaf size "
                                               << leaf_size << " threads " << threads;
          }
          const TreeCheck check = validate(one, *m);
          EXPECT_TRUE(check.ok()) << to_string(fitter) << " leaf size " << leaf_size << "\n" << check.summary();
        }
      }
    }
  }
}

// ------------------------------------------------------------------ stats and options

TEST(BuildStatsTest, VolumesAddUp) {
  const Mesh mesh = load_relative("meshes/elephant.off");
  const BuildResult r = build_with_stats(mesh, with(FitMethod::pca));
  double sum = 0.0;
  for (const Node& node : r.tree.nodes) sum += node.box.volume();
  double levels = 0.0;
  for (const double v : r.stats.tree.volume_per_level) levels += v;
  EXPECT_NEAR(r.stats.tree.sum_volume, sum, 1e-9 * sum);
  EXPECT_NEAR(levels, sum, 1e-9 * sum);
  EXPECT_DOUBLE_EQ(r.stats.tree.volume_per_level[0], r.tree.nodes[0].box.volume());
  EXPECT_EQ(r.stats.tree.bytes, r.tree.nodes.size() * 68 + mesh.triangles.size() * 4);
}

TEST(BuildStatsTest, LeafSizeOneTreeTakesLessThan150BytesPerTriangle) {
  // 2n - 1 float-box nodes of 68 bytes and one index per triangle: 140 bytes per triangle (FCL's
  // BVHModel<OBB> takes 276, the double-box tree took 260).
  const Mesh mesh = load_relative("meshes/elephant.off");
  const BuildResult r = build_with_stats(mesh, with(FitMethod::pca));
  ASSERT_EQ(r.tree.nodes.size(), 2 * mesh.triangles.size() - 1);
  EXPECT_LE(r.stats.tree.bytes_per_triangle, 150.0);
  EXPECT_GT(r.stats.tree.bytes_per_triangle, 139.0);
}

TEST(BuildOptionsTest, ParseFitter) {
  EXPECT_EQ(parse_fitter("auto"), Fitter{AutoFit{}});
  EXPECT_EQ(parse_fitter("pca-vertex"), Fitter{FitMethod::pca_vertex});
  EXPECT_EQ(parse_fitter("approx"), Fitter{FitMethod::approx});
  EXPECT_FALSE(parse_fitter("fastest"));
  EXPECT_EQ(to_string(Fitter{AutoFit{}}), "auto");
  EXPECT_EQ(to_string(Fitter{FitMethod::exact}), "exact");
  EXPECT_EQ(parse_split_method("binned"), SplitMethod::binned);
  EXPECT_EQ(parse_split_method("sah"), SplitMethod::binned);
  EXPECT_EQ(parse_split_method("median"), SplitMethod::median);
  EXPECT_FALSE(parse_split_method("middle"));
}

// The name tables: every entry parses back to itself, in declaration order, and the fitter
// names are "auto" then the fit methods.
TEST(BuildOptionsTest, NameTablesRoundTrip) {
  ASSERT_EQ(all_fit_methods().size(), std::size(test::kAllMethods));
  ASSERT_EQ(fit_method_names().size(), all_fit_methods().size());
  for (std::size_t i = 0; i < all_fit_methods().size(); ++i) {
    EXPECT_EQ(all_fit_methods()[i], test::kAllMethods[i]);
    EXPECT_EQ(fit_method_names()[i], to_string(all_fit_methods()[i]));
    EXPECT_EQ(parse_fit_method(fit_method_names()[i]), all_fit_methods()[i]);
  }
  const std::vector<std::string_view> fitters = fitter_names();
  ASSERT_EQ(fitters.size(), fit_method_names().size() + 1);
  EXPECT_EQ(fitters[0], "auto");
  for (const std::string_view name : fitters) {
    const auto fitter = parse_fitter(name);
    ASSERT_TRUE(fitter) << name;
    EXPECT_EQ(to_string(*fitter), name);
  }
  const SplitMethod splits[] = {SplitMethod::rapid, SplitMethod::median, SplitMethod::binned};
  ASSERT_EQ(all_split_methods().size(), std::size(splits));
  ASSERT_EQ(split_method_names().size(), std::size(splits));
  for (std::size_t i = 0; i < std::size(splits); ++i) {
    EXPECT_EQ(all_split_methods()[i], splits[i]);
    EXPECT_EQ(split_method_names()[i], to_string(splits[i]));
    EXPECT_EQ(parse_split_method(split_method_names()[i]), splits[i]);
  }
}

TEST(BuildOptionsTest, AutoUsesTightFitterAboveThreshold) {
  // auto with tight = aabb, cheap = pca: nodes at or above the threshold are axis-aligned.
  const Mesh mesh = load_relative("meshes/elephant.off");
  AutoFit policy{.tight_min_triangles = 100, .tight = FitMethod::aabb, .cheap = FitMethod::pca};
  const Tree tree = build(mesh, with(policy));
  ASSERT_TRUE(validate(tree, mesh).ok());
  EXPECT_TRUE(tree.nodes[0].box.axes.isIdentity());
  std::size_t rotated = 0;
  for (const Node& node : tree.nodes)
    if (!node.box.axes.isIdentity()) ++rotated;
  EXPECT_GT(rotated, tree.nodes.size() / 2);  // most nodes are small: pca
}

TEST(BuildOptionsTest, ApproxSnapIsRefusedAboveItsLimit) {
  Mesh mesh = load_relative("meshes/knot1.off");
  mesh = subdivide_midpoints(mesh);  // 25,600 triangles
  ASSERT_GT(mesh.triangles.size(), kMaxApproxSnapTriangles);
  try {
    (void)build(mesh, with(FitMethod::approx_snap));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("approx-snap is limited to 20000 triangles"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)build(mesh, with(AutoFit{.cheap = FitMethod::approx_snap})), InputError);
}

TEST(BuildOptionsTest, AutoUsesTheMediumFitterBetweenTheThresholds) {
  // tight = cheap = pca and medium = aabb: exactly the nodes of [100, 1000) triangles are axis-aligned.
  const Mesh mesh = load_relative("meshes/elephant.off");
  const AutoFit policy{.tight_min_triangles = 1000, .tight = FitMethod::pca, .medium_min_triangles = 100,
                       .medium = FitMethod::aabb, .cheap = FitMethod::pca, .or_aabb = false};
  const Tree tree = build(mesh, with(policy));
  ASSERT_TRUE(validate(tree, mesh).ok());
  const std::vector<TriangleRange> ranges = triangle_ranges(tree);
  std::size_t medium = 0;
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const bool in_medium = ranges[i].size() >= 100 && ranges[i].size() < 1000;
    medium += in_medium;
    if (in_medium || ranges[i].size() > 1) EXPECT_EQ(tree.nodes[i].box.axes.isIdentity(), in_medium) << "node " << i;
  }
  EXPECT_GT(medium, 4u);
}

// Above AutoFit::scale_above triangles both thresholds grow with the mesh: on elephant (5,558
// triangles) with scale_above = 1,000, thresholds 1000 and 100 become 5558 and 555, so exactly the
// nodes of [555, 5558) triangles get the medium fitter (marked by axis-aligned boxes) and the
// root the tight one. Refit follows the same rule (it must give the builder's boxes).
// AutoFit::search_from_parent: below the root, a normal-bopt node (2-63 triangles) keeps the box
// along its parent's axes where its Bopt box is larger, so its box is never larger than that one
// (to the float rounding of the stored boxes); with the search off it falls back on PCA instead,
// and some nodes' boxes are larger than the box along the parent's axes. Both trees are valid.
TEST(BuildOptionsTest, AutoSearchesFromTheParentBox) {
  const Mesh mesh = load_relative("meshes/elephant.off");
  std::size_t larger_on_its_own = 0;
  for (const bool from_parent : {true, false}) {
    SCOPED_TRACE(from_parent ? "from the parent" : "on its own");
    const Tree tree = build(mesh, with(AutoFit{.search_from_parent = from_parent}));
    ASSERT_TRUE(validate(tree, mesh).ok());
    const std::vector<TriangleRange> ranges = triangle_ranges(tree);
    std::vector<std::uint32_t> parent(tree.nodes.size(), 0);
    for (std::size_t i = 0; i < tree.nodes.size(); ++i)
      if (!tree.nodes[i].is_leaf()) parent[tree.nodes[i].first] = parent[tree.nodes[i].first + 1] = static_cast<std::uint32_t>(i);
    std::size_t checked = 0;
    for (std::size_t i = 1; i < tree.nodes.size(); ++i) {
      const std::size_t n = ranges[i].size();
      if (n < 2 || n >= 64) continue;
      std::vector<Vec3> corners;
      for (std::size_t p = ranges[i].begin; p < ranges[i].end; ++p)
        for (const std::uint32_t v : mesh.triangles[tree.triangle_order[p]]) corners.push_back(mesh.vertices[v]);
      const double along_parent =
          fit_detail::box_with_axes(corners, tree.nodes[parent[i]].box.axes_d(), corners.front()).volume();
      const double volume = tree.nodes[i].box.volume();
      // The stored box is rounded outward to floats (axes to ~6e-8, so each extent may grow by
      // ~1e-7 of the largest): slack for a growth of 1e-6 of the largest extent on every side.
      const Vec3 h = tree.nodes[i].box.half_extents_d();
      const double slack = 8.0 * (h.x() * h.y() + h.y() * h.z() + h.x() * h.z()) * 2e-6 * h.maxCoeff();
      ++checked;
      if (from_parent) EXPECT_LE(volume, along_parent + slack) << "node " << i << ", " << n << " triangles";
      else larger_on_its_own += volume > along_parent + slack;
    }
    EXPECT_GT(checked, 500u);
  }
  EXPECT_GT(larger_on_its_own, 0u);
}

// A flat part (CAD meshes have them): a grid of triangles in the plane z = 0, turned 30 degrees
// about z. Every box in the plane has a volume of rounding noise, and the axis-aligned box
// exactly zero, so comparing volumes alone kept the AABB (or, in normal-bopt, the fallback box)
// over the minimum-area rectangle. Boxes of flat sets are compared by area (smaller_box): no node
// keeps a box of larger area than its AABB's, and the small (normal-bopt) nodes get their
// minimum-area rectangle.
TEST(BuildOptionsTest, AutoGivesFlatNodesTheirSmallestRectangle) {
  Mesh mesh;
  constexpr int kCells = 12;
  const double c = std::cos(0.5235987755982988), s = std::sin(0.5235987755982988);
  for (int i = 0; i <= kCells; ++i)
    for (int j = 0; j <= kCells; ++j) mesh.vertices.emplace_back(c * i - s * j * 0.7, s * i + c * j * 0.7, 0.0);
  const auto at = [](int i, int j) { return static_cast<std::uint32_t>(i * (kCells + 1) + j); };
  for (int i = 0; i < kCells; ++i)
    for (int j = 0; j < kCells; ++j) {
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  const Tree tree = build(mesh, with(AutoFit{}));
  ASSERT_TRUE(validate(tree, mesh).ok());
  const std::vector<TriangleRange> ranges = triangle_ranges(tree);
  std::size_t small = 0;
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    std::vector<Vec2> points;
    Aabb bounds;
    for (std::size_t p = ranges[i].begin; p < ranges[i].end; ++p)
      for (const std::uint32_t v : mesh.triangles[tree.triangle_order[p]]) {
        points.emplace_back(mesh.vertices[v].x(), mesh.vertices[v].y());
        bounds.extend(mesh.vertices[v]);
      }
    const Vec3 h = tree.nodes[i].box.half_extents_d();
    std::array<double, 3> e = {2 * h.x(), 2 * h.y(), 2 * h.z()};
    std::sort(e.begin(), e.end());
    ASSERT_LE(e[0], 1e-6 * e[2]) << "node " << i;  // flat (to the float rounding of its axes)
    const double area = e[1] * e[2];
    const Vec3 d = bounds.max - bounds.min;
    // Slack for the float rounding of the stored box (extents grow by ~1e-7 of the largest).
    const double slack = 4e-6 * e[2] * e[2];
    EXPECT_LE(area, d.x() * d.y() + slack) << "node " << i;
    if (ranges[i].size() < 2 || ranges[i].size() >= 64) continue;
    ++small;
    const Rect2 want = min_area_rect(std::span<const Vec2>(points.data(), convex_hull_2d(points)));
    EXPECT_LE(area, want.area() + slack) << "node " << i << ", " << ranges[i].size() << " triangles";
  }
  EXPECT_GT(small, 10u);
}

TEST(BuildOptionsTest, AutoScalesItsThresholdsWithTheMesh) {
  const Mesh mesh = load_relative("meshes/elephant.off");
  ASSERT_EQ(mesh.triangles.size(), 5558u);
  const AutoFit policy{.tight_min_triangles = 1000, .tight = FitMethod::pca, .medium_min_triangles = 100,
                       .medium = FitMethod::aabb, .cheap = FitMethod::pca, .or_aabb = false, .scale_above = 1000};
  EXPECT_EQ(detail::scaled_threshold(policy, 1000, 5558), 5558u);
  EXPECT_EQ(detail::scaled_threshold(policy, 100, 5558), 555u);
  EXPECT_EQ(detail::scaled_threshold(policy, 100, 1000), 100u);  // not above scale_above: unchanged
  EXPECT_EQ(detail::scaled_threshold(AutoFit{.scale_above = 0}, 100, 5558), 100u);
  const Tree tree = build(mesh, with(policy));
  ASSERT_TRUE(validate(tree, mesh).ok());
  Tree refitted = tree;
  refit(refitted, mesh, {.fitter = policy});
  const std::vector<TriangleRange> ranges = triangle_ranges(tree);
  std::size_t medium = 0, small_medium = 0;
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const std::size_t n = ranges[i].size();
    const bool in_medium = n >= 555 && n < 5558;
    medium += in_medium;
    small_medium += in_medium && n < 1000;  // medium only because the thresholds grew
    if (in_medium || n > 1) {
      EXPECT_EQ(tree.nodes[i].box.axes.isIdentity(), in_medium) << "node " << i << ", " << n << " triangles";
      EXPECT_EQ(refitted.nodes[i].box.axes.isIdentity(), in_medium) << "refit, node " << i;
    }
  }
  EXPECT_GT(small_medium, 2u);
  EXPECT_GT(medium, small_medium);
}

// The tight tier's large nodes orient their box on column extremes (AutoFit::column_extremes_above):
// on the root of a mesh subdivided twice (midpoints: many points on the hull's faces, the case
// that made the full hull slow), a box oriented on the extremes and measured over all vertices is
// within 2% of approx's box on the full hull, from a small fraction of the points. The bound
// fails if the extremes missed a side of the set (e.g. only the low points were kept).
TEST(BuildOptionsTest, ColumnExtremesOrientAsWellAsTheFullHull) {
  for (const char* name : {"meshes/elephant.off", "meshes/knot1.off"}) {
    const Mesh mesh = subdivide_midpoints(subdivide_midpoints(load_relative(name)));
    std::vector<Vec3> extremes;
    detail::column_extremes(mesh.vertices, extremes);
    EXPECT_LT(extremes.size(), mesh.vertices.size() / 4) << name;
    const FitOptions approx{.method = FitMethod::approx};
    const Obb full = fit_points(mesh.vertices, approx);
    const Obb oriented = fit_points(extremes, approx);
    const Obb box = fit_detail::box_with_axes(mesh.vertices, oriented.axes, oriented.center);
    EXPECT_LT(box.volume(), 1.02 * full.volume()) << name;
    for (const Vec3& v : mesh.vertices) ASSERT_TRUE(box.contains(v, 1e-9)) << name;
  }
}

// With the threshold lowered to 200 vertices the extremes orient every tight node of the shipped
// meshes (down to 400 triangles): every box still contains its node.
TEST(BuildOptionsTest, ColumnExtremesTreesAreValid) {
  for (const char* name : {"meshes/elephant.off", "meshes/knot1.off"}) {
    const Mesh mesh = load_relative(name);
    const Tree full = build(mesh, with(AutoFit{.tight_min_triangles = 400, .column_extremes_above = 0}));
    const Tree tree = build(mesh, with(AutoFit{.tight_min_triangles = 400, .column_extremes_above = 200}));
    const TreeCheck check = validate(tree, mesh);
    EXPECT_TRUE(check.ok()) << name << "\n" << check.summary();
    EXPECT_FALSE(same_nodes(full, tree)) << name << ": the threshold changed nothing";
  }
}

// ------------------------------------------------------------------ validate finds problems

TEST(ValidateTree, NamesTheBrokenNode) {
  const Mesh mesh = load_relative("meshes/elephant.off");
  const Tree good = build(mesh, with(FitMethod::pca));
  ASSERT_TRUE(validate(good, mesh).ok());

  Tree shrunk = good;
  shrunk.nodes[5].box.half_extents *= 0.5f;
  TreeCheck c = validate(shrunk, mesh);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.errors[0].find("node 5 "), std::string::npos) << c.errors[0];
  EXPECT_NE(c.errors[0].find("does not contain"), std::string::npos) << c.errors[0];

  Tree duplicate = good;
  duplicate.triangle_order[3] = duplicate.triangle_order[4];
  c = validate(duplicate, mesh);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.summary().find("more than once"), std::string::npos) << c.summary();

  Tree out_of_range = good;
  out_of_range.nodes[0].first = static_cast<std::uint32_t>(good.nodes.size() - 1);
  c = validate(out_of_range, mesh);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.errors[0].find("node 0: children"), std::string::npos) << c.errors[0];

  Tree cycle = good;
  const std::uint32_t child = cycle.nodes[0].first;
  ASSERT_FALSE(cycle.nodes[child].is_leaf());
  cycle.nodes[child].first = 0;
  c = validate(cycle, mesh);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.summary().find("reached twice"), std::string::npos) << c.summary();

  Tree bad_leaf = good;
  for (Node& node : bad_leaf.nodes)
    if (node.is_leaf()) {
      node.first = static_cast<std::uint32_t>(mesh.triangles.size());
      break;
    }
  EXPECT_FALSE(validate(bad_leaf, mesh).ok());

  Tree skewed = good;
  skewed.nodes[2].box.axes(0, 1) += 0.1f;
  c = validate(skewed, mesh);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.errors[0].find("node 2: box axes are not orthonormal"), std::string::npos) << c.errors[0];

  EXPECT_FALSE(validate(good, test::first_triangles(mesh, 100)).ok());  // another mesh
  EXPECT_FALSE(validate(Tree{}, mesh).ok());
}

}  // namespace
}  // namespace tightbvh
