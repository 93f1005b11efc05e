#pragma once
// Shared helpers of the fitter tests: point sets and containment checks.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "tightbvh/fit.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::test {

inline std::vector<Vec3> gaussian_points(std::size_t n, std::uint64_t seed, const Vec3& scale = Vec3(1, 2, 0.5)) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<Vec3> points(n);
  for (auto& p : points) p = Vec3(normal(rng), normal(rng), normal(rng)).cwiseProduct(scale);
  return points;
}

// Appends a copy of every set moved to (1e6, -2e6, 3e6): far from the origin, where the fitters
// must keep their precision by working relative to a point of the set.
inline void append_far_copies(std::vector<std::vector<Vec3>>& sets) {
  const std::size_t plain = sets.size();
  for (std::size_t i = 0; i < plain; ++i) {
    std::vector<Vec3> far = sets[i];
    for (Vec3& p : far) p += Vec3(1e6, -2e6, 3e6);
    sets.push_back(std::move(far));
  }
}

inline Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

inline std::filesystem::path source_dir() { return TIGHTBVH_SOURCE_DIR; }

// Vertices of a shipped mesh (always present) or a corpus mesh (skipped when absent).
inline std::vector<Vec3> mesh_vertices(const std::string& relative) {
  const auto path = source_dir() / relative;
  if (!std::filesystem::exists(path)) return {};
  return load_mesh(path).vertices;
}

inline std::vector<Vec3> mesh_corners(const std::string& relative) {
  const auto path = source_dir() / relative;
  if (!std::filesystem::exists(path)) return {};
  return triangle_corners(load_mesh(path));
}

// Orthonormal, right-handed, finite; every point inside with the relative tolerance.
inline ::testing::AssertionResult valid_box_containing(const Obb& box, std::span<const Vec3> points) {
  if (!box.center.allFinite() || !box.axes.allFinite() || !box.half_extents.allFinite())
    return ::testing::AssertionFailure() << "non-finite box";
  if ((box.half_extents.array() < 0.0).any()) return ::testing::AssertionFailure() << "negative half extent";
  const double ortho = (box.axes.transpose() * box.axes - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (ortho > 1e-12) return ::testing::AssertionFailure() << "axes not orthonormal: " << ortho;
  if (box.axes.determinant() < 0.0) return ::testing::AssertionFailure() << "axes left-handed";
  const double tol = containment_tolerance(box);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!box.contains(points[i], tol)) {
      const Vec3 local = box.to_local(points[i]);
      return ::testing::AssertionFailure() << "point " << i << " outside: local " << local.transpose()
                                           << " half extents " << box.half_extents.transpose() << " tol " << tol;
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace tightbvh::test
