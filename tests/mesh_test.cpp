#include "tightbvh/mesh.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace tightbvh {
namespace {

Mesh two_triangles() {
  Mesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.triangles = {{0, 1, 2}, {3, 2, 1}};
  return mesh;
}

TEST(TriangleCorners, ThreePerTriangleInTriangleOrder) {
  const Mesh mesh = two_triangles();
  const std::vector<Vec3> c = triangle_corners(mesh);
  ASSERT_EQ(c.size(), 6u);
  for (std::size_t t = 0; t < 2; ++t)
    for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(c[3 * t + k], mesh.vertices[mesh.triangles[t][k]]);
}

TEST(TriangleCorners, ListedTrianglesReplaceTheBuffer) {
  const Mesh mesh = two_triangles();
  std::vector<Vec3> out(10, Vec3(9, 9, 9));
  triangle_corners(mesh, std::vector<std::uint32_t>{1, 0, 1}, out);
  ASSERT_EQ(out.size(), 9u);
  EXPECT_EQ(out[0], Vec3(0, 0, 1));
  EXPECT_EQ(out[3], Vec3(0, 0, 0));
  EXPECT_EQ(out[8], Vec3(1, 0, 0));
  triangle_corners(mesh, std::vector<std::uint32_t>{}, out);
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace tightbvh
