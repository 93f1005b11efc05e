// Tests of the minimum-volume enclosing ellipsoid (src/containers/ellipsoid.cpp): known optima
// (cube, regular simplex, points on a given ellipsoid), containment of every input point on the
// shipped meshes and degenerate sets, monotonicity in epsilon, the ball bound, errors.
#include "tightbvh/ellipsoid.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <vector>

#include "../fit/test_util.hpp"
#include "tightbvh/ball.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh {
namespace {

void expect_contains_all(const Ellipsoid& e, const std::vector<Vec3>& points) {
  ASSERT_TRUE(e.center.allFinite() && e.axes.allFinite() && e.radii.allFinite());
  ASSERT_TRUE((e.radii.array() >= 0).all());
  EXPECT_TRUE((e.axes.transpose() * e.axes).isIdentity(1e-12));
  for (std::size_t i = 0; i < points.size(); ++i) ASSERT_TRUE(e.contains(points[i])) << "point " << i;
}

std::string message_of(std::span<const Vec3> p, double epsilon = 0.01) {
  try {
    (void)bounding_ellipsoid(p, epsilon);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Ellipsoid, Errors) {
  EXPECT_EQ(message_of({}), "ellipsoid: empty point set");
  std::vector<Vec3> p(9, Vec3(1, 2, 3));
  p[7].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(message_of(p), "ellipsoid: point 7 has a non-finite coordinate (NaN or Inf)");
  p[7].y() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(message_of(p), "ellipsoid: point 7 has a non-finite coordinate (NaN or Inf)");
  p[7].y() = 0;
  for (double eps : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()})
    EXPECT_EQ(message_of(p, eps), "ellipsoid: epsilon must be a positive number") << eps;
  EXPECT_EQ(message_of(p, 0.5), "");
}

TEST(Ellipsoid, CubeCornersGiveTheCircumsphere) {
  for (double eps : {0.1, 0.01, 0.001}) {
    std::vector<Vec3> p;
    for (int i = 0; i < 8; ++i) p.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
    const Ellipsoid e = bounding_ellipsoid(p, eps);
    expect_contains_all(e, p);
    const double optimum = M_PI * std::sqrt(3.0) / 2.0;  // radius sqrt(3)/2
    EXPECT_GE(e.volume(), optimum * (1 - 1e-12));
    EXPECT_LE(e.volume(), optimum * (1 + eps) * (1 + 1e-12)) << eps;
    EXPECT_LT((e.center - Vec3(0.5, 0.5, 0.5)).norm(), 0.3);
  }
}

TEST(Ellipsoid, RegularTetrahedronGivesTheCircumsphere) {
  // Regular simplex: the MVEE is its circumsphere (radius sqrt(3) for these corners).
  std::mt19937_64 rng(1);
  const Mat3 r = test::random_rotation(rng);
  std::vector<Vec3> p = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  for (Vec3& q : p) q = r * q + Vec3(3, -2, 7);
  for (double eps : {0.05, 0.001}) {
    const Ellipsoid e = bounding_ellipsoid(p, eps);
    expect_contains_all(e, p);
    const double optimum = 4.0 / 3.0 * M_PI * std::pow(std::sqrt(3.0), 3);
    EXPECT_GE(e.volume(), optimum * (1 - 1e-12));
    EXPECT_LE(e.volume(), optimum * (1 + eps) * (1 + 1e-12)) << eps;
  }
}

// A random ellipsoid (rotation, radii drawn by `radius`, center about 10 from the origin) and the
// six ends of its axes. The caller's distributions are used, so each test's draws stay its own.
struct GivenEllipsoid {
  Mat3 axes;
  Vec3 radii;
  Vec3 center;
  std::vector<Vec3> axis_points;
};
GivenEllipsoid random_ellipsoid(std::mt19937_64& rng, std::normal_distribution<double>& normal,
                                std::uniform_real_distribution<double>& radius) {
  GivenEllipsoid g;
  g.axes = test::random_rotation(rng);
  g.radii = Vec3(radius(rng), radius(rng), radius(rng));
  g.center = Vec3(normal(rng) * 10, normal(rng) * 10, normal(rng) * 10);
  for (int k = 0; k < 3; ++k)
    for (double s : {-1.0, 1.0}) g.axis_points.push_back(g.center + s * g.radii[k] * g.axes.col(k));
  return g;
}

TEST(Ellipsoid, PointsOnAGivenEllipsoid) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> radius(0.2, 5.0);
  for (int trial = 0; trial < 10; ++trial) {
    const GivenEllipsoid given = random_ellipsoid(rng, normal, radius);
    const Mat3& axes = given.axes;
    const Vec3& radii = given.radii;
    const Vec3& center = given.center;
    std::vector<Vec3> p = given.axis_points;
    while (p.size() < 200) {
      const Vec3 d = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
      p.push_back(center + axes * radii.cwiseProduct(d));
    }
    const double optimum = 4.0 / 3.0 * M_PI * radii.prod();
    for (double eps : {0.01, 0.001}) {
      const Ellipsoid e = bounding_ellipsoid(p, eps);
      expect_contains_all(e, p);
      EXPECT_GE(e.volume(), optimum * (1 - 1e-9));
      EXPECT_LE(e.volume(), optimum * (1 + eps) * (1 + 1e-12)) << trial << " " << eps;
    }
    // Tight fit: the answer is close to the given ellipsoid itself.
    const Ellipsoid e = bounding_ellipsoid(p, 1e-6);
    EXPECT_LT((e.center - center).norm(), 1e-3 * radii.maxCoeff()) << trial;
  }
}

// Many interior points, shuffled: the active set (extreme points, then the violators of each
// pass) must still reach the optimum within (1 + eps); interior points never change it.
TEST(Ellipsoid, InteriorPointsAndOrderDoNotChangeTheOptimum) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> radius(0.2, 5.0), inside(0.0, 0.99);
  for (int trial = 0; trial < 6; ++trial) {
    const GivenEllipsoid given = random_ellipsoid(rng, normal, radius);
    const Mat3& axes = given.axes;
    const Vec3& radii = given.radii;
    const Vec3& center = given.center;
    std::vector<Vec3> p = given.axis_points;
    for (int i = 0; i < 3000; ++i) {
      const Vec3 d = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
      p.push_back(center + axes * radii.cwiseProduct(i % 10 == 0 ? d : inside(rng) * d));
    }
    std::shuffle(p.begin(), p.end(), rng);
    const double optimum = 4.0 / 3.0 * M_PI * radii.prod();
    const Ellipsoid e = bounding_ellipsoid(p, 0.01);
    expect_contains_all(e, p);
    EXPECT_GE(e.volume(), optimum * (1 - 1e-9)) << trial;
    EXPECT_LE(e.volume(), optimum * 1.01 * (1 + 1e-12)) << trial;
  }
}

TEST(Ellipsoid, MeshesContainedTighterWithSmallerEpsilonAndBelowTheBall) {
  std::mt19937_64 rng(3);
  int meshes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(test::source_dir() / "meshes")) {
    if (entry.path().extension() != ".off") continue;
    ++meshes;
    const auto v = load_mesh(entry.path()).vertices;
    const auto t0 = std::chrono::steady_clock::now();
    const Ellipsoid coarse = bounding_ellipsoid(v, 0.1);
    const auto t1 = std::chrono::steady_clock::now();
    const Ellipsoid fine = bounding_ellipsoid(v, 0.001);
    const auto t2 = std::chrono::steady_clock::now();
    std::printf("[ ellipsoid ] %s: %zu vertices, eps 0.1 %.2f ms, eps 0.001 %.2f ms\n",
                entry.path().filename().c_str(), v.size(),
                std::chrono::duration<double, std::milli>(t1 - t0).count(),
                std::chrono::duration<double, std::milli>(t2 - t1).count());
    SCOPED_TRACE(entry.path().string());
    expect_contains_all(coarse, v);
    expect_contains_all(fine, v);
    // Both are within their factor of the same optimum, which the fine one bounds from above.
    EXPECT_LE(fine.volume(), coarse.volume() * (1 + 1e-3));
    EXPECT_GE(fine.volume() * 1.1 * (1 + 1e-9), coarse.volume());
    // The MVEE is at most the minimum ball (a feasible ellipsoid).
    EXPECT_LE(fine.volume(), bounding_ball(v).volume() * (1 + 1e-3) * (1 + 1e-9));
    // Rigid motion: the transformed ellipsoid holds the transformed vertices.
    const Pose pose{test::random_rotation(rng), Vec3(10, -20, 30)};
    const Ellipsoid moved = fine.transformed(pose);
    for (const Vec3& p : v) ASSERT_TRUE(moved.contains(pose.apply(p), 1e-9 * fine.radii.maxCoeff()));
  }
  EXPECT_GE(meshes, 1);
}

TEST(Ellipsoid, BelowTheBallOnRandomSets) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    const auto p = test::gaussian_points(100, seed);
    const Ellipsoid e = bounding_ellipsoid(p, 0.01);
    expect_contains_all(e, p);
    EXPECT_LE(e.volume(), bounding_ball(p).volume() * 1.01 * (1 + 1e-9));
    EXPECT_LE(bounding_ellipsoid(p, 0.001).volume(), e.volume() * (1 + 1e-3));
  }
}

TEST(Ellipsoid, DegenerateSets) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  const Mat3 r0 = test::random_rotation(rng);
  const auto check_flat = [](const std::vector<Vec3>& p, int zero_radii) {
    const Ellipsoid e = bounding_ellipsoid(p);
    expect_contains_all(e, p);
    EXPECT_EQ(e.volume(), 0.0);
    int zeros = 0;
    for (int k = 0; k < 3; ++k) zeros += e.radii[k] == 0.0;
    EXPECT_EQ(zeros, zero_radii) << affine_dimension(p).dimension << " r " << e.radii.transpose() << " n " << p.size();
    return e;
  };
  for (const Vec3 offset : {Vec3(0, 0, 0), Vec3(1e6, -1e6, 1e6)}) {
    SCOPED_TRACE(offset.x());
    // Rotated sets are flat to rounding of their size; at the 1e6 offset rounding is 1e-10 of
    // the size, so affine_dimension() calls them solid: there the sets are exactly flat.
    const Mat3 r = offset.isZero() ? r0 : Mat3::Identity();
    // One point, and duplicates of it.
    const Ellipsoid point = check_flat({offset + Vec3(1, 2, 3)}, 3);
    EXPECT_EQ(point.center, offset + Vec3(1, 2, 3));
    check_flat(std::vector<Vec3>(5, offset + Vec3(1, 2, 3)), 3);
    // Collinear: the segment's midpoint, half its length.
    std::vector<Vec3> line;
    for (int i = 0; i < 50; ++i) line.push_back(offset + r * Vec3(normal(rng), 0, 0));
    line.push_back(offset + r * Vec3(-4, 0, 0)), line.push_back(offset + r * Vec3(6, 0, 0));
    const Ellipsoid seg = check_flat(line, 2);
    EXPECT_NEAR(seg.radii.maxCoeff(), 5.0, 1e-9);
    EXPECT_LT((seg.center - (offset + r * Vec3(1, 0, 0))).norm(), 1e-9);
    // Coplanar: the minimum-area ellipse (a circle for the points of a circle + a square).
    std::vector<Vec3> plane;
    for (int i = 0; i < 64; ++i) {
      const double a = 2 * M_PI * i / 64;
      plane.push_back(offset + r * Vec3(2 * std::cos(a), 2 * std::sin(a), 0));
    }
    for (int i = 0; i < 50; ++i) plane.push_back(offset + r * Vec3(normal(rng), normal(rng), 0) * 0.5);
    plane.push_back(plane[0]);  // a duplicate
    const Ellipsoid disk = check_flat(plane, 1);
    // Area pi r0 r1 of the circle of radius 2 (the 64-gon's MVEE is that circle).
    const double area = disk.radii[0] * disk.radii[1] + disk.radii[0] * disk.radii[2] + disk.radii[1] * disk.radii[2];
    EXPECT_GE(area, 4.0 * std::cos(M_PI / 64) * std::cos(M_PI / 64) * (1 - 1e-9));
    EXPECT_LE(area, 4.0 * 1.01 * (1 + 1e-9));
    // Duplicates of a solid set change nothing beyond epsilon.
    auto cube = std::vector<Vec3>{};
    for (int i = 0; i < 8; ++i) cube.push_back(offset + Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1));
    for (int i = 0; i < 8; ++i) cube.push_back(cube[i]);
    const Ellipsoid c = bounding_ellipsoid(cube);
    expect_contains_all(c, cube);
    EXPECT_LE(c.volume(), M_PI * std::sqrt(3.0) / 2.0 * 1.01 * (1 + 1e-9));
    EXPECT_GE(c.volume(), M_PI * std::sqrt(3.0) / 2.0 * (1 - 1e-9));
  }
}

TEST(Ellipsoid, ContainsAndTransformed) {
  Ellipsoid e{Vec3(1, 0, 0), Mat3::Identity(), Vec3(2, 1, 0.5)};
  EXPECT_NEAR(e.volume(), 4.0 / 3.0 * M_PI, 1e-15);
  EXPECT_TRUE(e.contains(Vec3(3, 0, 0)));
  EXPECT_FALSE(e.contains(Vec3(3.001, 0, 0)));
  EXPECT_TRUE(e.contains(Vec3(3.001, 0, 0), 0.01));
  EXPECT_FALSE(e.contains(Vec3(1, 0, 0.51)));
  const Pose pose{Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix(), Vec3(5, 6, 7)};
  EXPECT_TRUE(e.transformed(pose).contains(pose.apply(Vec3(1, 0.99, 0))));
  EXPECT_FALSE(e.transformed(pose).contains(pose.apply(Vec3(1, 1.01, 0))));
}

}  // namespace
}  // namespace tightbvh
