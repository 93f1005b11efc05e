#include "tightbvh/refit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "build_test_util.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/tree_stats.hpp"
#include "tightbvh/validate_tree.hpp"
#include "tree/node_fit.hpp"

namespace tightbvh {
namespace {

Mesh load_relative(const std::string& relative) { return load_mesh(test::source_dir() / relative); }

// ------------------------------------------------------------------ deformations (unit-box meshes)

// Bends the mesh around the z axis: x becomes an arc of `angle` radians over the mesh's x extent.
Mesh bent(Mesh mesh, double angle) {
  const Aabb bounds = bounds_of(mesh.vertices);
  const double length = bounds.max.x() - bounds.min.x();
  const double radius = length / angle;
  const Vec3 c = bounds.center();
  for (Vec3& v : mesh.vertices) {
    const double theta = (v.x() - c.x()) / radius;
    const double r = radius - (v.y() - c.y());
    v = Vec3(c.x() + r * std::sin(theta), c.y() + radius - r * std::cos(theta), v.z());
  }
  return mesh;
}

// y += amplitude * sin(2 pi waves x / extent): a travelling wave through the mesh.
Mesh sine_wave(Mesh mesh, double amplitude, double waves) {
  const Aabb bounds = bounds_of(mesh.vertices);
  const double length = bounds.max.x() - bounds.min.x();
  for (Vec3& v : mesh.vertices)
    v.y() += amplitude * std::sin(2.0 * std::numbers::pi * waves * (v.x() - bounds.min.x()) / length);
  return mesh;
}

Pose random_pose(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  const Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  Pose pose;
  pose.rotation = q.normalized().toRotationMatrix();
  pose.translation = Vec3(normal(rng), normal(rng), normal(rng));
  return pose;
}

Mesh moved(Mesh mesh, const Pose& pose) {
  for (Vec3& v : mesh.vertices) v = pose.apply(v);
  return mesh;
}

Mesh stretched(Mesh mesh, const Vec3& factors) {
  for (Vec3& v : mesh.vertices) v = v.cwiseProduct(factors);
  return mesh;
}

struct Deformation {
  std::string name;
  Mesh mesh;
};

std::vector<Deformation> deformations(const Mesh& mesh) {
  std::mt19937_64 rng(13);
  return {{"undeformed", mesh},
          {"bend 90 degrees", bent(mesh, std::numbers::pi / 2)},
          {"bend 300 degrees", bent(mesh, 5.0)},
          {"sine wave", sine_wave(mesh, 0.15, 2.0)},
          {"rigid motion", moved(mesh, random_pose(rng))},
          {"stretch 4 x 0.25 x 1", stretched(mesh, Vec3(4.0, 0.25, 1.0))}};
}

RefitOptions with(const Fitter& fitter, unsigned threads = 2) {
  RefitOptions options;
  options.fitter = fitter;
  options.threads = threads;
  return options;
}

Tree build_with(const Mesh& mesh, const Fitter& fitter, std::uint32_t leaf_size = 1) {
  BuildOptions options;
  options.fitter = fitter;
  options.leaf_size = leaf_size;
  options.threads = 2;
  return build(mesh, options);
}

bool same_bits(const Obb& a, const Obb& b) { return std::memcmp(&a, &b, sizeof(Obb)) == 0; }
bool same_bits(const CompactBox& a, const CompactBox& b) { return std::memcmp(&a, &b, sizeof(CompactBox)) == 0; }

// Same topology, boxes untouched by the comparison.
void expect_same_topology(const Tree& a, const Tree& b) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(a.triangle_order, b.triangle_order);
  for (std::size_t i = 0; i < a.nodes.size(); ++i) {
    EXPECT_EQ(a.nodes[i].first, b.nodes[i].first) << "node " << i;
    EXPECT_EQ(a.nodes[i].count, b.nodes[i].count) << "node " << i;
  }
}

// ------------------------------------------------------------------ undeformed: the builder's boxes

// aabb boxes do not depend on the order of the corners: refit reproduces the build bit for bit.
TEST(Refit, UndeformedAabbEqualsBuildBitForBit) {
  const Mesh mesh = load_relative("meshes/elephant.off");
  const Tree built = build_with(mesh, FitMethod::aabb);
  const Tree tree = refitted(built, mesh, with(FitMethod::aabb));
  expect_same_topology(built, tree);
  for (std::size_t i = 0; i < tree.nodes.size(); ++i)
    EXPECT_TRUE(same_bits(built.nodes[i].box, tree.nodes[i].box)) << i;
}

// pca: the fast path sums the moments bottom up, the builder per node in another corner order; the
// boxes agree to rounding (axes up to sign), and single-triangle leaves bit for bit. Meshes without
// nodes of tied eigenvalues (fandisk has some: there rounding picks the axes).
void expect_pca_boxes_match(const Mesh& mesh, FitMethod method) {
  const Tree built = build_with(mesh, method);
  const Tree tree = refitted(built, mesh, with(method));
  expect_same_topology(built, tree);
  const double scale = bounds_of(mesh.vertices).diagonal();
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const Obb want = built.nodes[i].box.obb();
    const Obb got = tree.nodes[i].box.obb();
    if (tree.nodes[i].count == 1 && detail::triangle_box(mesh.corners(tree.triangle_order[tree.nodes[i].first]))) {
      EXPECT_TRUE(same_bits(want, got)) << "leaf " << i;
      continue;
    }
    // Flat nodes (CAD patches): the thickness, hence the volume, is rounding noise. Otherwise each
    // half extent may differ by the float rounding of the stored center (refit measures the range
    // along the float axes, the builder along the double ones, and both round the center to the
    // nearest float): a few units of 2^-24 of the center's magnitude.
    if (want.half_extents.minCoeff() > 1e-9 * scale) {
      const double face = 4.0 * std::ldexp(want.center.cwiseAbs().maxCoeff() + want.half_extents.maxCoeff(), -24);
      const double relative = 1e-7 + face * want.half_extents.cwiseInverse().sum();
      EXPECT_NEAR(got.volume(), want.volume(), relative * want.volume()) << "node " << i;
    }
    EXPECT_LE((got.center - want.center).norm(), 1e-7 * scale) << "node " << i;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(std::abs(got.axes.col(k).dot(want.axes.col(k))), 1.0, 1e-7) << "node " << i << " axis " << k;
      EXPECT_NEAR(got.half_extents[k], want.half_extents[k], 1e-7 * scale) << "node " << i << " axis " << k;
    }
  }
}

TEST(Refit, UndeformedPcaMatchesBuild) {
  expect_pca_boxes_match(load_relative("meshes/elephant.off"), FitMethod::pca);
  expect_pca_boxes_match(load_relative("meshes/knot1.off"), FitMethod::pca);
}

TEST(Refit, UndeformedPcaVertexMatchesBuild) {
  expect_pca_boxes_match(load_relative("meshes/elephant.off"), FitMethod::pca_vertex);
}

// The generic path (every node fitted from its corners) with a hull-based fitter: about the sum of
// volumes of the build. Not the same boxes: the builder fits approx nodes from their distinct
// vertices with the tree nodes' extras (fit_tree_node_approx: fewer improvement starts, a coarser
// stop, tilts only on large hulls), refit's generic path from the corners with approx's full
// search, so its sum is no larger and within half a percent (measured: -0.14% on this mesh).
TEST(Refit, UndeformedApproxMatchesBuildVolume) {
  const Mesh mesh = test::first_triangles(load_relative("meshes/knot1.off"), 1500);
  const Tree built = build_with(mesh, FitMethod::approx);
  const Tree tree = refitted(built, mesh, with(FitMethod::approx));
  expect_same_topology(built, tree);
  const double want = tree_stats(built).sum_volume, got = tree_stats(tree).sum_volume;
  EXPECT_LE(got, want * (1 + 1e-9));
  EXPECT_GE(got, want * (1 - 5e-3));
}

// ------------------------------------------------------------------ deformed: valid trees

void expect_valid_refits(const Mesh& mesh, const Fitter& fitter, std::uint32_t leaf_size = 1) {
  const Tree built = build_with(mesh, fitter, leaf_size);
  for (const Deformation& d : deformations(mesh)) {
    SCOPED_TRACE(d.name + ", fitter " + to_string(fitter) + ", leaf size " + std::to_string(leaf_size));
    Tree tree = built;
    refit(tree, d.mesh, with(fitter, 1));
    expect_same_topology(built, tree);
    const TreeCheck check = validate(tree, d.mesh);
    EXPECT_TRUE(check.ok()) << check.summary();
    // Any thread count, the same tree bit for bit.
    const Tree two = refitted(built, d.mesh, with(fitter, 2));
    for (std::size_t i = 0; i < tree.nodes.size(); ++i)
      ASSERT_TRUE(same_bits(tree.nodes[i].box, two.nodes[i].box)) << "node " << i;
  }
}

TEST(RefitValidate, PcaOnShippedMeshes) {
  for (const char* name : {"meshes/elephant.off", "meshes/knot1.off"})
    expect_valid_refits(load_relative(name), FitMethod::pca);
}

TEST(RefitValidate, OtherFittersAndLeafSizes) {
  const Mesh mesh = load_relative("meshes/fandisk.off");
  expect_valid_refits(mesh, FitMethod::pca, 4);
  expect_valid_refits(mesh, FitMethod::pca_vertex);
  expect_valid_refits(mesh, FitMethod::aabb, 3);
  const Mesh small = test::first_triangles(mesh, 400);
  expect_valid_refits(small, FitMethod::approx);
  expect_valid_refits(small, AutoFit{.tight_min_triangles = 100});
}

// A tree built over a large mesh has top levels above the task grain (1024 triangles here): those
// are fitted level by level, on both threads.
TEST(RefitValidate, LargeMeshAcrossTaskGrain) {
  const Mesh mesh = subdivide_midpoints(load_relative("meshes/knot1.off"));
  const Tree built = build_with(mesh, FitMethod::pca);
  const Mesh deformed = bent(sine_wave(mesh, 0.1, 3.0), 2.0);
  const Tree one = refitted(built, deformed, with(FitMethod::pca, 1));
  const Tree two = refitted(built, deformed, with(FitMethod::pca, 2));
  const TreeCheck check = validate(one, deformed);
  EXPECT_TRUE(check.ok()) << check.summary();
  for (std::size_t i = 0; i < one.nodes.size(); ++i) ASSERT_TRUE(same_bits(one.nodes[i].box, two.nodes[i].box)) << i;
}

// Degenerate triangles (zero area, repeated vertices) go through pca's corner-covariance fallback.
TEST(RefitValidate, DegenerateTriangles) {
  Mesh mesh = load_relative("meshes/elephant.off");
  for (std::size_t t = 0; t < mesh.triangles.size(); t += 7) mesh.triangles[t][1] = mesh.triangles[t][0];
  const Tree built = build_with(mesh, FitMethod::pca, 2);
  Mesh flat = mesh;
  for (Vec3& v : flat.vertices) v.z() = 0.0;  // every triangle of zero area
  for (const Mesh* m : {&mesh, &flat}) {
    const Tree tree = refitted(built, *m);
    const TreeCheck check = validate(tree, *m);
    EXPECT_TRUE(check.ok()) << check.summary();
  }
}

// ------------------------------------------------------------------ queries on refitted trees

TEST(RefitCollide, SamePairsAsBruteForce) {
  const Mesh a = test::first_triangles(load_relative("meshes/elephant.off"), 1000);
  const Mesh b = test::first_triangles(load_relative("meshes/knot1.off"), 1000);
  const Tree tree_a = build_with(a, FitMethod::pca);
  const Tree tree_b = build(b, {.fitter = FitMethod::pca, .threads = 1});
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> shift(-0.3, 0.3);
  int hits = 0;
  for (const Deformation& d : deformations(a)) {
    if (d.name == "rigid motion") continue;  // moved far away: nothing to find
    const Tree refit_a = refitted(tree_a, d.mesh);
    for (int k = 0; k < 2; ++k) {
      Pose pose_b = random_pose(rng);
      pose_b.translation = bounds_of(d.mesh.vertices).center() + Vec3(shift(rng), shift(rng), shift(rng));
      SCOPED_TRACE(d.name + ", pose " + std::to_string(k));
      const QueryOptions all{.mode = QueryMode::all_pairs};
      const QueryResult got = collide(refit_a, d.mesh, Pose{}, tree_b, b, pose_b, all);
      const QueryResult want = collide_brute_force(d.mesh, Pose{}, b, pose_b, all);
      EXPECT_EQ(got.pairs, want.pairs);
      EXPECT_EQ(collide(refit_a, d.mesh, Pose{}, tree_b, b, pose_b).hit, want.hit);
      hits += want.hit;
    }
  }
  EXPECT_GE(hits, 3);  // the poses do test something
}

// ------------------------------------------------------------------ errors

template <class Fn>
std::string input_error(Fn&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no InputError";
}

TEST(RefitErrors, ClearMessagesAndTreeUnchanged) {
  const Mesh mesh = load_relative("meshes/fandisk.off");
  const Tree built = build_with(mesh, FitMethod::pca);
  const auto expect_error = [&](const Tree& tree, const Mesh& m, const std::string& part) {
    Tree copy = tree;
    const std::string message = input_error([&] { refit(copy, m); });
    EXPECT_NE(message.find(part), std::string::npos) << message;
    EXPECT_EQ(message.rfind("refit", 0), 0u) << message;
    for (std::size_t i = 0; i < copy.nodes.size(); ++i) ASSERT_TRUE(same_bits(copy.nodes[i].box, tree.nodes[i].box));
  };

  Mesh fewer = mesh;
  fewer.triangles.pop_back();
  expect_error(built, fewer,
               "the tree has " + std::to_string(mesh.triangles.size()) + " triangles, the mesh " +
                   std::to_string(fewer.triangles.size()));
  Mesh nan = mesh;
  nan.vertices[42].y() = std::numeric_limits<double>::quiet_NaN();
  expect_error(built, nan, "vertex 42 has a non-finite coordinate");
  Mesh inf = mesh;
  inf.vertices[7].x() = std::numeric_limits<double>::infinity();
  expect_error(built, inf, "vertex 7");
  Mesh bad_index = mesh;
  bad_index.triangles[3][2] = static_cast<std::uint32_t>(mesh.vertices.size());
  expect_error(built, bad_index, "triangle 3: vertex index");

  Tree broken = built;
  broken.nodes[0].first = static_cast<std::uint32_t>(broken.nodes.size());
  expect_error(broken, mesh, "node 0: children");
  broken = built;
  broken.triangle_order[5] = broken.triangle_order[6];
  expect_error(broken, mesh, "appears more than once");
  broken = built;
  broken.triangle_order[5] = static_cast<std::uint32_t>(mesh.triangles.size());
  expect_error(broken, mesh, "triangle_order[5]");
  broken = built;
  const std::uint32_t child = broken.nodes[0].first;
  broken.nodes[child].first = 0,
  broken.nodes[child].count = 0;  // points back at the root
  expect_error(broken, mesh, "reached twice");
  expect_error(Tree{}, mesh, "the tree has 0 triangles");
}

}  // namespace
}  // namespace tightbvh
