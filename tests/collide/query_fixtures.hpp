#pragma once
// Test meshes and poses shared by the query tests (collide_test.cpp, distance_test.cpp).
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "tightbvh/mesh.hpp"
#include "tightbvh/pose.hpp"

namespace tightbvh::query_test {

// ------------------------------------------------------------------ meshes
inline Mesh cube(const Vec3& lo = Vec3::Zero(), double size = 1.0) {
  Mesh m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back(lo + size * Vec3((i & 1) ? 1 : 0, (i & 2) ? 1 : 0, (i & 4) ? 1 : 0));
  // Two triangles per face, outward.
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

inline Mesh uv_sphere(int rings, int sectors, double radius = 1.0) {
  Mesh m;
  m.vertices.push_back(Vec3(0, 0, radius));
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < sectors; ++s) {
      const double th = M_PI * r / rings, ph = 2 * M_PI * s / sectors;
      m.vertices.push_back(radius * Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
    }
  m.vertices.push_back(Vec3(0, 0, -radius));
  const auto ring = [&](int r, int s) { return static_cast<std::uint32_t>(1 + (r - 1) * sectors + (s % sectors)); };
  const auto south = static_cast<std::uint32_t>(m.vertices.size() - 1);
  for (int s = 0; s < sectors; ++s) {
    m.triangles.push_back({0, ring(1, s), ring(1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r) {
      m.triangles.push_back({ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
      m.triangles.push_back({ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
    }
    m.triangles.push_back({ring(rings - 1, s), south, ring(rings - 1, s + 1)});
  }
  return m;
}

// Random triangles in a cube of side 2, some of them degenerate (segments and points).
inline Mesh random_soup(int n, std::uint64_t seed, double size = 0.4) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mesh m;
  for (int i = 0; i < n; ++i) {
    const Vec3 c(u(rng), u(rng), u(rng));
    const Vec3 a = c + size * Vec3(u(rng), u(rng), u(rng));
    const Vec3 b = c + size * Vec3(u(rng), u(rng), u(rng));
    Vec3 d = c + size * Vec3(u(rng), u(rng), u(rng));
    if (i % 10 == 3) d = a + 0.5 * (b - a);         // collinear up to rounding
    if (i % 10 == 7) d = a + 0.25 * (b - a) * 4.0;  // repeated corner b (exact segment)
    const auto k = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {a, b, d});
    if (i % 10 == 9)
      m.triangles.push_back({k, k, k});  // a point
    else
      m.triangles.push_back({k, k + 1, k + 2});
  }
  return m;
}

// Every k-th triangle of a shipped mesh (a decimated soup: small enough for brute force).
inline Mesh subset(const Mesh& mesh, std::size_t k) {
  Mesh m;
  m.vertices = mesh.vertices;
  for (std::size_t i = 0; i < mesh.triangles.size(); i += k) m.triangles.push_back(mesh.triangles[i]);
  return m;
}

inline Mesh shipped(const std::string& relative) {
  return load_mesh(std::string(TIGHTBVH_SOURCE_DIR) + "/" + relative);
}

// ------------------------------------------------------------------ poses
struct Sphere {
  Vec3 center;
  double radius;
};
inline Sphere bounding_sphere(const Mesh& m) {
  Aabb box;
  for (const Vec3& v : m.vertices) box.extend(v);
  return {box.center(), 0.5 * box.diagonal()};
}

inline Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
}

// Poses (pa, pb) putting B's center at `gap` times (rA + rB) from A's center: deep overlap,
// near contact and separated configurations.
inline std::vector<std::pair<Pose, Pose>> random_poses(const Mesh& ma, const Mesh& mb, std::uint64_t seed,
                                                       std::initializer_list<double> gaps = {0.0, 0.2, 0.5, 0.7, 0.85,
                                                                                             1.1}) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n;
  const Sphere sa = bounding_sphere(ma), sb = bounding_sphere(mb);
  std::vector<std::pair<Pose, Pose>> poses;
  for (const double gap : gaps) {
    Pose pa{random_rotation(rng), Vec3(n(rng), n(rng), n(rng))};
    const Vec3 dir = Vec3(n(rng), n(rng), n(rng)).normalized();
    const Vec3 world_center_b = pa.apply(sa.center) + gap * (sa.radius + sb.radius) * dir;
    Pose pb{random_rotation(rng), Vec3::Zero()};
    pb.translation = world_center_b - pb.rotation * sb.center;
    poses.push_back({pa, pb});
  }
  return poses;
}

}  // namespace tightbvh::query_test
