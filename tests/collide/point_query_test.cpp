#include "tightbvh/point_query.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "collide/query_common.hpp"
#include "solid_fixtures.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/closed.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/model.hpp"

namespace tightbvh {
namespace {

using namespace query_test;
using namespace solid_test;

// Points near the surface (a vertex or a triangle's point plus up to 2% of the radius), on it
// (a point of a triangle), at the vertices, and far from it (up to 3 radii), mesh frame.
std::vector<Vec3> sample_points(const Mesh& m, std::size_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0), s(-1.0, 1.0);
  const Sphere sphere = bounding_sphere(m);
  std::vector<Vec3> points;
  for (std::size_t i = 0; i < count; ++i) {
    const auto t = static_cast<std::size_t>(u(rng) * static_cast<double>(m.triangles.size())) % m.triangles.size();
    const auto [a, b, c] = m.corners(t);
    double x = u(rng), y = u(rng);
    if (x + y > 1.0) x = 1.0 - x, y = 1.0 - y;
    const Vec3 on = a + x * (b - a) + y * (c - a);
    const Vec3 offset(s(rng), s(rng), s(rng));
    switch (i % 4) {
      case 0: points.push_back(on + 0.02 * sphere.radius * offset); break;
      case 1: points.push_back(on); break;
      case 2: points.push_back(i % 8 == 2 ? a : on + 0.2 * sphere.radius * offset); break;
      default: points.push_back(sphere.center + 3.0 * sphere.radius * offset); break;
    }
  }
  return points;
}

std::vector<Vec3> posed(const Pose& pose, const std::vector<Vec3>& points) {
  std::vector<Vec3> out;
  for (const Vec3& p : points) out.push_back(pose.apply(p));
  return out;
}

// The tree's answer equals the brute force's: the same distance (to 1e-12 relative; in fact bit
// for bit), triangle, point and barycentric coordinates, which reconstruct the point. A Model of
// the same tree (its search runs on the wide nodes) gives the tree's answer bit for bit.
void expect_brute_force(const Mesh& m, const Tree& t, const Pose& pose, const std::vector<Vec3>& points,
                        const PointQueryOptions& options = {}) {
  const std::vector<ClosestPoint> got = closest_points(t, m, pose, points, options);
  const std::vector<ClosestPoint> want = closest_points_brute_force(m, pose, points, options);
  const std::vector<ClosestPoint> on_model = closest_points(*make_model(m, t), pose, points, options);
  ASSERT_EQ(got.size(), points.size());
  ASSERT_EQ(on_model.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    SCOPED_TRACE("point " + std::to_string(i));
    EXPECT_EQ(on_model[i].distance, got[i].distance);
    EXPECT_EQ(on_model[i].triangle, got[i].triangle);
    EXPECT_EQ(on_model[i].point, got[i].point);
    EXPECT_EQ(on_model[i].beyond_max_distance, got[i].beyond_max_distance);
    EXPECT_EQ(got[i].beyond_max_distance, want[i].beyond_max_distance);
    EXPECT_NEAR(got[i].distance, want[i].distance, 1e-12 * want[i].distance);
    EXPECT_EQ(got[i].triangle, want[i].triangle);
    EXPECT_EQ(got[i].point, want[i].point);
    EXPECT_EQ(got[i].barycentric, want[i].barycentric);
    if (got[i].beyond_max_distance) {
      EXPECT_EQ(got[i].distance, options.max_distance);
      EXPECT_GE(want[i].distance, options.max_distance);
      continue;
    }
    EXPECT_LT(got[i].distance, options.max_distance);
    EXPECT_NEAR((points[i] - got[i].point).norm(),
                got[i].distance, 1e-12 * (1.0 + got[i].distance));
    const Vec3& w = got[i].barycentric;
    EXPECT_NEAR(w.sum(), 1.0, 1e-12);
    EXPECT_GE(w.minCoeff(), 0.0);
    const auto [a, b, c] = m.corners(got[i].triangle);
    const Vec3 world = pose.apply(w[0] * a + w[1] * b + w[2] * c);
    const double scale = 1.0 + got[i].point.cwiseAbs().maxCoeff();
    EXPECT_LT((world - got[i].point).norm(), 1e-12 * scale);
  }
}

TEST(PointQuery, TriangleClosestPointByRegion) {
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  struct Case {
    Vec3 p, point, barycentric;
  };
  const Case cases[] = {
      {{0.5, 0.5, 3}, {0.5, 0.5, 0}, {0.5, 0.25, 0.25}},  // face region
      {{-1, -1, 1}, a, {1, 0, 0}},                         // vertex regions
      {{3, -1, 0}, b, {0, 1, 0}},
      {{-1, 3, -2}, c, {0, 0, 1}},
      {{1, -1, 0}, {1, 0, 0}, {0.5, 0.5, 0}},    // edge ab
      {{2, 2, 0}, {1, 1, 0}, {0, 0.5, 0.5}},     // edge bc
      {{-1, 0.5, 1}, {0, 0.5, 0}, {0.75, 0, 0.25}},  // edge ca
  };
  for (const Case& k : cases) {
    const TrianglePoint r = closest_point_on_triangle(k.p, a, b, c);
    EXPECT_LT((r.point - k.point).norm(), 1e-15) << k.p.transpose();
    EXPECT_LT((r.barycentric - k.barycentric).norm(), 1e-15) << k.p.transpose();
    EXPECT_DOUBLE_EQ(r.distance, (k.p - k.point).norm());
  }
}

TEST(PointQuery, DegenerateTrianglesAreTheirSegmentOrPoint) {
  // Collinear corners: the segment from (0,0,0) to (4,0,0) with a middle corner.
  const Vec3 a(0, 0, 0), b(4, 0, 0), c(1, 0, 0);
  TrianglePoint r = closest_point_on_triangle({3, 1, 0}, a, b, c);
  EXPECT_EQ(r.point, Vec3(3, 0, 0));
  EXPECT_EQ(r.distance, 1.0);
  r = closest_point_on_triangle({-2, 0, 0}, a, b, c);
  EXPECT_EQ(r.point, a);
  // Nearly collinear (rounding): still the segment's closest point.
  r = closest_point_on_triangle({0.7, 0.7, 0.7}, Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(0.1, 0.1, 0.1 + 1e-17));
  EXPECT_LT((r.point - Vec3(0.7, 0.7, 0.7)).norm(), 1e-15);
  // A point.
  r = closest_point_on_triangle({1, 2, 2}, Vec3(1, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 0));
  EXPECT_EQ(r.point, Vec3(1, 0, 0));
  EXPECT_EQ(r.distance, std::sqrt(8.0));
}

TEST(PointQuery, TriangleClosestPointBeatsEverySample) {
  // Random triangles (some thin) and points: the answer is on the triangle (its barycentrics
  // reconstruct it) and no point of a fine barycentric grid is closer.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 60; ++trial) {
    const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    const Vec3 c = trial % 3 == 0 ? Vec3(a + 0.3 * (b - a) + 1e-9 * Vec3(u(rng), u(rng), u(rng)))
                                  : Vec3(u(rng), u(rng), u(rng));
    const Vec3 p = 2.0 * Vec3(u(rng), u(rng), u(rng));
    const TrianglePoint r = closest_point_on_triangle(p, a, b, c);
    const Vec3& w = r.barycentric;
    EXPECT_LT((w[0] * a + w[1] * b + w[2] * c - r.point).norm(), 1e-14);
    EXPECT_NEAR((p - r.point).norm(), r.distance, 1e-15);
    constexpr int n = 60;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const Vec3 q = a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n);
        EXPECT_LE(r.distance, (p - q).norm() + 1e-14);
      }
  }
}

TEST(PointQuery, ClosestPointsEqualBruteForceOnShippedMeshes) {
  for (const char* file : {"meshes/knot1.off", "meshes/fandisk.off", "meshes/elephant.off", "meshes/camel.off",
                           "meshes/knot2.off", "meshes/corpus/cgal/anchor.off", "meshes/corpus/cgal/cube-ouvert.off"}) {
    SCOPED_TRACE(file);
    const Mesh m = shipped(file);
    const Tree t = build(m, {.threads = 1});
    const std::vector<Vec3> points = sample_points(m, 48, 11);
    expect_brute_force(m, t, Pose::identity(), points);
    // The same points in a random pose of the mesh.
    std::mt19937_64 rng(5);
    const Pose pose{random_rotation(rng), Vec3(3.0, -2.0, 10.0)};
    expect_brute_force(m, t, pose, posed(pose, points));
  }
}

TEST(PointQuery, SoupsWithDegenerateTrianglesAndOtherFitters) {
  const Mesh m = random_soup(300, 3);
  for (const FitMethod fitter : {FitMethod::aabb, FitMethod::pca}) {
    const Tree t = build(m, {.fitter = fitter, .leaf_size = 2, .threads = 1});
    expect_brute_force(m, t, Pose::identity(), sample_points(m, 64, 4));
  }
}

TEST(PointQuery, MaxDistance) {
  const Mesh m = shipped("meshes/knot1.off");
  const Tree t = build(m, {.threads = 1});
  const Sphere s = bounding_sphere(m);
  const std::vector<Vec3> points = sample_points(m, 64, 9);
  expect_brute_force(m, t, Pose::identity(), points, {.max_distance = 0.05 * s.radius});
  const std::vector<ClosestPoint> r = closest_points(t, m, Pose::identity(), points, {.max_distance = 0.05 * s.radius});
  std::size_t beyond = 0, within = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (!r[i].beyond_max_distance) { ++within; continue; }
    ++beyond;
    EXPECT_EQ(r[i].triangle, kNoTriangle);
    EXPECT_EQ(r[i].point, points[i]);
    EXPECT_EQ(r[i].barycentric, Vec3::Zero());
  }
  EXPECT_GT(beyond, 0u);
  EXPECT_GT(within, 0u);
  // 0: every point beyond.
  for (const ClosestPoint& c : closest_points(t, m, Pose::identity(), points, {.max_distance = 0.0}))
    EXPECT_TRUE(c.beyond_max_distance);
}

TEST(PointQuery, IdenticalForAnyThreadCount) {
  const ModelPtr model = make_model(shipped("meshes/fandisk.off"));
  const std::vector<Vec3> points = sample_points(model->mesh(), 1000, 21);
  std::mt19937_64 rng(8);
  const Pose pose{random_rotation(rng), Vec3(0.5, 1.0, -2.0)};
  const std::vector<Vec3> world = posed(pose, points);
  const std::vector<ClosestPoint> one = closest_points(*model, pose, world, {.threads = 1});
  const std::vector<ClosestPoint> signed_one = signed_distance(*model, pose, world, {.threads = 1});
  const std::vector<Containment> in_one = contains(*model, pose, world, 1);
  for (const unsigned threads : {2u, 3u, 0u}) {
    const std::vector<ClosestPoint> many = closest_points(*model, pose, world, {.threads = threads});
    const std::vector<ClosestPoint> signed_many = signed_distance(*model, pose, world, {.threads = threads});
    ASSERT_EQ(many.size(), one.size());
    for (std::size_t i = 0; i < one.size(); ++i) {
      EXPECT_EQ(many[i].distance, one[i].distance);
      EXPECT_EQ(many[i].triangle, one[i].triangle);
      EXPECT_EQ(many[i].point, one[i].point);
      EXPECT_EQ(signed_many[i].distance, signed_one[i].distance);
    }
    EXPECT_EQ(contains(*model, pose, world, threads), in_one);
  }
}

TEST(PointQuery, SignAndContainsAreClassifyPoint) {
  // Closed meshes: the shipped fandisk, a torus and a cube; the sign equals the brute-force
  // classification of the point mapped into the mesh frame (by the queries' own expression,
  // map_point), the magnitude the closest distance.
  for (const Mesh& m : {shipped("meshes/fandisk.off"), torus(1.0, 0.3, 24, 12), cube()}) {
    const ModelPtr model = make_model(m);
    ASSERT_TRUE(model->closedness().closed);
    std::mt19937_64 rng(13);
    for (const Pose& pose : {Pose::identity(), Pose{random_rotation(rng), Vec3(1.0, 2.0, 3.0)}}) {
      const std::vector<Vec3> world = posed(pose, sample_points(m, 96, 17));
      const std::vector<ClosestPoint> unsigned_d = closest_points(*model, pose, world);
      const std::vector<ClosestPoint> signed_d = signed_distance(*model, pose, world);
      const std::vector<Containment> in = contains(*model, pose, world);
      const Pose inverse = pose.inverse();
      std::size_t count[3] = {0, 0, 0};
      for (std::size_t i = 0; i < world.size(); ++i) {
        SCOPED_TRACE("point " + std::to_string(i));
        const Containment want = classify_point_brute_force(m, model->closedness(),
                                                                query_detail::map_point(inverse, world[i]));
        EXPECT_EQ(in[i], want);
        ++count[static_cast<int>(want)];
        EXPECT_EQ(signed_d[i].triangle, unsigned_d[i].triangle);
        switch (want) {
          case Containment::inside: EXPECT_EQ(signed_d[i].distance, -unsigned_d[i].distance); break;
          case Containment::outside: EXPECT_EQ(signed_d[i].distance, unsigned_d[i].distance); break;
          case Containment::on_surface: EXPECT_EQ(signed_d[i].distance, 0.0); break;
        }
      }
      EXPECT_GT(count[static_cast<int>(Containment::inside)], 0u);
      EXPECT_GT(count[static_cast<int>(Containment::outside)], 0u);
    }
  }
  // Exactly on the surface (identity pose: the coordinates as given).
  const ModelPtr cube_model = make_model(cube());
  const std::vector<Vec3> points = {{0.5, 0.5, 1.0}, {0.5, 0.5, 0.5}, {0.5, 0.5, 1.0000000000000002}, {1, 1, 1}};
  const std::vector<Containment> in = contains(*cube_model, Pose::identity(), points);
  EXPECT_EQ(in, (std::vector<Containment>{Containment::on_surface, Containment::inside, Containment::outside,
                                           Containment::on_surface}));
  const std::vector<ClosestPoint> sd = signed_distance(*cube_model, Pose::identity(), points);
  EXPECT_EQ(sd[0].distance, 0.0);
  EXPECT_EQ(sd[1].distance, -0.5);
  EXPECT_GT(sd[2].distance, 0.0);
  EXPECT_EQ(sd[3].distance, 0.0);
}

// contains() and signed_distance() on a Model shoot their first ray through the model's wide
// nodes (classify_point_wide), and closest_points() and signed_distance() search them
// (search_wide): the same closest points as on the tree, and the same sides as classify_point on
// the tree and the brute force,
// for random points, grid points on the coordinate planes of a CAD mesh (rays along its faces and
// through its edges and vertices, which go on to the tree's re-shot rays), the mesh's vertices
// and edge midpoints (on the surface), at scales 1e-3 to 1e4 and offsets up to 1e6.
TEST(PointQuery, WideNodesGiveTheTreesAnswers) {
  std::mt19937_64 rng(38);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::size_t count[3] = {0, 0, 0};
  for (const char* name : {"meshes/fandisk.off", "meshes/knot1.off"}) {
    for (const double scale : {1e-3, 1.0, 1e4}) {
      for (const double offset : {0.0, 1e6}) {
        SCOPED_TRACE(std::string(name) + " scale " + std::to_string(scale) + " offset " + std::to_string(offset));
        Mesh m = shipped(name);
        const Vec3 shift = offset * Vec3(unit(rng), unit(rng), unit(rng));
        for (Vec3& v : m.vertices) v = scale * v + shift;
        const ModelPtr model = make_model(m, {.fitter = scale == 1.0 ? Fitter{FitMethod::approx} : Fitter{AutoFit{}}});
        ASSERT_TRUE(model->closedness().closed);
        Aabb box;
        for (const Vec3& v : m.vertices) box.extend(v);
        std::vector<Vec3> points;
        for (int i = 0; i < 150; ++i) {
          Vec3 p;
          for (int k = 0; k < 3; ++k) p[k] = box.min[k] + (unit(rng) * 1.1 - 0.05) * (box.max[k] - box.min[k]);
          points.push_back(p);
        }
        for (int i = 0; i < 8; ++i)  // a grid through the box, on the mesh's own coordinates
          for (int j = 0; j < 8; ++j)
            points.push_back({m.vertices[(i * 37) % m.vertices.size()].x(), m.vertices[(j * 53) % m.vertices.size()].y(),
                              m.vertices[((i + j) * 71) % m.vertices.size()].z()});
        for (std::size_t t = 0; t < m.triangles.size(); t += m.triangles.size() / 40 + 1) {
          const auto [a, b, c] = m.corners(static_cast<std::uint32_t>(t));
          points.push_back(a);
          points.push_back(0.5 * (a + b));
        }
        const std::vector<Containment> got = contains(*model, Pose::identity(), points);
        const std::vector<ClosestPoint> sd = signed_distance(*model, Pose::identity(), points);
        // The closest points on the wide nodes: the tree's, bit for bit.
        const std::vector<ClosestPoint> near = closest_points(*model, Pose::identity(), points);
        const std::vector<ClosestPoint> near_tree = closest_points(model->tree(), m, Pose::identity(), points);
        for (std::size_t i = 0; i < points.size(); ++i) {
          ASSERT_EQ(near[i].distance, near_tree[i].distance) << "point " << i;
          ASSERT_EQ(near[i].triangle, near_tree[i].triangle) << "point " << i;
          ASSERT_EQ(std::abs(sd[i].distance), near[i].distance) << "point " << i;
        }
        for (std::size_t i = 0; i < points.size(); ++i) {
          const Containment want = classify_point(model->tree(), m, model->closedness(), points[i]);
          ASSERT_EQ(got[i], want) << "point " << i;
          if (i % 5 == 0) ASSERT_EQ(want, classify_point_brute_force(m, model->closedness(), points[i])) << i;
          // The sign bit (an inside point at a rounded-off distance 0 gets -0).
          EXPECT_EQ(std::signbit(sd[i].distance), want == Containment::inside) << i;
          ++count[static_cast<int>(want)];
        }
      }
    }
  }
  EXPECT_GT(count[static_cast<int>(Containment::inside)], 100u);
  EXPECT_GT(count[static_cast<int>(Containment::outside)], 100u);
  EXPECT_GT(count[static_cast<int>(Containment::on_surface)], 100u);
}

TEST(PointQuery, BadInputIsAnInputErrorNamingIt) {
  const ModelPtr closed = make_model(cube());
  const ModelPtr open = make_model(shipped("meshes/corpus/cgal/cube-ouvert.off"));
  ASSERT_FALSE(open->closedness().closed);
  const std::vector<Vec3> good = {{0.5, 0.5, 0.5}};
  const auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no InputError)";
  };
  // Open meshes: closest points work, the sign and contains say why not.
  EXPECT_EQ(closest_points(*open, Pose::identity(), good).size(), 1u);
  EXPECT_NE(message([&] { (void)signed_distance(*open, Pose::identity(), good); }).find("not closed: "),
            std::string::npos);
  EXPECT_NE(message([&] { (void)contains(*open, Pose::identity(), good); }).find("boundary edge"), std::string::npos);
  // Points that are not finite: named by index.
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<Vec3> bad = {{0, 0, 0}, {0, 0, 0}, {0, nan, 0}, {inf, 0, 0}};
  EXPECT_NE(message([&] { (void)closest_points(*closed, Pose::identity(), bad); }).find("point 2 is not finite"),
            std::string::npos);
  EXPECT_NE(message([&] { (void)signed_distance(*closed, Pose::identity(), bad); }).find("point 2"), std::string::npos);
  EXPECT_NE(message([&] { (void)contains(*closed, Pose::identity(), bad); }).find("point 2"), std::string::npos);
  // Bad poses and options.
  Pose skew;
  skew.rotation(0, 1) = 0.5;
  EXPECT_NE(message([&] { (void)closest_points(*closed, skew, good); }).find("not orthonormal"), std::string::npos);
  Pose nan_pose;
  nan_pose.translation.x() = nan;
  EXPECT_NE(message([&] { (void)contains(*closed, nan_pose, good); }).find("not finite"), std::string::npos);
  EXPECT_NE(message([&] { (void)closest_points(*closed, Pose::identity(), good, {.max_distance = -1.0}); })
                .find("max_distance"),
            std::string::npos);
  EXPECT_NE(message([&] { (void)closest_points(closed->tree(), open->mesh(), Pose::identity(), good); })
                .find("tree was built over"),
            std::string::npos);
}

TEST(PointQuery, FarPointsAndFarMeshes) {
  // Points 1e100 away, and a mesh 1e6 from the origin: the same answers as the brute force.
  const Mesh m = transformed(cube(), 1.0, Vec3(1e6, -1e6, 3e6));
  const Tree t = build(m, {.threads = 1});
  const std::vector<Vec3> points = {{1e100, 0, 0}, {-1e100, 1e100, 0}, {1e6 + 0.5, -1e6 + 0.5, 3e6 + 2}};
  expect_brute_force(m, t, Pose::identity(), points);
  for (const ClosestPoint& r : closest_points(t, m, Pose::identity(), points)) EXPECT_FALSE(r.beyond_max_distance);
}

TEST(PointQuery, EmptyPointSets) {
  const ModelPtr model = make_model(cube());
  EXPECT_TRUE(closest_points(*model, Pose::identity(), std::vector<Vec3>{}).empty());
  EXPECT_TRUE(signed_distance(*model, Pose::identity(), std::vector<Vec3>{}).empty());
  EXPECT_TRUE(contains(*model, Pose::identity(), std::vector<Vec3>{}).empty());
}

}  // namespace
}  // namespace tightbvh
