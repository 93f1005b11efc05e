// Tests of the bounding balls (src/containers/ball.cpp): containment of every input point, known
// answers, degenerate sets, and the exact ball against a brute-force search on small sets.
#include "tightbvh/ball.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <vector>

#include "../fit/test_util.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh {
namespace {

// The brute-force oracle: the smallest circumball (in the affine hull) of 1-4 of the points
// that contains all points (within a relative 1e-10), independent of the library's solver.
Ball brute_force_ball(const std::vector<Vec3>& p) {
  const std::size_t n = p.size();
  double best_radius = std::numeric_limits<double>::infinity();
  Vec3 best_center = p[0];
  const auto consider = [&](const Vec3& c, double r) {
    if (!c.allFinite() || r >= best_radius) return;
    for (const Vec3& q : p)
      if ((q - c).norm() > r * (1 + 1e-10) + 1e-300) return;
    best_radius = r, best_center = c;
  };
  for (std::size_t i = 0; i < n; ++i) {
    consider(p[i], 0.0);
    for (std::size_t j = i + 1; j < n; ++j) {
      consider(0.5 * (p[i] + p[j]), 0.5 * (p[i] - p[j]).norm());
      for (std::size_t k = j + 1; k < n; ++k) {
        const Vec3 ab = p[j] - p[i], ac = p[k] - p[i], x = ab.cross(ac);
        if (x.squaredNorm() > 1e-24 * ab.squaredNorm() * ac.squaredNorm()) {
          const Vec3 c = p[i] + (ac.squaredNorm() * x.cross(ab) + ab.squaredNorm() * ac.cross(x)) / (2 * x.squaredNorm());
          consider(c, std::max({(c - p[i]).norm(), (c - p[j]).norm(), (c - p[k]).norm()}));
        }
        for (std::size_t l = k + 1; l < n; ++l) {
          Mat3 a;
          a.row(0) = 2 * (p[j] - p[i]), a.row(1) = 2 * (p[k] - p[i]), a.row(2) = 2 * (p[l] - p[i]);
          const Vec3 b((p[j] - p[i]).squaredNorm(), (p[k] - p[i]).squaredNorm(), (p[l] - p[i]).squaredNorm());
          Eigen::FullPivLU<Mat3> lu(a);
          lu.setThreshold(1e-10);
          if (lu.rank() < 3) continue;
          const Vec3 c = p[i] + lu.solve(b);
          consider(c, std::max({(c - p[i]).norm(), (c - p[j]).norm(), (c - p[k]).norm(), (c - p[l]).norm()}));
        }
      }
    }
  }
  return {best_center, best_radius};
}

void expect_contains_all(const Ball& ball, const std::vector<Vec3>& points) {
  for (std::size_t i = 0; i < points.size(); ++i) ASSERT_TRUE(ball.contains(points[i])) << "point " << i;
}

void expect_exact(const std::vector<Vec3>& points, double tolerance = 1e-9) {
  const Ball exact = bounding_ball(points), fast = fast_ball(points), brute = brute_force_ball(points);
  expect_contains_all(exact, points);
  expect_contains_all(fast, points);
  EXPECT_LE(exact.radius, fast.radius * (1 + 1e-12));
  const double scale = std::max(brute.radius, 1e-300);
  EXPECT_LE(std::abs(exact.radius - brute.radius), tolerance * scale) << exact.radius << " vs " << brute.radius;
}

TEST(Ball, Errors) {
  const std::vector<Vec3> none;
  EXPECT_THROW((void)bounding_ball(none), InputError);
  EXPECT_THROW((void)fast_ball(none), InputError);
  try {
    (void)bounding_ball(none);
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "ball: empty point set");
  }
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    std::vector<Vec3> p(10, Vec3(1, 2, 3));
    p[7].y() = bad;
    for (auto fit : {&bounding_ball, &fast_ball}) {
      try {
        (void)fit(p);
        ADD_FAILURE() << "no throw";
      } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "ball: point 7 has a non-finite coordinate (NaN or Inf)");
      }
    }
  }
}

TEST(Ball, CubeCorners) {
  for (const Vec3 offset : {Vec3(0, 0, 0), Vec3(1e6, -1e6, 1e6)}) {
    std::vector<Vec3> p;
    const double edge = 2.0;
    for (int i = 0; i < 8; ++i) p.push_back(offset + edge * Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1));
    p.push_back(offset + Vec3(1, 1, 1));  // an interior point
    const Ball b = bounding_ball(p);
    EXPECT_NEAR(b.radius, std::sqrt(3.0) / 2 * edge, 1e-9);
    EXPECT_NEAR((b.center - (offset + Vec3(1, 1, 1))).norm(), 0.0, 1e-9);
    expect_contains_all(b, p);
    expect_contains_all(fast_ball(p), p);
  }
}

TEST(Ball, RegularTetrahedron) {
  const std::vector<Vec3> p{Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1), Vec3(0.1, 0.2, 0.1)};
  const Ball b = bounding_ball(p);
  EXPECT_NEAR(b.radius, std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(b.center.norm(), 0.0, 1e-12);
  expect_exact(p);
}

TEST(Ball, DegenerateSets) {
  expect_exact({Vec3(3, 4, 5)});
  EXPECT_EQ(bounding_ball(std::vector<Vec3>{Vec3(3, 4, 5)}).radius, 0.0);
  expect_exact(std::vector<Vec3>(6, Vec3(-1, 2, 0.5)));                         // duplicates
  expect_exact({Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(0, 0, 0), Vec3(1, 1, 1)});  // duplicated pair
  std::vector<Vec3> line, plane, sphere;
  for (int i = 0; i < 9; ++i) line.push_back(Vec3(1, 2, 3) + (i * 0.37 - 1) * Vec3(1, -2, 0.5));
  expect_exact(line);
  EXPECT_NEAR(bounding_ball(line).radius, 0.5 * (line.front() - line.back()).norm(), 1e-12);
  for (int i = 0; i < 10; ++i) plane.push_back(Vec3(std::cos(i * 0.7), std::sin(i * 0.7), 2.0));  // on a circle
  expect_exact(plane);
  EXPECT_NEAR(bounding_ball(plane).radius, 1.0, 1e-12);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 12; ++i) sphere.push_back(Vec3(normal(rng), normal(rng), normal(rng)).normalized());
  for (int s = 0; s < 6; ++s) sphere.push_back(Vec3::Unit(s % 3) * (s < 3 ? 1 : -1));  // cospherical
  expect_exact(sphere);
  // The same sets far from the origin.
  for (auto set : {line, plane, sphere}) {
    for (Vec3& p : set) p += Vec3(1e6, 2e6, -1e6);
    expect_exact(set, 1e-8);
  }
}

TEST(Ball, MatchesBruteForceOnSmallRandomSets) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> grid(-2, 2), count(1, 11);
  for (int trial = 0; trial < 400; ++trial) {
    const int n = count(rng);
    std::vector<Vec3> p(n);
    for (Vec3& q : p)
      q = trial % 2 ? Vec3(normal(rng), normal(rng), normal(rng))
                    : Vec3(grid(rng), grid(rng), trial % 4 == 0 ? 0 : grid(rng));  // ties, coplanar
    SCOPED_TRACE(trial);
    expect_exact(p);
  }
}

// Larger sets, where many pivots run: random, on a sphere (every point on the boundary, many
// candidate supports), and on a sphere with interior points, far from the origin.
TEST(Ball, MatchesBruteForceOnLargerRandomSets) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> count(12, 28);
  for (int trial = 0; trial < 60; ++trial) {
    const int n = count(rng);
    const Vec3 offset = trial % 3 == 2 ? Vec3(1e3, -2e3, 5e2) : Vec3::Zero();
    std::vector<Vec3> p(n);
    for (int i = 0; i < n; ++i) {
      const Vec3 d(normal(rng), normal(rng), normal(rng));
      p[i] = offset + (trial % 3 == 0 ? d : d.normalized() * (i % 4 == 0 && trial % 3 == 2 ? 0.5 : 1.0));
    }
    SCOPED_TRACE(trial);
    expect_exact(p);
  }
}

// Nearly cospherical sets (many candidate supports of almost equal radius) at several scales.
TEST(Ball, NearlyCosphericalAndScaled) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> normal;
  for (double scale : {1e-8, 1.0, 1e8})
    for (int trial = 0; trial < 10; ++trial) {
      std::vector<Vec3> p;
      for (int i = 0; i < 30; ++i)
        p.push_back(scale * (Vec3(normal(rng), normal(rng), normal(rng)).normalized() * (1 + 1e-9 * normal(rng))));
      SCOPED_TRACE(scale);
      expect_exact(p);
    }
}

TEST(Ball, ContainsEveryMeshVertex) {
  std::mt19937_64 rng(3);
  int meshes = 0;
  for (const auto& e : std::filesystem::directory_iterator(test::source_dir() / "meshes")) {
    if (e.path().extension() != ".off") continue;
    ++meshes;
    const auto v = load_mesh(e.path()).vertices;
    const Ball exact = bounding_ball(v), fast = fast_ball(v);
    expect_contains_all(exact, v);
    expect_contains_all(fast, v);
    EXPECT_LE(exact.radius, fast.radius);
    EXPECT_LE(fast.radius, 1.2 * exact.radius) << e.path();
    // The support is tight: some vertex lies on the boundary.
    double far = 0;
    for (const Vec3& p : v) far = std::max(far, (p - exact.center).norm());
    EXPECT_NEAR(far, exact.radius, 1e-12 * exact.radius);
    // Rigid motion: the transformed ball holds the transformed vertices.
    const Pose pose{test::random_rotation(rng), Vec3(10, -20, 30)};
    const Ball moved = exact.transformed(pose);
    for (const Vec3& p : v) ASSERT_TRUE(moved.contains(pose.apply(p), 1e-9 * exact.radius));
  }
  EXPECT_GE(meshes, 1);
}

TEST(Ball, VolumeAndOverlaps) {
  const Ball a{Vec3(0, 0, 0), 1.0}, b{Vec3(2, 0, 0), 1.0}, c{Vec3(2.01, 0, 0), 1.0};
  EXPECT_NEAR(a.volume(), 4.0 / 3.0 * M_PI, 1e-15);
  EXPECT_TRUE(overlaps(a, b));  // touching
  EXPECT_FALSE(overlaps(a, c));
  EXPECT_TRUE(a.contains(Vec3(1, 0, 0)));
  EXPECT_FALSE(a.contains(Vec3(1.001, 0, 0)));
  EXPECT_TRUE(a.contains(Vec3(1.001, 0, 0), 0.01));
}

}  // namespace
}  // namespace tightbvh
