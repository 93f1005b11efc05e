// dito (dito.cpp): DiTO-14 of Larsson & Källberg (2011). Checked for containment and against
// pca on real tree nodes (its purpose: tighter than PCA at linear cost), for the minimum-area
// rectangle of a single triangle (one of its candidate frames is flush with the triangle and an
// edge), for degenerate sets, and for bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "node_sets.hpp"
#include "test_util.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/fit.hpp"
#include "tightbvh/min_rect.hpp"

namespace tightbvh {
namespace {

using test::NodeSet;
using test::node_sets;
using test::valid_box_containing;

TEST(Dito, ContainsAndBeatsPcaInSumOnTreeNodes) {
  for (const char* name : {"meshes/knot1.off", "meshes/elephant.off"}) {
    SCOPED_TRACE(name);
    const std::vector<NodeSet> sets = node_sets(name, 16);
    ASSERT_GE(sets.size(), 300u);
    double pca_sum = 0, dito_sum = 0;
    FitWorkspace ws;
    for (const NodeSet& s : sets) {
      const Obb box = fit_triangles(s.corners, s.vertices, {.method = FitMethod::dito}, ws);
      ASSERT_TRUE(valid_box_containing(box, s.corners));
      dito_sum += box.volume();
      pca_sum += fit_triangles(s.corners, {.method = FitMethod::pca}, ws).volume();
    }
    // Measured: 0.929 (knot1) and 0.871 (elephant). PCA's axes follow the surface's mass, DiTO's
    // its extremes.
    EXPECT_LT(dito_sum, 0.95 * pca_sum);
  }
}

// A single triangle: the frame of its plane and one of its edges is a candidate, the volume is 0
// for every frame of its plane, and the area breaks the tie, so the box's face is the triangle's
// minimum-area rectangle (whose side lies along an edge).
TEST(Dito, SingleTriangleGetsItsMinimumAreaRectangle) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Mat3 r = test::random_rotation(rng);
    const std::array<Vec2, 3> flat = {Vec2(unit(rng), unit(rng)), Vec2(unit(rng), unit(rng)), Vec2(unit(rng), unit(rng))};
    std::vector<Vec3> corners;
    for (const Vec2& p : flat) corners.push_back(r * Vec3(p.x(), p.y(), 0.0) + Vec3(3, -2, 1));
    const Obb box = fit_triangles(corners, {.method = FitMethod::dito});
    ASSERT_TRUE(valid_box_containing(box, corners));
    const Vec3 e = 2.0 * box.half_extents;
    std::array<double, 3> sides = {e.x(), e.y(), e.z()};
    std::sort(sides.begin(), sides.end());
    EXPECT_LE(sides[0], 1e-12) << "trial " << trial;  // flush with the plane
    std::vector<Vec2> hull(flat.begin(), flat.end());
    const Rect2 want = min_area_rect(std::span<const Vec2>(hull.data(), convex_hull_2d(hull)));
    EXPECT_NEAR(sides[1] * sides[2], want.area(), 1e-9 * want.area()) << "trial " << trial;
  }
}

TEST(Dito, DegenerateSetsGiveFiniteBoxes) {
  const std::vector<Vec3> point(5, Vec3(1, 2, 3));
  const Obb p = fit_points(point, {.method = FitMethod::dito});
  EXPECT_TRUE(valid_box_containing(p, point));
  EXPECT_EQ(p.volume(), 0.0);
  std::vector<Vec3> line;
  for (int i = 0; i < 9; ++i) line.push_back(Vec3(1, 2, 3) + i * Vec3(0.3, -0.2, 0.7));
  const Obb l = fit_points(line, {.method = FitMethod::dito});
  EXPECT_TRUE(valid_box_containing(l, line));
  EXPECT_NEAR(l.volume(), 0.0, 1e-15);
  EXPECT_NEAR(2.0 * l.half_extents.maxCoeff(), (line.back() - line.front()).norm(), 1e-12);
  // Duplicated and far-away points keep their precision (relative to a point of the set).
  std::vector<Vec3> far = test::mesh_vertices("meshes/knot1.off");
  for (Vec3& v : far) v += Vec3(1e6, -1e6, 1e6);
  far.insert(far.end(), far.begin(), far.begin() + 100);
  EXPECT_TRUE(valid_box_containing(fit_points(far, {.method = FitMethod::dito}), far));
}

TEST(Dito, BadInputIsAnInputError) {
  EXPECT_THROW((void)fit_points(std::vector<Vec3>{}, {.method = FitMethod::dito}), InputError);
  const std::vector<Vec3> nan{{0, 0, 0}, {1, 0, 0}, {0, std::nan(""), 0}};
  EXPECT_THROW((void)fit_points(nan, {.method = FitMethod::dito}), InputError);
  EXPECT_EQ(parse_fit_method("dito"), FitMethod::dito);
}

}  // namespace
}  // namespace tightbvh
