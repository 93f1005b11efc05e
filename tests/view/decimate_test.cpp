// view/decimate: vertex clustering keeps what is drawn under the budget and on the mesh.
#include "view/decimate.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace tightbvh::view {
namespace {

Mesh shipped(const char* name) { return load_mesh(std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/" + name); }

TEST(ViewDecimate, UnderTheBudgetTheMeshItself) {
  const Mesh mesh = shipped("knot1.off");
  const DrawnMesh drawn = decimate_for_drawing(mesh, mesh.triangles.size());
  EXPECT_FALSE(drawn.decimated);
  EXPECT_EQ(drawn.mesh.triangles, mesh.triangles);
  EXPECT_EQ(drawn.mesh.vertices, mesh.vertices);
}

TEST(ViewDecimate, AboveTheBudgetFewerTrianglesOnTheMesh) {
  const Mesh mesh = shipped("elephant.off");
  const Aabb bounds = bounds_of(mesh.vertices);
  for (const std::size_t budget : {200u, 1000u, 4000u}) {
    SCOPED_TRACE(budget);
    const DrawnMesh drawn = decimate_for_drawing(mesh, budget);
    EXPECT_TRUE(drawn.decimated);
    EXPECT_LE(drawn.mesh.triangles.size(), budget);
    // The finest grid under the budget: not far below it (counts grow about 4x per doubling).
    EXPECT_GE(drawn.mesh.triangles.size(), budget / 5);
    for (const Triangle& t : drawn.mesh.triangles) {
      ASSERT_TRUE(t[0] < drawn.mesh.vertices.size() && t[1] < drawn.mesh.vertices.size() &&
                  t[2] < drawn.mesh.vertices.size());
      EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    }
    // Cluster means stay inside the input's bounds.
    for (const Vec3& v : drawn.mesh.vertices) EXPECT_TRUE(bounds.contains(v, 1e-12));
    // No two triangles on the same three vertices.
    std::vector<Triangle> sorted = drawn.mesh.triangles;
    for (Triangle& t : sorted) std::sort(t.begin(), t.end());
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
  }
}

TEST(ViewDecimate, BadInput) {
  const Mesh mesh = shipped("knot1.off");
  EXPECT_THROW((void)decimate_for_drawing(mesh, 0), InputError);
  Mesh broken = mesh;
  broken.triangles[0][1] = static_cast<std::uint32_t>(mesh.vertices.size());
  EXPECT_THROW((void)decimate_for_drawing(broken, 10), InputError);
}

}  // namespace
}  // namespace tightbvh::view
