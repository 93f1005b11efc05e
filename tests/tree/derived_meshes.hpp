#pragma once
// Meshes derived from the shipped ones, as users make them: midpoint subdivision (flat patches of
// coplanar triangles whose midpoints of midpoints sit within rounding of their plane), far from
// the origin, tiny and huge scales, duplicated triangles; and flat grids, exact and with noise.
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "tightbvh/mesh.hpp"

namespace tightbvh::test {

inline Mesh transformed(Mesh mesh, double scale, const Vec3& shift) {
  for (Vec3& v : mesh.vertices) v = scale * v + shift;
  return mesh;
}

inline Mesh with_duplicated_triangles(Mesh mesh) {
  const std::size_t n = mesh.triangles.size();
  for (std::size_t i = 0; i < n; ++i) mesh.triangles.push_back(mesh.triangles[i]);
  return mesh;
}

// An n x n grid of unit squares (two triangles each) on the plane through `origin` spanned by
// u and w, each vertex moved along u x w by a uniform random amount in [-noise, noise].
inline Mesh grid_mesh(int n, const Vec3& origin, const Vec3& u, const Vec3& w, double noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(-noise, noise);
  const Vec3 normal = u.cross(w).normalized();
  Mesh mesh;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      Vec3 p = origin + static_cast<double>(i) * u + static_cast<double>(j) * w;
      if (noise > 0.0) p += jitter(rng) * normal;
      mesh.vertices.push_back(p);
    }
  const auto at = [n](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return mesh;
}

struct DerivedMesh {
  std::string name;
  Mesh mesh;
};

// The family of the robustness tests, from one base mesh: subdivided once and twice, shifted by
// 1e6, scaled by 1e-6 and 1e6, every triangle twice.
inline std::vector<DerivedMesh> derived_meshes(const std::string& base_name, const Mesh& base) {
  std::vector<DerivedMesh> out;
  Mesh once = subdivide_midpoints(base);
  out.push_back({base_name + "-sub2", subdivide_midpoints(once)});
  out.push_back({base_name + "-sub1", std::move(once)});
  out.push_back({base_name + "-shift1e6", transformed(base, 1.0, Vec3(1e6, -1e6, 1e6))});
  out.push_back({base_name + "-scale1e-6", transformed(base, 1e-6, Vec3::Zero())});
  out.push_back({base_name + "-scale1e6", transformed(base, 1e6, Vec3::Zero())});
  out.push_back({base_name + "-duplicated", with_duplicated_triangles(base)});
  return out;
}

// Flat grids: on a coordinate plane, on a tilted plane (coordinates rounded off the plane), the
// tilted one with 1e-12 noise, and the tilted one subdivided (midpoints of a rounded plane).
inline std::vector<DerivedMesh> grid_meshes(int n) {
  const Vec3 u = Vec3(1.0, 0.3, -0.2) / n, w = Vec3(-0.25, 0.9, 0.4) / n;
  std::vector<DerivedMesh> out;
  out.push_back({"grid-z0", grid_mesh(n, Vec3(0.1, 0.2, 0.0), Vec3(1.0 / n, 0, 0), Vec3(0, 1.0 / n, 0), 0.0, 1)});
  out.push_back({"grid-tilted", grid_mesh(n, Vec3(0.1, 0.2, 0.3), u, w, 0.0, 1)});
  out.push_back({"grid-noise1e-12", grid_mesh(n, Vec3(0.1, 0.2, 0.3), u, w, 1e-12, 2)});
  out.push_back({"grid-tilted-sub2", subdivide_midpoints(subdivide_midpoints(grid_mesh(n / 4, Vec3(0.1, 0.2, 0.3), 4.0 * u, 4.0 * w, 0.0, 1)))});
  return out;
}

}  // namespace tightbvh::test
