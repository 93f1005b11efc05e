// Tests of grid_search's internals (src/fit/grid_search.cpp): the volume bound that lets the
// grid and tilt searches skip directions must never exceed the Bopt volume it stands for.
#include <gtest/gtest.h>

#include <random>

#include "fit/fitters.hpp"
#include "test_util.hpp"

namespace tightbvh {
namespace {

using fit_detail::HullGeometry;

// Bound <= Bopt(S, {v}) for random (non-unit) directions, on a hull geometry and on the
// hull-free geometry of the same points; and the bound is not vacuous on solid sets.
void expect_bound_below_bopt(std::span<const Vec3> points, std::uint64_t seed) {
  const ConvexHull3 hull = convex_hull(points);
  ASSERT_EQ(hull.dimension, 3);
  HullGeometry with_hull, without_hull;
  with_hull.reset(hull, points[0]);
  without_hull.reset_points(points, points[0]);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  for (const HullGeometry* g : {&with_hull, &without_hull}) {
    fit_detail::BoptScratch scratch;
    const fit_detail::VolumeBound bound(*g, fit_detail::lemma_box(*g, scratch));
    double sum_ratio = 0.0;
    constexpr int kDirections = 200;
    for (int i = 0; i < kDirections; ++i) {
      const Vec3 v = Vec3(normal(rng), normal(rng), normal(rng)) * std::exp(normal(rng));
      const double bopt_volume = fit_detail::bopt(*g, v, scratch).volume();
      EXPECT_LE(bound(v), bopt_volume * (1 + 1e-12)) << "direction " << i;
      sum_ratio += bound(v) / bopt_volume;
    }
    EXPECT_GT(sum_ratio / kDirections, 0.1);
  }
}

TEST(VolumeBound, NeverAboveBoptOnRandomSetsAndMeshes) {
  for (std::uint64_t seed = 1; seed <= 8; ++seed) expect_bound_below_bopt(test::gaussian_points(6 + 10 * seed, seed), seed);
  for (const char* name : {"meshes/knot1.off", "meshes/elephant.off"}) {
    const auto points = test::mesh_vertices(name);
    ASSERT_FALSE(points.empty()) << name;
    expect_bound_below_bopt(points, 99);
  }
}

}  // namespace
}  // namespace tightbvh
