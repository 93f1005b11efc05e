#include "tightbvh/closed.hpp"

#include <gtest/gtest.h>

#include <string>

#include "solid_fixtures.hpp"

namespace tightbvh {
namespace {

using namespace query_test;
using namespace solid_test;

TEST(Closed, ClosedMeshesAndTheirPieces) {
  for (const Mesh& m : {cube(), octahedron(), uv_sphere(6, 8), torus(2.0, 0.5, 12, 8)}) {
    const Closedness c = check_closed(m);
    EXPECT_TRUE(c.closed) << c.problem;
    EXPECT_EQ(c.problem, "");
    EXPECT_EQ(c.pieces, std::vector<std::uint32_t>{0});
    EXPECT_EQ(c.triangle_count, m.triangles.size());
    EXPECT_NO_THROW(require_closed(c, m, "test", "A"));
  }
  // Two pieces (and a hollow sphere: an outer surface and an inward one), one vertex each.
  const Mesh two = merged(cube(), cube(Vec3(5, 0, 0)));
  EXPECT_TRUE(check_closed(two).closed);
  EXPECT_EQ(check_closed(two).pieces, (std::vector<std::uint32_t>{0, 8}));
  const Mesh hollow = merged(uv_sphere(6, 8), flipped(transformed(uv_sphere(6, 8), 0.5)));
  EXPECT_TRUE(check_closed(hollow).closed);
  EXPECT_EQ(check_closed(hollow).pieces.size(), 2u);
  // Triangles repeating an index are points or segments: ignored. Zero-area triangles with
  // three indices are ordinary triangles.
  Mesh with_point = cube();
  with_point.triangles.push_back({3, 3, 5});
  EXPECT_TRUE(check_closed(with_point).closed);
}

TEST(Closed, OpenMeshesSayWhy) {
  Mesh holed = cube();
  holed.triangles.pop_back();
  const Closedness h = check_closed(holed);
  EXPECT_FALSE(h.closed);
  EXPECT_EQ(h.boundary_edges, 3u);
  EXPECT_EQ(h.problem, "3 boundary edges (of one triangle only), e.g. (3, 5)");

  Mesh misoriented = cube();
  std::swap(misoriented.triangles[0][1], misoriented.triangles[0][2]);  // (0, 1, 2) against its neighbours
  const Closedness m = check_closed(misoriented);
  EXPECT_FALSE(m.closed);
  EXPECT_EQ(m.boundary_edges, 0u);
  EXPECT_EQ(m.misoriented_edges, 3u);
  EXPECT_NE(m.problem.find("inconsistently oriented at edge (0, 1): triangles 0 and 4 both run 0 -> 1"),
            std::string::npos)
      << m.problem;

  Mesh nonmanifold = cube();
  nonmanifold.triangles.push_back({0, 3, 1});  // a third triangle on edges (0, 1) and (1, 3)
  const Closedness n = check_closed(nonmanifold);
  EXPECT_FALSE(n.closed);
  EXPECT_EQ(n.nonmanifold_edges, 2u);
  EXPECT_EQ(n.boundary_edges, 1u);  // (0, 3)
  EXPECT_NE(n.problem.find("shared by more than two triangles"), std::string::npos) << n.problem;

  // Same positions, other indices: not connected (the check is by index).
  Mesh unwelded = cube();
  unwelded.vertices.push_back(unwelded.vertices[7]);
  unwelded.triangles.back()[1] = 8;  // (3, 7, 5) -> (3, 8, 5)
  EXPECT_FALSE(check_closed(unwelded).closed);

  try {
    require_closed(h, holed, "collide", "B");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "collide: mesh B is not closed: 3 boundary edges (of one triangle only), e.g. (3, 5)");
  }
  // A check of another mesh.
  EXPECT_THROW(require_closed(check_closed(cube()), uv_sphere(6, 8), "collide", "A"), InputError);
}

TEST(Closed, ShippedMeshesAreClosed) {
  for (const char* name : {"meshes/elephant.off", "meshes/knot1.off", "meshes/knot2.off", "meshes/fandisk.off",
                           "meshes/camel.off"}) {
    const Closedness c = check_closed(shipped(name));
    EXPECT_TRUE(c.closed) << name << ": " << c.problem;
    EXPECT_EQ(c.pieces.size(), std::string(name) == "meshes/knot2.off" ? 2u : 1u) << name;  // knot2: two tubes
  }
}

}  // namespace
}  // namespace tightbvh
