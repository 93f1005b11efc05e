#include "tightbvh/mesh.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace tightbvh {
namespace {

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

}  // namespace
}  // namespace tightbvh
