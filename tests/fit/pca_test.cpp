// Tests of the AABB and PCA fitters (src/fit/pca.cpp, src/fit/fit.cpp).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "fit/pca.hpp"
#include "test_util.hpp"

namespace tightbvh {
namespace {

using test::valid_box_containing;

const FitMethod kSimple[] = {FitMethod::aabb, FitMethod::pca, FitMethod::pca_vertex};

TEST(FitSimple, ContainsRandomPoints) {
  for (FitMethod m : kSimple)
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      const auto points = test::gaussian_points(5 + 13 * seed, seed);
      EXPECT_TRUE(valid_box_containing(fit_points(points, {.method = m}), points)) << to_string(m) << " seed " << seed;
      const std::size_t usable = points.size() / 3 * 3;
      const std::span<const Vec3> corners(points.data(), usable);
      EXPECT_TRUE(valid_box_containing(fit_triangles(corners, {.method = m}), corners)) << to_string(m);
    }
}

TEST(FitSimple, ContainsShippedMeshes) {
  for (const char* name : {"meshes/elephant.off", "meshes/knot1.off"}) {
    const auto corners = test::mesh_corners(name);
    ASSERT_FALSE(corners.empty()) << name;
    for (FitMethod m : kSimple) {
      const Obb box = fit_triangles(corners, {.method = m});
      EXPECT_TRUE(valid_box_containing(box, corners)) << to_string(m) << " " << name;
      EXPECT_GT(box.volume(), 0.0);
    }
  }
}

TEST(FitSimple, AabbIsTheBoundingBox) {
  const std::vector<Vec3> points{{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0, 0, 3}};
  const Obb box = fit_points(points, {.method = FitMethod::aabb});
  EXPECT_DOUBLE_EQ(box.volume(), 6.0);
  EXPECT_TRUE(box.axes.isIdentity());
}

TEST(FitSimple, PcaRecoversElongatedAxis) {
  // Points spread along a rotated direction: the first PCA axis must follow it.
  std::mt19937_64 rng(7);
  const Mat3 r = test::random_rotation(rng);
  auto points = test::gaussian_points(500, 3, Vec3(10, 1, 0.1));
  for (auto& p : points) p = r * p;
  for (FitMethod m : {FitMethod::pca, FitMethod::pca_vertex}) {
    const Obb box = fit_points(points, {.method = m});
    EXPECT_GT(std::abs(box.axes.col(0).dot(r.col(0))), 0.999) << to_string(m);
  }
}

TEST(FitSimple, PcaAreaWeightingDiffersFromVertexCovariance) {
  // A long thin rectangle made of two big triangles plus many tiny triangles clustered at one
  // end along a perpendicular direction: the vertex covariance is dominated by the cluster,
  // the area-weighted one by the big triangles.
  std::vector<Vec3> corners{{-10, -0.5, 0}, {10, -0.5, 0}, {10, 0.5, 0}, {-10, -0.5, 0}, {10, 0.5, 0}, {-10, 0.5, 0}};
  for (int i = 0; i < 200; ++i) {
    const double y = -3.0 + 6.0 * i / 199.0;
    corners.push_back({0, y, 0});
    corners.push_back({1e-3, y, 0});
    corners.push_back({0, y + 1e-3, 0});
  }
  const Obb area = fit_triangles(corners, {.method = FitMethod::pca});
  const Obb vertex = fit_triangles(corners, {.method = FitMethod::pca_vertex});
  EXPECT_GT(std::abs(area.axes.col(0).x()), 0.999);
  EXPECT_GT(std::abs(vertex.axes.col(0).y()), 0.999);
  EXPECT_TRUE(valid_box_containing(area, corners));
  EXPECT_TRUE(valid_box_containing(vertex, corners));
}

TEST(FitSimple, RejectsNonFiniteAndEmpty) {
  for (FitMethod m : kSimple) {
    std::vector<Vec3> points{{0, 0, 0}, {1, std::numeric_limits<double>::quiet_NaN(), 0}, {0, 0, 1}};
    EXPECT_THROW((void)fit_points(points, {.method = m}), InputError);
    points[1].y() = std::numeric_limits<double>::infinity();
    EXPECT_THROW((void)fit_triangles(points, {.method = m}), InputError);
    EXPECT_THROW((void)fit_points(std::span<const Vec3>{}, {.method = m}), InputError);
  }
  const std::vector<Vec3> two{{0, 0, 0}, {1, 1, 1}};
  EXPECT_THROW((void)fit_triangles(two, {.method = FitMethod::aabb}), InputError);
}

TEST(FitSimple, DegenerateInputsGiveFiniteZeroVolumeBoxes) {
  const std::vector<std::vector<Vec3>> sets{
      {{1, 2, 3}},
      {{1, 2, 3}, {1, 2, 3}, {1, 2, 3}},
      {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {0.5, 0.5, 0.5}},
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.3, 0.2, 0}},
  };
  for (FitMethod m : kSimple)
    for (const auto& s : sets) {
      const Obb box = fit_points(s, {.method = m});
      EXPECT_TRUE(valid_box_containing(box, s)) << to_string(m);
      // The AABB of a diagonal segment is a genuine box; every other set is flat.
      if (m != FitMethod::aabb || &s != &sets[2]) EXPECT_NEAR(box.volume(), 0.0, 1e-12) << to_string(m);
    }
}

TEST(FitSimple, FarFromOriginKeepsContainment) {
  auto points = test::gaussian_points(300, 11);
  for (auto& p : points) p += Vec3(1e6, -1e6, 1e6);
  for (FitMethod m : kSimple) EXPECT_TRUE(valid_box_containing(fit_points(points, {.method = m}), points));
}

TEST(FitSimple, WorkspaceReuseGivesSameBoxes) {
  FitWorkspace ws;
  for (std::uint64_t seed = 1; seed < 5; ++seed) {
    const auto points = test::gaussian_points(30 * seed, seed);
    for (FitMethod m : kSimple) {
      const Obb a = fit_points(points, {.method = m}, ws);
      const Obb b = fit_points(points, {.method = m});
      EXPECT_EQ(a.volume(), b.volume());
    }
  }
}

// principal_axes (closed form with an iterative fallback): every column an eigenvector, the
// frame orthonormal and right-handed, eigenvalues decreasing; also for repeated eigenvalues
// (isotropic sets such as a cube's corners or a regular tetrahedron, axially symmetric
// ones), near-ties and spectra spanning many orders of magnitude, in random orientations.
// `tolerance`: of the residuals |C a - lambda a|, relative to the largest coefficient of C.
::testing::AssertionResult is_eigenframe(const Mat3& c, const Mat3& axes, double tolerance = 1e-9) {
  const double ortho = (axes.transpose() * axes - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (!axes.allFinite() || ortho > 1e-12) return ::testing::AssertionFailure() << "not orthonormal: " << ortho;
  if (!(axes.determinant() > 0.0)) return ::testing::AssertionFailure() << "left-handed";
  const double scale = c.cwiseAbs().maxCoeff();  // not norm(): squares of 1e-300 underflow
  double previous = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    const Vec3 a = axes.col(i);
    const double lambda = a.dot(c * a);
    const double residual = (c * a - lambda * a).norm();
    if (residual > tolerance * scale)
      return ::testing::AssertionFailure() << "column " << i << " residual " << residual / scale;
    if (lambda > previous + 1e-12 * scale)
      return ::testing::AssertionFailure() << "eigenvalues not decreasing: " << previous << " then " << lambda;
    previous = lambda;
  }
  return ::testing::AssertionSuccess();
}

// Spectra with repeated eigenvalues, near-ties and many orders of magnitude.
std::vector<Vec3> hard_spectra() {
  return {{1, 1, 1},     {2, 1, 1},        {1, 1, 0},           {1, 0, 0},
          {1, 1, 1e-12}, {1, 1 + 1e-9, 1}, {1, 1 - 1e-14, 0.5}, {1e6, 1, 1e-6},
          {3, 2, 1},     {1e-300, 1e-300, 2e-300}, {5, 5, 5 + 1e-13}};
}

// principal_axes_from (refit's Jacobi sweeps from the previous axes): an eigenframe for the same
// spectra as principal_axes, from starts near the answer (a float-rounded or slightly turned
// eigenframe, as after a frame's deformation), far from it (random) and degenerate (zero or
// parallel columns: the closed form's answer); with a repeated eigenvalue the start's directions
// in that eigenspace are kept. The sweeps stop once every off-diagonal entry in the frame is at
// most 1e-7 of its largest entry (the closed form's own acceptance), so a column's residual is at
// most sqrt(2) 1e-7 of that entry, itself at most 3 times C's largest coefficient: 5e-7.
TEST(FitSimple, PrincipalAxesFromAStartAreAnEigenframe) {
  std::mt19937_64 rng(6);
  for (const Vec3& d : hard_spectra())
    for (int trial = 0; trial < 50; ++trial) {
      const Mat3 r = trial == 0 ? Mat3::Identity() : test::random_rotation(rng);
      const Mat3 c = r * d.asDiagonal() * r.transpose();
      const Mat3 turned = r * Eigen::AngleAxisd(1e-3 * trial, Vec3(1, 2, 3).normalized()).toRotationMatrix();
      Mat3 parallel = test::random_rotation(rng);
      parallel.col(1) = parallel.col(0);
      for (const Mat3& start : {Mat3(r.cast<float>().cast<double>()), turned, test::random_rotation(rng),
                                Mat3(Mat3::Zero()), parallel})
        EXPECT_TRUE(is_eigenframe(c, fit_detail::principal_axes_from(c, start), 5e-7))
            << d.transpose() << " trial " << trial << " start\n" << start;
    }
  // A repeated eigenvalue: any frame of the eigenspace is an answer; the start's is kept.
  const Mat3 c = Vec3(2, 1, 1).asDiagonal();
  const Mat3 start = Eigen::AngleAxisd(0.4, Vec3::UnitX()).toRotationMatrix();
  const Mat3 axes = fit_detail::principal_axes_from(c, start);
  EXPECT_NEAR(std::abs(axes.col(0).dot(Vec3::UnitX())), 1.0, 1e-15);
  EXPECT_NEAR(std::max(std::abs(axes.col(1).dot(start.col(1))), std::abs(axes.col(1).dot(start.col(2)))), 1.0, 1e-15);
  EXPECT_TRUE(fit_detail::principal_axes_from(Mat3::Zero(), start).isIdentity());
  Mat3 nan = c;
  nan(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(fit_detail::principal_axes_from(nan, start).isIdentity());
}

TEST(FitSimple, PrincipalAxesAreAnEigenframeForRepeatedAndNearlyRepeatedEigenvalues) {
  std::mt19937_64 rng(5);
  for (const Vec3& d : hard_spectra())
    for (int trial = 0; trial < 50; ++trial) {
      const Mat3 r = trial == 0 ? Mat3::Identity() : test::random_rotation(rng);
      const Mat3 c = r * d.asDiagonal() * r.transpose();
      EXPECT_TRUE(is_eigenframe(c, fit_detail::principal_axes(c))) << d.transpose() << " trial " << trial;
    }
  // Point sets with isotropic covariance: a cube's corners and a regular tetrahedron, rotated.
  const std::vector<Vec3> cube{{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {1, 1, -1},
                               {-1, -1, 1},  {1, -1, 1},  {-1, 1, 1},  {1, 1, 1}};
  const std::vector<Vec3> tetra{{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  for (const auto* set : {&cube, &tetra})
    for (int trial = 0; trial < 20; ++trial) {
      const Mat3 r = test::random_rotation(rng);
      std::vector<Vec3> points;
      for (const Vec3& p : *set) points.push_back(r * p + Vec3(3, -2, 1e3));
      for (FitMethod m : {FitMethod::pca, FitMethod::pca_vertex}) {
        const Obb box = fit_points(points, {.method = m});
        EXPECT_TRUE(valid_box_containing(box, points)) << to_string(m);
      }
      // The tetrahedron's faces as triangles (area-weighted covariance, also isotropic).
      if (set == &tetra) {
        std::vector<Vec3> corners;
        for (int skip = 0; skip < 4; ++skip)
          for (int k = 0; k < 4; ++k)
            if (k != skip) corners.push_back(points[k]);
        EXPECT_TRUE(valid_box_containing(fit_triangles(corners, {.method = FitMethod::pca}), corners));
      }
    }
}

TEST(FitNames, RoundTrip) {
  for (FitMethod m : {FitMethod::aabb, FitMethod::pca, FitMethod::pca_vertex, FitMethod::diameter, FitMethod::approx,
                      FitMethod::approx_snap, FitMethod::exact})
    EXPECT_EQ(parse_fit_method(to_string(m)), m);
  EXPECT_FALSE(parse_fit_method("nope").has_value());
}

}  // namespace
}  // namespace tightbvh
