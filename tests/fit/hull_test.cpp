// Tests of the convex hulls and rotating calipers (src/fit/hull.cpp, src/fit/min_rect.cpp).
#include "tightbvh/hull.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "test_util.hpp"
#include "tightbvh/min_rect.hpp"
#include "tightbvh/fit.hpp"
#include "tightbvh/mesh.hpp"
#include "../../src/predicates.hpp"

namespace tightbvh {
namespace {

// Every point is on the inner side of every face plane; Euler's formula holds; every edge
// joins two faces that contain it.
void expect_valid_solid_hull(const ConvexHull3& hull, std::span<const Vec3> points) {
  ASSERT_EQ(hull.dimension, 3);
  const double scale = bounds_of(points).diagonal();
  const auto nv = static_cast<long>(hull.vertices.size());
  const auto ne = static_cast<long>(hull.edges.size());
  const auto nf = static_cast<long>(hull.faces.size());
  EXPECT_EQ(nv - ne + nf, 2);
  for (std::size_t f = 0; f < hull.faces.size(); ++f) {
    const Vec3& n = hull.face_normals[f];
    EXPECT_NEAR(n.norm(), 1.0, 1e-12);
    const Vec3& a = hull.vertices[hull.faces[f][0]];
    for (const Vec3& p : points) EXPECT_LE(n.dot(p - a), 1e-9 * scale);
  }
  for (const HullEdge& e : hull.edges)
    for (std::uint32_t f : e.face) {
      const auto& face = hull.faces[f];
      EXPECT_TRUE(std::count(face.begin(), face.end(), e.vertex[0]) == 1 &&
                  std::count(face.begin(), face.end(), e.vertex[1]) == 1);
    }
  for (std::size_t i = 0; i < hull.vertices.size(); ++i)
    EXPECT_EQ(hull.vertices[i], points[hull.input_index[i]]);
}

TEST(Hull3, CubeWithInteriorAndDuplicatePointsAndCoplanarFaces) {
  std::vector<Vec3> points;
  for (int i = 0; i < 8; ++i) points.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  for (int i = 0; i < 8; ++i) points.push_back(points[i]);  // duplicates
  points.emplace_back(0.5, 0.5, 0.5);                         // interior
  points.emplace_back(0.5, 0.5, 1.0);                         // on a face
  points.emplace_back(0.5, 0.0, 0.0);                         // on an edge
  const ConvexHull3 hull = convex_hull(points);
  expect_valid_solid_hull(hull, points);
  EXPECT_EQ(hull.vertices.size(), 8u);
}

TEST(Hull3, RandomSetsAndSphere) {
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const auto points = test::gaussian_points(10 + 50 * seed, seed);
    expect_valid_solid_hull(convex_hull(points), points);
  }
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  std::vector<Vec3> sphere(500);
  for (auto& p : sphere) p = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
  const ConvexHull3 hull = convex_hull(sphere);
  expect_valid_solid_hull(hull, sphere);
  EXPECT_EQ(hull.vertices.size(), 500u);
}

// Meshes whose points mostly lie on flat or ruled hull faces (qhull runs with 'Q8': near-inside
// points are not partitioned, which must not let any point end up outside a face).
TEST(Hull3, CorpusMeshesWithManyCoplanarPoints) {
  for (const char* name : {"meshes/corpus/cgal/blade.off", "meshes/corpus/cgal/cylinder_locally_refined.off",
                           "meshes/corpus/cgal/fandisk_large.off"}) {
    const auto points = test::mesh_vertices(name);
    if (points.empty()) continue;  // corpus not fetched
    expect_valid_solid_hull(convex_hull(points), points);
  }
}

TEST(Hull3, FarFromOrigin) {
  auto points = test::gaussian_points(200, 9);
  for (auto& p : points) p += Vec3(1e6, 2e6, -1e6);
  expect_valid_solid_hull(convex_hull(points), points);
}

TEST(Hull3, DegenerateDimensions) {
  EXPECT_EQ(convex_hull(std::vector<Vec3>{{1, 2, 3}, {1, 2, 3}}).dimension, 0);
  const ConvexHull3 line = convex_hull(std::vector<Vec3>{{0, 0, 0}, {2, 2, 2}, {1, 1, 1}, {-1, -1, -1}});
  EXPECT_EQ(line.dimension, 1);
  ASSERT_EQ(line.vertices.size(), 2u);
  EXPECT_NEAR((line.vertices[1] - line.vertices[0]).norm(), std::sqrt(27.0), 1e-12);
  std::vector<Vec3> plane;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uni(-1, 1);
  for (int i = 0; i < 100; ++i) plane.emplace_back(uni(rng), uni(rng), 0.0);
  plane.emplace_back(-2, -2, 0);
  plane.emplace_back(2, -2, 0);
  plane.emplace_back(2, 2, 0);
  plane.emplace_back(-2, 2, 0);
  const ConvexHull3 flat = convex_hull(plane);
  EXPECT_EQ(flat.dimension, 2);
  EXPECT_EQ(flat.vertices.size(), 4u);
  EXPECT_NEAR(std::abs(flat.plane_normal.z()), 1.0, 1e-12);
  EXPECT_THROW((void)convex_hull(std::vector<Vec3>{}), InputError);
}

TEST(Hull2, MonotoneChainDropsCollinearAndDuplicates) {
  std::vector<Vec2> pts{{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {0, 2}, {1, 1}, {0, 0}, {0, 1}};
  const std::size_t n = convex_hull_2d(pts);
  ASSERT_EQ(n, 4u);
  double area = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = pts[i];
    const Vec2& b = pts[(i + 1) % n];
    area += a.x() * b.y() - a.y() * b.x();
  }
  EXPECT_DOUBLE_EQ(area / 2, 4.0);  // counter-clockwise: positive
  std::vector<Vec2> same{{1, 1}, {1, 1}, {1, 1}};
  EXPECT_EQ(convex_hull_2d(same), 1u);
  std::vector<Vec2> line{{0, 0}, {1, 1}, {3, 3}, {2, 2}};
  EXPECT_EQ(convex_hull_2d(line), 2u);
}

// Nearly collinear sets: rounded cross products can keep a point in both the lower and the upper
// chain, which once made the chain longer than the input (a heap overflow found under ASan).
TEST(Hull2, NearlyCollinearSetsGiveAStrictlyConvexHullOfTheInput) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const double slope = unit(rng) * 3, offset = unit(rng);
    std::vector<Vec2> input(3 + trial % 40);
    for (Vec2& p : input) {
      const double t = unit(rng);
      p = Vec2(t, slope * t + offset);
    }
    std::vector<Vec2> hull = input;
    const std::size_t n = convex_hull_2d(hull);
    ASSERT_LE(n, input.size());
    hull.resize(n);
    if (n < 3) continue;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2& a = hull[i];
      const Vec2& b = hull[(i + 1) % n];
      const Vec2& c = hull[(i + 2) % n];
      ASSERT_GT(detail::orient2d(a.x(), a.y(), b.x(), b.y(), c.x(), c.y()), 0) << "trial " << trial;
      for (const Vec2& p : input) ASSERT_GE(detail::orient2d(a.x(), a.y(), b.x(), b.y(), p.x(), p.y()), 0);
    }
  }
}

// The input that overflowed the 2D hull inside Bopt: two triangles of elephant.off sharing an edge.
TEST(Hull2, ElephantTrianglesThatOverflowedTheChain) {
  const Mesh mesh = load_mesh(std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/elephant.off");
  std::vector<Vec3> corners;
  for (const std::size_t t : {3984u, 3985u})
    for (const Vec3& c : mesh.corners(t)) corners.push_back(c);
  for (const FitMethod method : {FitMethod::diameter, FitMethod::approx, FitMethod::exact}) {
    const Obb box = fit_triangles(corners, {.method = method});
    for (const Vec3& c : corners) EXPECT_TRUE(box.contains(c, containment_tolerance(box))) << to_string(method);
  }
}

TEST(MinRect, RotatedRectangleIsRecovered) {
  for (double angle : {0.0, 0.3, 0.7853981633974483, 1.2, 2.9}) {
    const Eigen::Rotation2Dd r(angle);
    std::vector<Vec2> pts;
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> ux(-3, 3), uy(-1, 1);
    for (int i = 0; i < 200; ++i) pts.push_back(r * Vec2(ux(rng), uy(rng)));
    for (const Vec2 c : {Vec2(-3, -1), Vec2(3, -1), Vec2(3, 1), Vec2(-3, 1)}) pts.push_back(r * c);
    const std::size_t n = convex_hull_2d(pts);
    const Rect2 rect = min_area_rect(std::span<const Vec2>(pts.data(), n));
    EXPECT_NEAR(rect.area(), 12.0, 1e-9) << angle;  // 6 x 2
  }
}

TEST(MinRect, BruteForceOverEdgeDirections) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<Vec2> pts(5 + trial);
    for (auto& p : pts) p = Vec2(normal(rng), 0.3 * normal(rng));
    const std::size_t n = convex_hull_2d(pts);
    const std::span<const Vec2> poly(pts.data(), n);
    double brute = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 u = (poly[(i + 1) % n] - poly[i]).normalized();
      const Vec2 v(-u.y(), u.x());
      double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
      for (const Vec2& p : poly) {
        a0 = std::min(a0, u.dot(p)), a1 = std::max(a1, u.dot(p));
        b0 = std::min(b0, v.dot(p)), b1 = std::max(b1, v.dot(p));
      }
      brute = std::min(brute, (a1 - a0) * (b1 - b0));
    }
    const Rect2 rect = min_area_rect(poly);
    EXPECT_NEAR(rect.area(), brute, 1e-12 * brute);
    for (const Vec2& p : poly) {
      const Vec2 q(rect.axis.dot(p), -rect.axis.y() * p.x() + rect.axis.x() * p.y());
      EXPECT_TRUE(q.x() >= rect.min.x() - 1e-12 && q.x() <= rect.max.x() + 1e-12);
      EXPECT_TRUE(q.y() >= rect.min.y() - 1e-12 && q.y() <= rect.max.y() + 1e-12);
    }
  }
}

}  // namespace
}  // namespace tightbvh
