#include "tightbvh/shape.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "query_fixtures.hpp"
#include "shape_fixtures.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/point_query.hpp"
#include "tightbvh/tri_distance.hpp"

namespace tightbvh {
namespace {

namespace qt = query_test;
using namespace shape_test;  // NOLINT: the shared checks

TEST(ShapeQuery, SphereMatchesBruteForce) {
  check_random([](double a, double, double) { return Sphere(a); }, 1);
}

TEST(ShapeQuery, CapsuleMatchesBruteForce) {
  check_random([](double a, double b, double) { return Capsule(0.5 * a, 2.0 * b); }, 2);
}

TEST(ShapeQuery, BoxMatchesBruteForce) {
  check_random([](double a, double b, double c) { return Box(2.0 * a, 2.0 * b, 0.5 * c); }, 3);
}

Pose at(const Vec3& t) { return {Mat3::Identity(), t}; }

// The box distance against an independent reference: every triangle mapped into the box frame by
// the composed pose, 0 when a corner is inside or it touches the surface, else the least
// tri_tri_distance to all 12 surface triangles (the query skips faces the triangle is not outside of).
TEST(ShapeQuery, BoxDistanceMatchesAllTwelveSurfaceTriangles) {
  const Mesh mesh = qt::random_soup(60, 7);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.1, 0.8);
  int apart = 0, touching = 0;
  for (int i = 0; i < 20; ++i) {
    const Vec3 h(u(rng), u(rng), u(rng));
    const Box box(2.0 * h);
    const Pose ps{qt::random_rotation(rng), 3.0 * Vec3(u(rng), -u(rng), 0.5 * u(rng))};
    const Pose to_box = ps.inverse();
    std::vector<std::array<Vec3, 3>> surface;
    for (int k = 0; k < 3; ++k)
      for (const double side : {-1.0, 1.0}) {
        const int a = (k + 1) % 3, b = (k + 2) % 3;
        std::array<Vec3, 4> q;
        for (int m = 0; m < 4; ++m) {
          q[m][k] = side * h[k];
          q[m][a] = (m == 1 || m == 2 ? 1.0 : -1.0) * h[a];
          q[m][b] = (m >= 2 ? 1.0 : -1.0) * h[b];
        }
        surface.push_back({q[0], q[1], q[2]});
        surface.push_back({q[0], q[2], q[3]});
      }
    double want = std::numeric_limits<double>::infinity();
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto [a, b, c] = mesh.corners(t);
      const std::array<Vec3, 3> v = {to_box.apply(a), to_box.apply(b), to_box.apply(c)};
      for (const Vec3& x : v)
        if ((x.cwiseAbs().array() <= h.array()).all()) want = 0.0;
      for (const auto& f : surface) want = std::min(want, tri_tri_distance(f, v).distance);
    }
    const Tree tree = build(mesh);
    const double got = distance(box, ps, tree, mesh, Pose{}).distance;
    EXPECT_NEAR(got, want, 1e-12 * (1.0 + want)) << "pose " << i;
    EXPECT_EQ(got, distance_brute_force(box, ps, mesh, Pose{}).distance) << "pose " << i;
    (want > 0.0 ? apart : touching) += 1;
  }
  EXPECT_GT(apart, 0);
  EXPECT_GT(touching, 0);
}

// The same reference triangle by triangle (each its own one-triangle mesh), so that no candidate
// of the box–triangle distance hides behind another triangle's minimum: a random soup with
// segments and points among its triangles, and a cube whose edges are parallel to the box's
// (boxes at the identity and at quarter turns, so edge pairs are exactly parallel).
TEST(ShapeQuery, BoxDistanceEachTriangleAgainstTwelveSurfaceTriangles) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0.1, 0.8);
  const Mat3 quarter = Eigen::AngleAxisd(0.5 * M_PI, Vec3::UnitZ()).toRotationMatrix();
  int apart = 0;
  for (const Mesh& mesh : {qt::random_soup(40, 5), qt::cube(Vec3(-0.5, -0.5, -0.5), 1.0)}) {
    for (int i = 0; i < 12; ++i) {
      const Vec3 h(u(rng), u(rng), u(rng));
      const Box box(2.0 * h);
      const Mat3 r = i % 3 == 0 ? Mat3::Identity() : i % 3 == 1 ? quarter : qt::random_rotation(rng);
      const Pose ps{r, 2.0 * Vec3(u(rng), -u(rng), 0.5 * u(rng))};
      const Pose to_box = ps.inverse();
      for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto [a, b, c] = mesh.corners(t);
        const Mesh one{{a, b, c}, {Triangle{0, 1, 2}}};
        const std::array<Vec3, 3> v = {to_box.apply(a), to_box.apply(b), to_box.apply(c)};
        double want = std::numeric_limits<double>::infinity();
        for (const Vec3& x : v)
          if ((x.cwiseAbs().array() <= h.array()).all()) want = 0.0;
        for (int k = 0; k < 3; ++k)
          for (const double side : {-1.0, 1.0}) {
            const int e = (k + 1) % 3, f = (k + 2) % 3;
            std::array<Vec3, 4> q;
            for (int m = 0; m < 4; ++m) {
              q[m][k] = side * h[k];
              q[m][e] = (m == 1 || m == 2 ? 1.0 : -1.0) * h[e];
              q[m][f] = (m >= 2 ? 1.0 : -1.0) * h[f];
            }
            want = std::min({want, tri_tri_distance({q[0], q[1], q[2]}, v).distance,
                             tri_tri_distance({q[0], q[2], q[3]}, v).distance});
          }
        const ShapeDistanceResult got = distance_brute_force(box, ps, one, Pose{});
        EXPECT_NEAR(got.distance, want, 1e-12 * (1.0 + want)) << "pose " << i << " triangle " << t;
        EXPECT_NEAR((got.point_shape - got.point_mesh).norm(), got.distance, 1e-12 * (1.0 + want));
        apart += want > 0.0 ? 1 : 0;
      }
    }
  }
  EXPECT_GT(apart, 200);
}

// The capsule's segment–triangle distance against tri_tri_distance on the degenerate triangle
// (p, q, q), triangle by triangle: random segments against a soup with segments and points among
// its triangles, and against a cube with segments parallel to its edges and faces, crossing it,
// and lying in a face's plane.
TEST(ShapeQuery, CapsuleDistanceEachTriangleAgainstTriTriDistance) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const Mat3 quarter = Eigen::AngleAxisd(0.5 * M_PI, Vec3::UnitX()).toRotationMatrix();
  int apart = 0, touching = 0;
  for (const Mesh& mesh : {qt::random_soup(40, 9), qt::cube(Vec3(-0.5, -0.5, -0.5), 1.0)}) {
    for (int i = 0; i < 16; ++i) {
      const Capsule capsule(0.05, 0.2 + std::abs(u(rng)));
      const Mat3 r = i % 4 == 0 ? Mat3::Identity() : i % 4 == 1 ? quarter : qt::random_rotation(rng);
      // i % 8 == 5: the axis in the plane z = 0.5 of the cube's top face.
      const Vec3 t = i % 8 == 5 ? Vec3(u(rng), u(rng), 0.5) : 0.6 * Vec3(u(rng), u(rng), u(rng));
      const Pose ps{i % 8 == 5 ? quarter : r, t};
      const Vec3 p = ps.apply(Vec3(0.0, 0.0, -0.5 * capsule.length)), q = ps.apply(Vec3(0.0, 0.0, 0.5 * capsule.length));
      for (std::uint32_t k = 0; k < mesh.triangles.size(); ++k) {
        const auto [a, b, c] = mesh.corners(k);
        const Mesh one{{a, b, c}, {Triangle{0, 1, 2}}};
        const double d = tri_tri_distance(p, q, q, a, b, c).distance;
        const double want = std::max(0.0, d - capsule.radius);
        const ShapeDistanceResult got = distance_brute_force(capsule, ps, one, Pose{});
        EXPECT_NEAR(got.distance, want, 1e-12 * (1.0 + want)) << "pose " << i << " triangle " << k;
        EXPECT_EQ(got.distance == 0.0, d <= capsule.radius) << "pose " << i << " triangle " << k;
        (want > 0.0 ? apart : touching) += 1;
      }
    }
  }
  EXPECT_GT(apart, 500);
  EXPECT_GT(touching, 10);
}

// The unit cube [0, 1]^3: shapes tangent to its top face (z = 1) touch it; a hair above they do not.
TEST(ShapeQuery, ExactlyTangentTouches) {
  const Mesh cube = qt::cube();
  const Tree tree = build(cube);
  const Pose id;
  const double above = std::nextafter(1.5, 2.0);

  const ShapeDistanceResult tangent = distance(Sphere(0.5), at({0.5, 0.5, 1.5}), tree, cube, id);
  EXPECT_EQ(tangent.distance, 0.0);
  EXPECT_TRUE(tangent.intersecting);
  EXPECT_TRUE(collide(Sphere(0.5), at({0.5, 0.5, 1.5}), tree, cube, id).hit);
  EXPECT_FALSE(collide(Sphere(0.5), at({0.5, 0.5, above}), tree, cube, id).hit);
  EXPECT_GT(distance(Sphere(0.5), at({0.5, 0.5, above}), tree, cube, id).distance, 0.0);

  // A capsule standing on the face with its lower cap.
  EXPECT_TRUE(collide(Capsule(0.25, 1.0), at({0.5, 0.5, 1.75}), tree, cube, id).hit);
  EXPECT_FALSE(collide(Capsule(0.25, 1.0), at({0.5, 0.5, std::nextafter(1.75, 2.0)}), tree, cube, id).hit);

  // A box whose bottom face is flush with the top face, and one a hair above.
  const QueryOptions all{.mode = QueryMode::all_pairs};
  const ShapeQueryResult flush = collide(Box(1.0, 1.0, 1.0), at({0.5, 0.5, 1.5}), tree, cube, id, all);
  EXPECT_TRUE(flush.hit);
  EXPECT_EQ(flush.triangles, collide_brute_force(Box(1.0, 1.0, 1.0), at({0.5, 0.5, 1.5}), cube, id, all).triangles);
  EXPECT_EQ(distance(Box(1.0, 1.0, 1.0), at({0.5, 0.5, 1.5}), tree, cube, id).distance, 0.0);
  EXPECT_FALSE(collide(Box(1.0, 1.0, 1.0), at({0.5, 0.5, above}), tree, cube, id).hit);
  const ShapeDistanceResult gap = distance(Box(1.0, 1.0, 1.0), at({0.5, 0.5, 1.75}), tree, cube, id);
  EXPECT_NEAR(gap.distance, 0.25, 1e-15);
  EXPECT_NEAR(gap.point_shape.z(), 1.25, 1e-15);
  EXPECT_NEAR(gap.point_mesh.z(), 1.0, 1e-15);
  // A box edge resting on the face: rotated 45 degrees about x, its lowest edge at z = 1.
  const Pose tilted{Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX()).toRotationMatrix(), {0.5, 0.5, 1.0 + std::sqrt(0.5)}};
  EXPECT_LT(distance(Box(1.0, 1.0, 1.0), tilted, tree, cube, id).distance, 1e-15);
  EXPECT_EQ(collide(Box(1.0, 1.0, 1.0), tilted, tree, cube, id, all).triangles,
            collide_brute_force(Box(1.0, 1.0, 1.0), tilted, cube, id, all).triangles);
}

// Solid shapes: a triangle wholly inside touches; a shape inside a closed mesh without touching
// its surface does not (the mesh is a surface).
TEST(ShapeQuery, TrianglesInsideTheShape) {
  Mesh small;
  small.vertices = {{0.1, 0.0, 0.0}, {0.0, 0.1, 0.0}, {0.0, 0.0, 0.1}};
  small.triangles = {{0, 1, 2}};
  const Tree tree = build(small);
  const Pose id;
  EXPECT_TRUE(collide(Box(1.0, 1.0, 1.0), id, tree, small, id).hit);
  EXPECT_TRUE(collide(Sphere(1.0), id, tree, small, id).hit);
  EXPECT_TRUE(collide(Capsule(0.5, 1.0), id, tree, small, id).hit);
  EXPECT_EQ(distance(Box(1.0, 1.0, 1.0), id, tree, small, id).distance, 0.0);

  const Mesh cube = qt::cube(Vec3::Constant(-2.0), 4.0);
  const Tree cube_tree = build(cube);
  EXPECT_FALSE(collide(Box(1.0, 1.0, 1.0), id, cube_tree, cube, id).hit);
  EXPECT_NEAR(distance(Box(1.0, 1.0, 1.0), id, cube_tree, cube, id).distance, 1.5, 1e-15);
  EXPECT_NEAR(distance(Sphere(1.0), id, cube_tree, cube, id).distance, 1.0, 1e-15);
  // A box enclosing the whole mesh touches every triangle.
  const ShapeQueryResult every =
      collide(Box(5.0, 5.0, 5.0), id, cube_tree, cube, id, {.mode = QueryMode::all_pairs});
  EXPECT_EQ(every.triangles.size(), cube.triangles.size());
}

// Degenerate triangles (a segment, a point) against each shape, tree and brute force.
TEST(ShapeQuery, DegenerateTriangles) {
  Mesh m;
  m.vertices = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {3.0, 3.0, 3.0}};
  m.triangles = {{0, 1, 1}, {2, 2, 2}};
  const Tree tree = build(m);
  const Pose id;
  const QueryOptions all{.mode = QueryMode::all_pairs};
  EXPECT_EQ(collide(Sphere(0.5), at({0.5, 0.5, 0.0}), tree, m, id, all).triangles, (std::vector<std::uint32_t>{0}));
  EXPECT_EQ(collide(Box(1.0, 1.0, 1.0), at({3.5, 3.5, 3.5}), tree, m, id, all).triangles,
            (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(collide(Capsule(0.1, 2.0), at({0.5, 0.0, 0.0}), tree, m, id, all).triangles,
            (std::vector<std::uint32_t>{0}));
  const ShapeDistanceResult d = distance(Sphere(0.5), at({3.0, 3.0, 4.0}), tree, m, id);
  EXPECT_EQ(d.triangle, 1u);
  EXPECT_NEAR(d.distance, 0.5, 1e-15);
  EXPECT_NEAR(distance(Box(1.0, 1.0, 1.0), at({0.5, 2.0, 0.0}), tree, m, id).distance, 1.5, 1e-15);
}

TEST(ShapeQuery, ModelOverloadsAndBounds) {
  const Model model(qt::cube());
  const Pose pm{Eigen::AngleAxisd(0.3, Vec3::UnitY()).toRotationMatrix(), {0.2, 0.0, 0.1}};
  const Pose ps = pm * at({0.5, 0.5, 1.2});
  EXPECT_EQ(collide(Sphere(0.3), ps, model, pm, {.mode = QueryMode::all_pairs}).triangles,
            collide(Sphere(0.3), ps, model.tree(), model.mesh(), pm, {.mode = QueryMode::all_pairs}).triangles);
  const ShapeDistanceResult d = distance(Capsule(0.1, 0.2), ps, model, pm);
  EXPECT_NEAR(d.distance, 0.0, 1e-12);  // its lower cap reaches the top face
  EXPECT_NEAR(distance(Box(0.2, 0.2, 0.2), ps, model, pm).distance, 0.1, 1e-12);

  EXPECT_EQ(bounding_box(Sphere(2.0)).half_extents, Vec3(2.0, 2.0, 2.0));
  EXPECT_EQ(bounding_box(Box(1.0, 2.0, 3.0)).half_extents, Vec3(0.5, 1.0, 1.5));
  EXPECT_EQ(bounding_box(Capsule(1.0, 4.0)).half_extents, Vec3(1.0, 1.0, 3.0));
}

// The error message of `fn`'s InputError (empty when it throws none).
template <class Fn>
std::string error_of(Fn fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ShapeQuery, BadInputNamesTheField) {
  EXPECT_NE(error_of([] { (void)Sphere(-1.0); }).find("radius"), std::string::npos);
  EXPECT_NE(error_of([] { (void)Box(1.0, 0.0, 1.0); }).find("size y"), std::string::npos);
  EXPECT_NE(error_of([] { (void)Capsule(1.0, std::nan("")); }).find("length"), std::string::npos);
  EXPECT_NE(error_of([] { (void)Capsule(std::numeric_limits<double>::infinity(), 1.0); }).find("radius"),
            std::string::npos);

  const Model model(qt::cube());
  Pose nan_pose;
  nan_pose.translation.x() = std::nan("");
  EXPECT_NE(error_of([&] { (void)collide(Sphere(1.0), nan_pose, model, Pose{}); }).find("shape pose"),
            std::string::npos);
  EXPECT_NE(error_of([&] { (void)distance(Box(1.0, 1.0, 1.0), Pose{}, model, nan_pose); }).find("mesh pose"),
            std::string::npos);
  Sphere bad(1.0);
  bad.radius = -2.0;  // public member made invalid after construction
  EXPECT_NE(error_of([&] { (void)distance(bad, Pose{}, model, Pose{}); }).find("sphere radius"), std::string::npos);
  EXPECT_NE(error_of([&] { (void)collide(Sphere(1.0), Pose{}, model, Pose{}, {.margin = -1.0}); }).find("margin"),
            std::string::npos);
  EXPECT_NE(error_of([&] { (void)collide(Sphere(1.0), Pose{}, model, Pose{}, {.solid = true}); }).find("solid"),
            std::string::npos);
  EXPECT_NE(error_of([&] { (void)distance(Sphere(1.0), Pose{}, model, Pose{}, {.upper_bound = -1.0}); })
                .find("upper_bound"),
            std::string::npos);
  const Mesh other = qt::random_soup(5, 1);
  EXPECT_NE(error_of([&] { (void)collide(Sphere(1.0), Pose{}, model.tree(), other, Pose{}); }).find("tree"),
            std::string::npos);
}

}  // namespace
}  // namespace tightbvh
