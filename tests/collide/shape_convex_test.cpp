// Cylinder and Convex against meshes: brute force, sampling, exact boundary cases, Box equivalence.
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
#include "tightbvh/collide.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/point_query.hpp"
#include "tightbvh/tri_distance.hpp"

namespace tightbvh {
namespace {

namespace qt = query_test;
using namespace shape_test;  // NOLINT: the shared checks

Pose at(const Vec3& t) { return {Mat3::Identity(), t}; }

// A convex hull of `count` random points in the ellipsoid of semi-axes (a, b, c), about 2 * count
// faces.
Convex random_convex(double a, double b, double c, std::uint64_t seed, int count = 27) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n;
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i) {
    const Vec3 dir = Vec3(n(rng), n(rng), n(rng)).normalized();
    points.push_back(Vec3(a * dir.x(), b * dir.y(), c * dir.z()));
  }
  return Convex(points);
}

Convex cube_corners(const Vec3& h) {
  std::vector<Vec3> corners;
  for (int i = 0; i < 8; ++i) corners.emplace_back(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z());
  return Convex(corners);
}

TEST(ShapeConvex, ConvexMatchesBruteForce) {
  std::uint64_t seed = 100;
  check_random([&](double a, double b, double c) { return random_convex(a, b, 0.5 * c, ++seed); }, 5);
}

TEST(ShapeConvex, CylinderMatchesBruteForce) {
  check_random([](double a, double b, double) { return Cylinder(0.5 * a, 2.0 * b); }, 6);
}

// Thin needles and flat discs.
TEST(ShapeConvex, CylinderExtremeAspectRatios) {
  check_random([](double a, double b, double) { return Cylinder(1e-3 * a, 4.0 * b); }, 7);
  check_random([](double a, double b, double) { return Cylinder(2.0 * a, 1e-3 * b); }, 8);
}

// The convex distance against an independent reference: 0 when a corner is in the hull or the
// triangle touches a face, else the least tri_tri_distance over every face (the query measures only
// the faces a corner is outside of), in the hull's frame as the query.
TEST(ShapeConvex, ConvexDistanceMatchesAllFaces) {
  const Mesh mesh = qt::subset(qt::shipped("meshes/elephant.off"), 8);
  const double radius = qt::bounding_sphere(mesh).radius;
  const Convex hull = random_convex(0.3 * radius, 0.2 * radius, 0.25 * radius, 11, 30);
  EXPECT_GE(hull.faces.size(), 40u);
  int touching = 0, apart = 0;
  for (const Pose& ps : shape_poses(mesh, 12, 14)) {
    const Pose to_hull = ps.inverse();
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto [a, b, c] = mesh.corners(t);
      const Vec3 v[3] = {to_hull.apply(a), to_hull.apply(b), to_hull.apply(c)};
      for (const Vec3& x : v) {
        bool in = true;
        for (const auto& f : hull.faces)
          in = in && (hull.vertices[f[1]] - hull.vertices[f[0]]).cross(hull.vertices[f[2]] - hull.vertices[f[0]])
                             .dot(x - hull.vertices[f[0]]) <= 0.0;
        if (in) best = 0.0;
      }
      for (const auto& f : hull.faces)
        best = std::min(best, tri_tri_distance(hull.vertices[f[0]], hull.vertices[f[1]], hull.vertices[f[2]], v[0], v[1],
                                               v[2])
                                  .distance);
    }
    const double got = distance_brute_force(hull, ps, mesh, Pose{}).distance;
    EXPECT_LE(std::abs(got - best), 1e-12 * std::max(best, radius)) << got << " vs " << best;
    (best == 0.0 ? touching : apart) += 1;
  }
  EXPECT_GT(touching, 0);
  EXPECT_GT(apart, 0);
}

// The hull of a box's 8 corners answers as the box: the same touching triangles (both exact), the
// same distances.
TEST(ShapeConvex, CubeCornersAnswerAsTheBox) {
  const Box box(0.4, 0.25, 0.3);
  const Convex hull = cube_corners(0.5 * box.size);
  EXPECT_EQ(hull.vertices.size(), 8u);
  EXPECT_EQ(hull.faces.size(), 12u);
  const QueryOptions all{.mode = QueryMode::all_pairs};
  int hits = 0;
  for (const Mesh& mesh : test_meshes()) {
    const Tree tree = build(mesh);
    const double radius = qt::bounding_sphere(mesh).radius;
    for (const Pose& unit : shape_poses(mesh, 21, 21)) {
      const Pose ps{unit.rotation, unit.translation};
      const ShapeQueryResult a = collide(box, ps, tree, mesh, Pose{}, all), b = collide(hull, ps, tree, mesh, Pose{}, all);
      EXPECT_EQ(a.triangles, b.triangles);
      const QueryOptions near{.mode = QueryMode::all_pairs, .margin = 0.1 * radius};
      EXPECT_EQ(collide(box, ps, tree, mesh, Pose{}, near).triangles, collide(hull, ps, tree, mesh, Pose{}, near).triangles);
      const double da = distance(box, ps, tree, mesh, Pose{}).distance, db = distance(hull, ps, tree, mesh, Pose{}).distance;
      EXPECT_LE(std::abs(da - db), 1e-12 * std::max(1.0, da)) << da << " vs " << db;
      hits += a.hit ? 1 : 0;
    }
  }
  EXPECT_GT(hits, 0);
}

// Exact boundary cases on exactly representable coordinates: a hull face flush with a triangle, a
// hull vertex on a triangle, and the same a hair apart.
TEST(ShapeConvex, ConvexBoundaryIsExact) {
  const Mesh cube = qt::cube();
  const Tree tree = build(cube);
  const Pose id;
  const double above = std::nextafter(1.5, 2.0);
  const Convex unit = cube_corners(Vec3::Constant(0.5));
  // Bottom face flush with the cube's top face.
  EXPECT_TRUE(collide(unit, at({0.5, 0.5, 1.5}), tree, cube, id).hit);
  EXPECT_EQ(distance(unit, at({0.5, 0.5, 1.5}), tree, cube, id).distance, 0.0);
  EXPECT_FALSE(collide(unit, at({0.5, 0.5, above}), tree, cube, id).hit);
  EXPECT_GT(distance(unit, at({0.5, 0.5, above}), tree, cube, id).distance, 0.0);
  // A tetrahedron standing on its apex, the apex exactly on the top face.
  const Convex apex(std::vector<Vec3>{{0.0, 0.0, 0.0}, {1.0, 0.0, 1.0}, {-1.0, 1.0, 1.0}, {-1.0, -1.0, 1.0}});
  EXPECT_TRUE(collide(apex, at({0.25, 0.5, 1.0}), tree, cube, id).hit);
  EXPECT_EQ(distance(apex, at({0.25, 0.5, 1.0}), tree, cube, id).distance, 0.0);
  EXPECT_FALSE(collide(apex, at({0.25, 0.5, std::nextafter(1.0, 2.0)}), tree, cube, id).hit);
  // A triangle wholly inside the hull touches; a hull inside a closed mesh does not.
  Mesh small;
  small.vertices = {{0.1, 0.0, 0.0}, {0.0, 0.1, 0.0}, {0.0, 0.0, 0.1}};
  small.triangles = {{0, 1, 2}};
  EXPECT_TRUE(collide(unit, id, build(small), small, id).hit);
  const Mesh big = qt::cube(Vec3::Constant(-2.0), 4.0);
  EXPECT_FALSE(collide(unit, id, build(big), big, id).hit);
  EXPECT_NEAR(distance(unit, id, build(big), big, id).distance, 1.5, 1e-15);
}

// The cylinder's GJK distance against dense sampling of its surface (each sample measured exactly
// against the triangle): never more than the sampled minimum (plus the tolerance), never less than
// it by more than the sampling's resolution; touching decisions agree away from that band, and a
// triangle point sampled inside the solid means touching.
TEST(ShapeConvex, CylinderAgreesWithSampling) {
  const Cylinder cyl(0.3, 0.8);
  std::vector<Vec3> surface;
  constexpr int kAround = 128, kAlong = 64, kRings = 20;
  for (int i = 0; i < kAround; ++i) {
    const double t = 2.0 * M_PI * i / kAround;
    for (int j = 0; j <= kAlong; ++j)
      surface.emplace_back(cyl.radius * std::cos(t), cyl.radius * std::sin(t), cyl.length * (double(j) / kAlong - 0.5));
    for (int k = 0; k < kRings; ++k) {
      const double rr = cyl.radius * k / kRings;
      surface.emplace_back(rr * std::cos(t), rr * std::sin(t), 0.5 * cyl.length);
      surface.emplace_back(rr * std::cos(t), rr * std::sin(t), -0.5 * cyl.length);
    }
  }
  // The farthest any surface point is from a sample.
  const double resolution = std::hypot(M_PI * cyl.radius / kAround, 0.5 * cyl.length / kAlong) + cyl.radius / kRings;
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-0.7, 0.7);
  int touching = 0, apart = 0;
  for (int trial = 0; trial < 60; ++trial) {
    Mesh m;
    m.vertices = {Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng))};
    m.triangles = {{0, 1, 2}};
    const Tree tree = build(m);
    const Pose ps{qt::random_rotation(rng), Vec3(0.2 * u(rng), 0.2 * u(rng), 0.2 * u(rng))};
    const ShapeDistanceResult d = distance(cyl, ps, tree, m, Pose{});
    double sampled = std::numeric_limits<double>::infinity();
    for (const Vec3& x : surface)
      sampled = std::min(sampled, closest_point_on_triangle(ps.apply(x), m.vertices[0], m.vertices[1], m.vertices[2]).distance);
    bool inside = false;  // a triangle point inside the solid
    for (int i = 0; i <= 20 && !inside; ++i)
      for (int j = 0; i + j <= 20 && !inside; ++j) {
        const Vec3 x = m.vertices[0] + (m.vertices[1] - m.vertices[0]) * (i / 20.0) + (m.vertices[2] - m.vertices[0]) * (j / 20.0);
        inside = outside(cyl, ps, x) < 0.0;
      }
    const double tol = kCylinderTolerance * 2.0;
    if (inside) {
      EXPECT_EQ(d.distance, 0.0) << trial;
      ++touching;
      continue;
    }
    EXPECT_LE(d.distance, sampled + tol) << trial;
    if (!d.intersecting) EXPECT_GE(d.distance, sampled - resolution - tol) << trial;
    if (sampled > resolution + tol) {
      EXPECT_FALSE(d.intersecting) << trial;
      ++apart;
    }
    EXPECT_EQ(collide(cyl, ps, tree, m, Pose{}).hit, d.intersecting) << trial;
  }
  EXPECT_GT(touching, 5);
  EXPECT_GT(apart, 5);
}

// Exact contact configurations for the cylinder (within its tolerance) and clear gaps.
TEST(ShapeConvex, CylinderContacts) {
  const Mesh cube = qt::cube();
  const Tree tree = build(cube);
  const Pose id;
  // Standing on the top face, lying on it (side tangent), a hair above.
  EXPECT_TRUE(collide(Cylinder(0.25, 1.0), at({0.5, 0.5, 1.5}), tree, cube, id).hit);
  const Pose lying{Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix(), {0.5, 0.5, 1.25}};
  EXPECT_TRUE(collide(Cylinder(0.25, 0.5), lying, tree, cube, id).hit);
  EXPECT_FALSE(collide(Cylinder(0.25, 1.0), at({0.5, 0.5, 1.5 + 1e-6}), tree, cube, id).hit);
  EXPECT_NEAR(distance(Cylinder(0.25, 1.0), at({0.5, 0.5, 1.75}), tree, cube, id).distance, 0.25, 1e-12);
  EXPECT_NEAR(distance(Cylinder(0.25, 0.5), Pose{lying.rotation, {0.5, 0.5, 1.5}}, tree, cube, id).distance, 0.25,
              1e-12);
  // Beside the cube, the rim's nearest point at distance 0.1 from the face x = 1.
  EXPECT_NEAR(distance(Cylinder(0.2, 0.5), at({1.3, 0.5, 0.5}), tree, cube, id).distance, 0.1, 1e-12);
  EXPECT_EQ(bounding_box(Cylinder(1.0, 4.0)).half_extents, Vec3(1.0, 1.0, 2.0));
  const Obb hb = bounding_box(cube_corners(Vec3(1.0, 2.0, 3.0)));
  EXPECT_EQ(hb.half_extents, Vec3(1.0, 2.0, 3.0));
  EXPECT_EQ(hb.center, Vec3::Zero());
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

TEST(ShapeConvex, BadInputNamesTheField) {
  EXPECT_NE(error_of([] { (void)Cylinder(-1.0, 1.0); }).find("Cylinder: radius"), std::string::npos);
  EXPECT_NE(error_of([] { (void)Cylinder(1.0, std::nan("")); }).find("Cylinder: length"), std::string::npos);
  EXPECT_NE(error_of([] { (void)Convex(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}); }).find("at least 4"),
            std::string::npos);
  EXPECT_NE(error_of([] { (void)Convex(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}); })
                .find("coplanar"),
            std::string::npos);
  EXPECT_NE(error_of([] { (void)Convex(std::vector<Vec3>{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}); })
                .find("collinear"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              (void)Convex(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, std::nan(""), 0}, {0, 0, 1}});
            }).find("points[2]"),
            std::string::npos);
  const Model model(qt::cube());
  Cylinder bad(1.0, 1.0);
  bad.length = 0.0;
  EXPECT_NE(error_of([&] { (void)collide(bad, Pose{}, model, Pose{}); }).find("cylinder length"), std::string::npos);
  Convex empty = cube_corners(Vec3::Ones());
  empty.vertices.clear();
  empty.faces.clear();
  EXPECT_NE(error_of([&] { (void)distance(empty, Pose{}, model, Pose{}); }).find("convex"), std::string::npos);
}

}  // namespace
}  // namespace tightbvh
