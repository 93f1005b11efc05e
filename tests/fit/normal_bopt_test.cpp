// normal-bopt (fit.cpp): one Bopt along the thinnest of the triangles' area-weighted normal and
// their own normals, the `auto` tree fitter's method for small nodes. Checked against pca (never
// larger), approx (on real small tree nodes, most of its gain), known answers on planar and
// folded patches, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "node_sets.hpp"
#include "test_util.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/fit.hpp"

namespace tightbvh {
namespace {

using test::NodeSet;
using test::node_sets;
using test::valid_box_containing;

TEST(NormalBopt, ContainsAndNeverLargerThanPcaOnSmallTreeNodes) {
  for (const char* name : {"meshes/knot1.off", "meshes/elephant.off"}) {
    SCOPED_TRACE(name);
    const std::vector<NodeSet> sets = node_sets(name, 2, 63);  // auto's cheap tier
    ASSERT_GE(sets.size(), 1000u);
    double pca_sum = 0, normal_sum = 0, approx_sum = 0;
    FitWorkspace ws;
    for (const NodeSet& s : sets) {
      const Obb box = fit_triangles(s.corners, s.vertices, {.method = FitMethod::normal_bopt}, ws);
      ASSERT_TRUE(valid_box_containing(box, s.corners));
      // The corners alone (repeated vertices) give the same box up to rounding.
      const Obb from_corners = fit_triangles(s.corners, {.method = FitMethod::normal_bopt}, ws);
      EXPECT_NEAR(from_corners.volume(), box.volume(), 1e-9 * box.volume() + 1e-300);
      const double pca = fit_triangles(s.corners, {.method = FitMethod::pca}, ws).volume();
      EXPECT_LE(box.volume(), pca * (1 + 1e-12));  // the PCA box is kept when smaller
      pca_sum += pca;
      normal_sum += box.volume();
      approx_sum += fit_triangles(s.corners, s.vertices, {.method = FitMethod::approx}, ws).volume();
    }
    const double share = (pca_sum - normal_sum) / (pca_sum - approx_sum);
    RecordProperty(std::string("share_of_approx_gain_") + (name[7] == 'k' ? "knot1" : "elephant"), std::to_string(share));
    // Measured: 67% (knot1) and 65% (elephant) of approx's volume gain over pca on these nodes;
    // along the area-weighted normal alone (without the triangles' own normals as candidates) 43%
    // and 32%, which this bound rejects. What it gains in queries is more (collide_test:
    // AutoTreesNeedAboutTheBoxTestsOfApproxTrees).
    EXPECT_GE(share, 0.55);
  }
}

TEST(NormalBopt, PlanarPatchGetsItsMinimumAreaRectangle) {
  // A 4 x 1 rectangle, tilted, triangulated as a fan from an interior point, with extra interior
  // vertices: the minimum box is the rectangle itself (zero thickness).
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 r = test::random_rotation(rng);
    const Vec3 offset(1e3 * trial, -7.0, 0.5);
    const auto at = [&](double x, double y) { return Vec3(r * Vec3(x, y, 0.0) + offset); };
    const std::vector<Vec3> rim{at(-2, -0.5), at(2, -0.5), at(2, 0.5), at(-2, 0.5)};
    const Vec3 inside = at(0.3, 0.1);
    std::vector<Vec3> corners;
    for (int i = 0; i < 4; ++i) corners.insert(corners.end(), {inside, rim[i], rim[(i + 1) % 4]});
    const Obb box = fit_triangles(corners, {.method = FitMethod::normal_bopt});
    ASSERT_TRUE(valid_box_containing(box, corners));
    Vec3 e = box.half_extents;
    std::sort(e.data(), e.data() + 3);
    EXPECT_NEAR(e[2], 2.0, 1e-9 * (1 + offset.norm()));
    EXPECT_NEAR(e[1], 0.5, 1e-9 * (1 + offset.norm()));
    EXPECT_LT(e[0], 1e-9 * (1 + offset.norm()));
    // pca's box of the same patch is rotated within the plane (the fan's weights skew the
    // covariance) and larger in area.
  }
}

TEST(NormalBopt, FoldedPatchIsFlushWithItsThinnestTrianglePlane) {
  // A 4 x 1 rectangle (two triangles) with a small flap folded up along one long edge: the
  // area-weighted normal leans towards the flap, but the patch is thinnest across the rectangle's
  // plane (the flap's height). The box must lie flush with that plane.
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 r = test::random_rotation(rng);
    const Vec3 offset(-3.0, 1e3 * trial, 2.0);
    const auto at = [&](double x, double y, double z) { return Vec3(r * Vec3(x, y, z) + offset); };
    const double flap = 0.3;  // the flap's height above the plane
    const std::vector<Vec3> corners{at(-2, -0.5, 0), at(2, -0.5, 0),      at(2, 0.5, 0),  //
                                    at(-2, -0.5, 0), at(2, 0.5, 0),       at(-2, 0.5, 0),
                                    at(-1, 0.5, 0),  at(1, 0.5, 0),       at(0, 0.4, flap)};
    const Obb box = fit_triangles(corners, {.method = FitMethod::normal_bopt});
    ASSERT_TRUE(valid_box_containing(box, corners));
    const Vec3 plane_normal = r.col(2);
    Eigen::Index thin = 0;
    box.half_extents.minCoeff(&thin);
    EXPECT_NEAR(std::abs(box.axes.col(thin).dot(plane_normal)), 1.0, 1e-9);
    EXPECT_NEAR(2 * box.half_extents[thin], flap, 1e-9 * (1 + offset.norm()));
    // The rectangle's outline in the plane: 4 x 1.
    EXPECT_NEAR(box.volume(), 4.0 * 1.0 * flap, 1e-9 * (1 + offset.norm()));
  }
}

TEST(NormalBopt, PointsWithoutTrianglesUseThePlaneOfBestFit) {
  std::vector<Vec3> grid;  // a tilted planar grid: flat box
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 10; ++j) grid.emplace_back(i, j, 0.3 * i + 0.7 * j);
  const Obb flat = fit_points(grid, {.method = FitMethod::normal_bopt});
  EXPECT_TRUE(valid_box_containing(flat, grid));
  EXPECT_LT(flat.half_extents.minCoeff(), 1e-9 * flat.half_extents.maxCoeff());
  EXPECT_LE(flat.volume(), fit_points(grid, {.method = FitMethod::pca}).volume() * (1 + 1e-12));
  const std::vector<Vec3> blob = test::gaussian_points(200, 5);
  EXPECT_TRUE(valid_box_containing(fit_points(blob, {.method = FitMethod::normal_bopt}), blob));
}

TEST(NormalBopt, DegenerateAndBadInput) {
  // Collinear, one point, and triangles whose normals cancel (two copies, opposite orientation).
  const std::vector<Vec3> line{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, {4, 4, 4}, {5, 5, 5}};
  EXPECT_TRUE(valid_box_containing(fit_triangles(line, {.method = FitMethod::normal_bopt}), line));
  const std::vector<Vec3> one{{1e6, -2, 3}, {1e6, -2, 3}, {1e6, -2, 3}};
  EXPECT_TRUE(valid_box_containing(fit_triangles(one, {.method = FitMethod::normal_bopt}), one));
  const std::vector<Vec3> cancel{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 1, 0}, {1, 0, 0}};
  EXPECT_TRUE(valid_box_containing(fit_triangles(cancel, {.method = FitMethod::normal_bopt}), cancel));
  EXPECT_THROW((void)fit_points(std::vector<Vec3>{}, {.method = FitMethod::normal_bopt}), InputError);
  const std::vector<Vec3> nan{{0, 0, 0}, {1, 0, 0}, {0, std::nan(""), 0}};
  EXPECT_THROW((void)fit_triangles(nan, {.method = FitMethod::normal_bopt}), InputError);
  const std::vector<Vec3> inf{{0, 0, 0}, {1, 0, 0}, {0, INFINITY, 0}};
  EXPECT_THROW((void)fit_points(inf, {.method = FitMethod::normal_bopt}), InputError);
  EXPECT_EQ(parse_fit_method("normal-bopt"), FitMethod::normal_bopt);
}

}  // namespace
}  // namespace tightbvh
