#pragma once
// Closed test meshes and an independent point-in-solid reference for the solid tests
// (closed_test.cpp, inside_test.cpp).
#include <cmath>
#include <cstdint>
#include <vector>

#include "query_fixtures.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::solid_test {

// Vertices (+-1, 0, 0), (0, +-1, 0), (0, 0, +-1): eight outward faces.
inline Mesh octahedron() {
  Mesh m;
  m.vertices = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return m;
}

// A torus around the z axis (major radius R, tube radius r), outward, closed.
inline Mesh torus(double big_r, double small_r, int n, int k) {
  Mesh m;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < k; ++j) {
      const double u = 2 * M_PI * i / n, v = 2 * M_PI * j / k;
      m.vertices.push_back(Vec3((big_r + small_r * std::cos(v)) * std::cos(u),
                                (big_r + small_r * std::cos(v)) * std::sin(u), small_r * std::sin(v)));
    }
  const auto at = [&](int i, int j) { return static_cast<std::uint32_t>((i % n) * k + (j % k)); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < k; ++j) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

inline Mesh transformed(Mesh m, double scale, const Vec3& offset = Vec3::Zero()) {
  for (Vec3& v : m.vertices) v = scale * v + offset;
  return m;
}

inline Mesh flipped(Mesh m) {
  for (Triangle& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

inline Mesh merged(const Mesh& a, const Mesh& b) {
  Mesh m = a;
  const auto base = static_cast<std::uint32_t>(a.vertices.size());
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const Triangle& t : b.triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return m;
}

// The generalised winding number (Jacobson et al. 2013) in floating point: the sum of the
// triangles' signed solid angles (Van Oosterom & Strackee 1983) over 4 pi. An independent
// reference for points away from the surface: 1 inside an outward closed mesh, 0 outside.
inline double winding_number(const Mesh& mesh, const Vec3& p) {
  double sum = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]] - p, b = mesh.vertices[t[1]] - p, c = mesh.vertices[t[2]] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double det = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    sum += 2.0 * std::atan2(det, den);
  }
  return sum / (4.0 * M_PI);
}

}  // namespace tightbvh::solid_test
