// Every fitter and the builder on meshes derived from the shipped ones (derived_meshes.hpp):
// midpoint-subdivided once and twice, shifted by 1e6, scaled by 1e-6 and 1e6, triangles
// duplicated, flat grids exact and with 1e-12 noise. Subdivided meshes have nodes with sliver hull
// faces, on which the hull-based fitters must not throw.
//
// The suite runs a sample: knot1's family and the grids; convex_hull on every fourth node of a pca
// tree (every hull-based fitter starts there; about 1 node in 10,000 has sliver faces), the
// default and pca trees validated in full (every node's box contains its triangles), every
// fitter on sampled nodes. TIGHTBVH_FULL_SWEEP=1 runs
// all shipped meshes, the hull of every node, 3,000 sampled nodes per fitter and mesh, and a
// whole validated tree with every fitter (exact up to 30,000 triangles, approx-snap up to 64)
// (scripts/robustness-sweep).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include "../fit/test_util.hpp"
#include "derived_meshes.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/hull.hpp"
#include "tightbvh/tree_walk.hpp"
#include "tightbvh/validate_tree.hpp"

namespace tightbvh {
namespace {

bool full_sweep() {
  const char* value = std::getenv("TIGHTBVH_FULL_SWEEP");
  return value != nullptr && std::string(value) == "1";
}

constexpr FitMethod kMethods[] = {FitMethod::aabb,   FitMethod::pca,         FitMethod::pca_vertex, FitMethod::diameter,
                                  FitMethod::approx, FitMethod::approx_snap, FitMethod::exact,
                                  FitMethod::eberly2015, FitMethod::approx_kernel, FitMethod::normal_bopt, FitMethod::dito};

// The triangle corners below each node.
std::vector<std::vector<Vec3>> node_corners(const Tree& tree, const Mesh& mesh) {
  const std::vector<TriangleRange> ranges = triangle_ranges(tree);
  std::vector<std::vector<Vec3>> out(tree.nodes.size());
  for (std::size_t n = 0; n < tree.nodes.size(); ++n)
    triangle_corners(mesh, std::span(tree.triangle_order).subspan(ranges[n].begin, ranges[n].size()), out[n]);
  return out;
}

BuildOptions options_for(const Fitter& fitter) {
  BuildOptions options;
  options.fitter = fitter;
  options.threads = 2;
  return options;
}

void expect_valid_tree(const Mesh& mesh, const Fitter& fitter, const std::string& name) {
  SCOPED_TRACE(name + ", fitter " + to_string(fitter));
  Tree tree;
  ASSERT_NO_THROW(tree = build(mesh, options_for(fitter)));
  const TreeCheck check = validate(tree, mesh);
  EXPECT_TRUE(check.ok()) << check.summary();
}

// The largest node a method is run on in the sampled part (exact and approx-snap cost seconds
// on big hulls; the others are cheap enough for any node).
std::size_t max_sampled_corners(FitMethod method) {
  switch (method) {
    case FitMethod::exact:
    case FitMethod::eberly2015:
      return 3 * 256;
    case FitMethod::approx_snap:
      return 3 * 16;
    default:
      return 3 * 4096;
  }
}

// The largest mesh whose whole tree the full sweep builds with a method (exact: tens of
// seconds per 10,000 triangles; approx-snap: seconds per node).
std::size_t max_tree_triangles(FitMethod method) {
  switch (method) {
    case FitMethod::exact:
    case FitMethod::eberly2015:
      return 30'000;
    case FitMethod::approx_snap:
      return 64;
    default:
      return std::size_t{1} << 30;
  }
}

void check_family(const std::vector<test::DerivedMesh>& family) {
  const bool full = full_sweep();
  HullWorkspace hull_workspace;
  ConvexHull3 hull;
  FitWorkspace fit_workspace;
  for (const auto& [name, mesh] : family) {
    SCOPED_TRACE(name);
    // The hull of every node of a pca tree: the common first step of every hull-based fitter.
    const Tree pca_tree = build(mesh, options_for(FitMethod::pca));
    const auto corners = node_corners(pca_tree, mesh);
    std::size_t hulls_failed = 0;
    const std::size_t hull_stride = full ? 1 : 4;  // a quarter of the nodes in the suite: ~50,000 hulls
    for (std::size_t n = 0; n < corners.size(); n += hull_stride) {
      try {
        convex_hull(corners[n], hull, hull_workspace);
        if (hull.dimension != affine_dimension(corners[n]).dimension) ++hulls_failed;
      } catch (const std::exception& e) {
        if (hulls_failed++ == 0) ADD_FAILURE() << "node " << n << " (" << corners[n].size() << " corners): " << e.what();
      }
    }
    EXPECT_EQ(hulls_failed, 0u) << "of " << corners.size() / hull_stride << " nodes";
    // Whole trees, every node's box checked: pca and the default everywhere; every fitter in
    // the full sweep (approx-snap only on small meshes: seconds per node).
    expect_valid_tree(mesh, FitMethod::pca, name);
    expect_valid_tree(mesh, AutoFit{}, name);
    if (full)
      for (const FitMethod method : kMethods)
        if (method != FitMethod::pca && mesh.triangles.size() <= max_tree_triangles(method))
          expect_valid_tree(mesh, method, name);
    // Every fitter on sampled nodes (60 in the suite, 3,000 in the full sweep), boxes checked.
    const std::size_t stride = std::max<std::size_t>(1, corners.size() / (full ? 3000 : 60));
    for (const FitMethod method : kMethods) {
      FitOptions options;
      options.method = method;
      for (std::size_t n = 0; n < corners.size(); n += stride) {
        if (corners[n].size() > max_sampled_corners(method)) continue;
        Obb box;
        try {
          box = fit_triangles(corners[n], options, fit_workspace);
        } catch (const std::exception& e) {
          ADD_FAILURE() << to_string(method) << " on node " << n << ": " << e.what();
          continue;
        }
        EXPECT_TRUE(test::valid_box_containing(box, corners[n])) << to_string(method) << " on node " << n;
      }
    }
  }
}

TEST(Robustness, EveryFitterOnMeshesDerivedFromShippedOnes) {
  const std::vector<std::string> bases =
      full_sweep() ? std::vector<std::string>{"knot1", "knot2", "camel", "fandisk", "elephant"}
                   : std::vector<std::string>{"knot1"};
  for (const std::string& base : bases) {
    const Mesh mesh = load_mesh(test::source_dir() / "meshes" / (base + ".off"));
    check_family(test::derived_meshes(base, mesh));
  }
}

TEST(Robustness, EveryFitterOnFlatGrids) { check_family(test::grid_meshes(full_sweep() ? 64 : 32)); }

}  // namespace
}  // namespace tightbvh
