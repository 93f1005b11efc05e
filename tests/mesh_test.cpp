#include "tightbvh/mesh.hpp"

#include <gtest/gtest.h>

#include <limits>
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


Mesh unit_tetrahedron() {
  return {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
}

TEST(Validate, CountsAndBounds) {
  const MeshStats s = check_mesh(unit_tetrahedron());
  EXPECT_EQ(s.vertices, 4u);
  EXPECT_EQ(s.triangles, 4u);
  EXPECT_EQ(s.degenerate_triangles, 0u);
  EXPECT_EQ(s.bounds.max, Vec3(1, 1, 1));
}

TEST(Validate, RejectsNonFiniteAndOutOfRange) {
  Mesh nan = unit_tetrahedron();
  nan.vertices[2].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)check_mesh(nan), InputError);
  Mesh out_of_range = unit_tetrahedron();
  out_of_range.triangles[1][2] = 4;
  EXPECT_THROW((void)check_mesh(out_of_range), InputError);
  EXPECT_THROW((void)check_mesh(Mesh{}), InputError);
}

TEST(Validate, CountsDegenerateTriangles) {
  Mesh m = unit_tetrahedron();
  m.triangles.push_back({1, 1, 2});
  EXPECT_EQ(check_mesh(m).degenerate_triangles, 1u);
}


// Every triangle into four, one shared midpoint per edge: V + E vertices, 4 T triangles, each
// new vertex the exact midpoint of its edge.
TEST(SubdivideMidpoints, FourTrianglesPerTriangleAndSharedEdgeMidpoints) {
  const Mesh tetra = unit_tetrahedron();
  const Mesh once = subdivide_midpoints(tetra);
  EXPECT_EQ(once.triangles.size(), 16u);
  EXPECT_EQ(once.vertices.size(), 4u + 6u);  // 6 edges, each split once
  EXPECT_EQ(once.vertices[4], 0.5 * (tetra.vertices[0] + tetra.vertices[2]));
  const Mesh twice = subdivide_midpoints(once);
  EXPECT_EQ(twice.triangles.size(), 64u);
  EXPECT_EQ(twice.vertices.size(), 10u + 24u);  // a closed mesh: E = 3T / 2 = 24
  EXPECT_NO_THROW((void)check_mesh(twice));
}

}  // namespace
}  // namespace tightbvh
