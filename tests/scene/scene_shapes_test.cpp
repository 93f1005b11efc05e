// Shapes in scenes: the shape–shape distance (closed forms, and against the shape–mesh query on a
// box's triangles), scenes mixing models and shapes against every object pair, and shapes in
// the scene file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <utility>
#include <variant>
#include <random>
#include <string>
#include <unistd.h>
#include <vector>

#include "scene_fixtures.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/scene.hpp"
#include "tightbvh/scene_file.hpp"
#include "tightbvh/shape.hpp"

namespace tightbvh {
namespace {

using scene_test::random_pose;

Pose at(double x, double y, double z) { return {Mat3::Identity(), Vec3(x, y, z)}; }

Pose turned_about_z(double angle, const Vec3& t) {
  return {Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix(), t};
}

// The surface of Box(size) centered at the origin, outward triangles.
Mesh box_mesh(const Vec3& size) {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1 ? 0.5 : -0.5) * size.x(), (i & 2 ? 0.5 : -0.5) * size.y(),
                            (i & 4 ? 0.5 : -0.5) * size.z());
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

TEST(ShapePair, ClosedForms) {
  const Shape ball = Sphere(1.0), rod = Capsule(0.5, 4.0), crate = Box(2.0, 2.0, 2.0);
  EXPECT_DOUBLE_EQ(distance(ball, at(0, 0, 0), Shape(Sphere(0.5)), at(3, 0, 0)).distance, 1.5);
  // Two capsules along z, side by side; crossed at right angles, one above the other.
  EXPECT_DOUBLE_EQ(distance(rod, at(0, 0, 0), rod, at(2, 0, 0)).distance, 1.0);
  const Pose lying{Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix(), Vec3(0, 0, 4)};
  EXPECT_NEAR(distance(rod, at(0, 0, 0), rod, lying).distance, 4.0 - 2.0 - 1.0, 1e-15);
  // Sphere and box: off a face, off an edge, off a corner; a center inside the box is 0.
  EXPECT_DOUBLE_EQ(distance(ball, at(3, 0, 0), crate, at(0, 0, 0)).distance, 1.0);
  EXPECT_NEAR(distance(ball, at(3, 3, 0), crate, at(0, 0, 0)).distance, std::sqrt(8.0) - 1.0, 1e-15);
  EXPECT_NEAR(distance(ball, at(3, 3, 3), crate, at(0, 0, 0)).distance, std::sqrt(12.0) - 1.0, 1e-15);
  EXPECT_EQ(distance(Shape(Sphere(0.1)), at(0.2, 0.3, 0), crate, at(0, 0, 0)).distance, 0.0);
  // Box and box: face to face, and one turned 45 degrees about z so that its edge faces the other.
  EXPECT_DOUBLE_EQ(distance(crate, at(0, 0, 0), crate, at(3, 0, 0)).distance, 1.0);
  EXPECT_NEAR(distance(crate, at(0, 0, 0), crate, turned_about_z(M_PI / 4, Vec3(4, 0, 0))).distance,
              4.0 - 1.0 - std::sqrt(2.0), 1e-15);
  // Nested: a small box wholly inside, no surfaces touching.
  EXPECT_EQ(distance(crate, at(0, 0, 0), Shape(Box(0.2, 0.2, 0.2)), at(0.1, 0, 0)).distance, 0.0);
  // A capsule through the box without an end inside: its axis crosses two faces.
  EXPECT_EQ(distance(Shape(Capsule(0.01, 10.0)), at(0.5, 0.5, 0), crate, at(0, 0, 0)).distance, 0.0);
  // The points: on each shape, that far apart.
  const ShapePairDistance d = distance(ball, at(3, 3, 0), crate, at(0, 0, 0));
  EXPECT_NEAR((d.point_a - Vec3(3, 3, 0)).norm(), 1.0, 1e-15);
  EXPECT_NEAR((d.point_b - Vec3(1, 1, 0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((d.point_a - d.point_b).norm(), d.distance, 1e-15);
  EXPECT_THROW((void)distance(ball, Pose{Mat3::Zero(), Vec3::Zero()}, crate, at(0, 0, 0)), InputError);
}

// The hull of a box's 8 corners.
Convex corners_of(const Vec3& size) { return Convex(box_mesh(size).vertices); }

// Random points on a sphere of this radius, their hull.
Convex round_hull(double radius, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n;
  std::vector<Vec3> points;
  for (int i = 0; i < 24; ++i) points.push_back(radius * Vec3(n(rng), n(rng), n(rng)).normalized());
  return Convex(points);
}

TEST(ShapePair, CylinderAndConvexClosedForms) {
  const Shape drum = Cylinder(0.5, 2.0), ball = Sphere(0.25), crate = Box(2.0, 2.0, 2.0);
  const Shape hull = corners_of(Vec3(2.0, 2.0, 2.0));
  // Side by side, end to end, and a sphere off the rim's edge.
  EXPECT_NEAR(distance(drum, at(0, 0, 0), drum, at(3, 0, 0)).distance, 2.0, 1e-12);
  EXPECT_NEAR(distance(drum, at(0, 0, 0), drum, at(0.2, 0, 2.5)).distance, 0.5, 1e-12);
  EXPECT_NEAR(distance(drum, at(0, 0, 0), ball, at(1.5, 0, 2.0)).distance, std::sqrt(2.0) - 0.25, 1e-12);
  EXPECT_NEAR(distance(drum, at(0, 0, 0), Shape(Capsule(0.25, 1.0)), at(0, 0, 3.0)).distance, 1.25, 1e-12);
  EXPECT_EQ(distance(drum, at(0, 0, 0), ball, at(0.3, 0.1, 0.9)).distance, 0.0);  // inside
  // The hull of a box's corners answers as the box.
  for (const Pose& p : {at(3, 0.5, 0), at(2.5, 2.5, 2.5), turned_about_z(M_PI / 4, Vec3(4, 0, 0)), at(0.5, 0, 0)}) {
    EXPECT_NEAR(distance(hull, at(0, 0, 0), crate, p).distance, distance(crate, at(0, 0, 0), crate, p).distance, 1e-12);
    EXPECT_NEAR(distance(ball, p, hull, at(0, 0, 0)).distance, distance(ball, p, crate, at(0, 0, 0)).distance, 1e-12);
  }
  const ShapePairDistance d = distance(drum, at(0, 0, 0), hull, at(3, 0, 0));
  EXPECT_NEAR(d.distance, 1.5, 1e-12);
  EXPECT_NEAR(d.point_a.x(), 0.5, 1e-12);
  EXPECT_NEAR(d.point_b.x(), 2.0, 1e-12);
  EXPECT_EQ(shape_name(drum), std::string("cylinder"));
  EXPECT_EQ(shape_name(hull), std::string("convex"));
}

TEST(ShapePair, CylinderAndConvexAgreeWithTheShapeQueryOnTheBoxSurface) {
  // As below, for pairs through GJK: the cylinder within its tolerance, the hull to rounding.
  std::mt19937_64 rng(19);
  const Vec3 size(1.0, 0.6, 0.4);
  const ModelPtr surface = make_model(box_mesh(size));
  const Shape box = Box(size), box_hull = corners_of(size);
  int apart = 0, touching = 0;
  for (int i = 0; i < 150; ++i) {
    const Pose pb = random_pose(rng, 1.5), pa = random_pose(rng, 1.5);
    for (const Shape& a : {Shape(Cylinder(0.25, 0.5)), Shape(round_hull(0.3, 5)), Shape(Sphere(0.3)),
                           Shape(Capsule(0.2, 0.7))}) {
      for (const Shape& b : {box, box_hull}) {
        if (!std::holds_alternative<Cylinder>(a) && !std::holds_alternative<Convex>(a) &&
            !std::holds_alternative<Convex>(b))
          continue;
        const ShapePairDistance pair = distance(a, pa, b, pb);
        EXPECT_EQ(distance(b, pb, a, pa).distance, pair.distance) << i << " " << shape_name(a);  // symmetric
        const ShapeDistanceResult mesh = std::visit([&](const auto& s) { return distance(s, pa, *surface, pb); }, a);
        if (mesh.distance > 1e-8) {
          EXPECT_NEAR(pair.distance, mesh.distance, 1e-10 * (1.0 + mesh.distance)) << i << " " << shape_name(a);
          ++apart;
        } else if (mesh.distance == 0.0) {
          EXPECT_EQ(pair.distance, 0.0) << i << " " << shape_name(a);
          ++touching;
        }
      }
    }
  }
  EXPECT_GT(apart, 100);
  EXPECT_GT(touching, 50);
}

TEST(ShapePair, AgreesWithTheShapeQueryOnTheBoxSurface) {
  // A box as a solid shape and as its 12 triangles: where the mesh route says apart, the two
  // distances agree; where the solids touch, the pair says 0.
  std::mt19937_64 rng(17);
  const Vec3 size(1.0, 0.6, 0.4);
  const ModelPtr surface = make_model(box_mesh(size));
  const Shape box = Box(size);
  int apart = 0, touching = 0;
  for (int i = 0; i < 300; ++i) {
    const Pose pb = random_pose(rng, 1.5), pa = random_pose(rng, 1.5);
    for (const Shape& a : {Shape(Sphere(0.3)), Shape(Capsule(0.2, 0.7)), Shape(Box(0.5, 0.3, 0.8))}) {
      const ShapePairDistance pair = distance(a, pa, box, pb);
      const ShapeDistanceResult mesh =
          std::visit([&](const auto& s) { return distance(s, pa, *surface, pb); }, a);
      if (mesh.distance > 0.0) {
        EXPECT_NEAR(pair.distance, mesh.distance, 1e-12 * (1.0 + mesh.distance)) << i << " " << shape_name(a);
        ++apart;
      } else {
        EXPECT_EQ(pair.distance, 0.0) << i << " " << shape_name(a);
        ++touching;
      }
    }
  }
  EXPECT_GT(apart, 100);
  EXPECT_GT(touching, 50);
}

// Every pair of a scene of models and shapes, by the pair queries directly.
struct Expected {
  std::vector<std::pair<ObjectId, ObjectId>> hits;
  double nearest = std::numeric_limits<double>::infinity();
};

Expected every_pair(const Scene& scene, double margin) {
  Expected e;
  const std::vector<ObjectId> ids = scene.ids();
  for (std::size_t i = 0; i < ids.size(); ++i)
    for (std::size_t j = i + 1; j < ids.size(); ++j) {
      const SceneObject& a = scene.object(ids[i]);
      const SceneObject& b = scene.object(ids[j]);
      double d = 0.0;
      bool hit = false;
      if (a.model && b.model) {
        d = distance(*a.model, a.pose, *b.model, b.pose).distance;
        hit = collide(*a.model, a.pose, *b.model, b.pose, {.margin = margin}).hit;
      } else if (a.shape && b.shape) {
        d = distance(*a.shape, a.pose, *b.shape, b.pose).distance;
        hit = d <= margin;
      } else {
        const SceneObject& s = a.shape ? a : b;
        const SceneObject& m = a.shape ? b : a;
        std::visit(
            [&](const auto& shape) {
              d = distance(shape, s.pose, *m.model, m.pose).distance;
              hit = collide(shape, s.pose, *m.model, m.pose, {.margin = margin}).hit;
            },
            *s.shape);
      }
      if (hit) e.hits.emplace_back(ids[i], ids[j]);
      e.nearest = std::min(e.nearest, d);
    }
  return e;
}

TEST(SceneShapes, MixedSceneEqualsEveryPair) {
  std::mt19937_64 rng(23);
  const std::vector<ModelPtr> models = scene_test::mixed_models();
  const std::vector<Shape> shapes{Sphere(0.25), Capsule(0.1, 0.8), Box(0.4, 0.3, 0.6), Cylinder(0.2, 0.7),
                                  round_hull(0.35, 3)};
  int shape_model_hits = 0, shape_shape_hits = 0, gjk_hits = 0;
  for (int round = 0; round < 6; ++round) {
    Scene scene;
    for (int k = 0; k < 12; ++k) {
      if (k % 2 == 0)
        (void)scene.add(models[static_cast<std::size_t>(k / 2) % models.size()], random_pose(rng, 3.0));
      else
        (void)scene.add(shapes[static_cast<std::size_t>(k / 2) % shapes.size()], random_pose(rng, 3.0));
    }
    for (const double margin : {0.0, 0.1}) {
      const Expected want = every_pair(scene, margin);
      std::vector<std::pair<ObjectId, ObjectId>> got;
      for (const ObjectPairHit& h : collide(scene, {.mode = QueryMode::all_pairs, .margin = margin}, 2)) {
        got.emplace_back(h.a, h.b);
        const bool a_is_shape = scene.object(h.a).shape.has_value(), b_is_shape = scene.object(h.b).shape.has_value();
        shape_model_hits += a_is_shape != b_is_shape;
        shape_shape_hits += a_is_shape && b_is_shape;
        for (const ObjectId id : {h.a, h.b})
          if (const auto& sh = scene.object(id).shape; sh && (std::holds_alternative<Cylinder>(*sh) ||
                                                               std::holds_alternative<Convex>(*sh)))
            ++gjk_hits;
        for (const TrianglePair& p : h.result.pairs) {  // the shape side's index is 0
          if (a_is_shape) EXPECT_EQ(p.a, 0u);
          if (b_is_shape) EXPECT_EQ(p.b, 0u);
        }
      }
      EXPECT_EQ(got, want.hits) << "round " << round << " margin " << margin;
      if (margin == 0.0) {
        const auto nearest = distance(scene);
        ASSERT_TRUE(nearest.has_value());
        EXPECT_EQ(nearest->result.distance, want.nearest);
        const SceneObject& a = scene.object(nearest->a);
        const SceneObject& b = scene.object(nearest->b);
        EXPECT_NEAR((nearest->result.point_a - nearest->result.point_b).norm(), nearest->result.distance, 1e-12);
        EXPECT_NEAR((a.pose.apply(nearest->result.point_a_local) - nearest->result.point_a).norm(), 0.0, 1e-12);
        EXPECT_NEAR((b.pose.apply(nearest->result.point_b_local) - nearest->result.point_b).norm(), 0.0, 1e-12);
      }
    }
    // Moves: the pair cache follows shapes as it follows models.
    for (const ObjectId id : scene.ids()) scene.set_pose(id, random_pose(rng, 3.0));
    EXPECT_EQ(collide(scene, {.mode = QueryMode::all_pairs}).size(), every_pair(scene, 0.0).hits.size());
  }
  EXPECT_GT(shape_model_hits, 5);  // the scenes are dense enough to test every kind of pair
  EXPECT_GT(shape_shape_hits, 2);
  EXPECT_GT(gjk_hits, 3);
}

// A shape as the query object of the single-object calls: the same objects, distances and
// points as the pair queries against every object of a mixed scene.
TEST(SceneShapes, ShapeAsTheQueryObject) {
  std::mt19937_64 rng(31);
  const std::vector<ModelPtr> models = scene_test::mixed_models();
  const std::vector<Shape> shapes{Sphere(0.3), Capsule(0.15, 0.9), Box(0.5, 0.35, 0.7), Cylinder(0.25, 0.8),
                                  round_hull(0.4, 7)};
  int hits = 0, shape_hits = 0;
  for (int round = 0; round < 10; ++round) {
    Scene scene;
    for (int k = 0; k < 10; ++k) {
      if (k % 3 != 2)
        (void)scene.add(models[static_cast<std::size_t>(k) % models.size()], random_pose(rng, 2.5));
      else
        (void)scene.add(shapes[static_cast<std::size_t>(k) % shapes.size()], random_pose(rng, 2.5));
    }
    const Shape& query = shapes[static_cast<std::size_t>(round) % shapes.size()];
    std::vector<Pose> poses;
    for (int i = 0; i < 4; ++i) poses.push_back(random_pose(rng, 2.5));
    const auto batch = collide_batch(scene, query, poses, {}, 2);
    ASSERT_EQ(batch.size(), poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const Pose& pose = poses[i];
      std::vector<ObjectId> want_hits, want_within;
      std::optional<std::pair<double, ObjectId>> want_nearest;
      for (const ObjectId id : scene.ids()) {
        const SceneObject& o = scene.object(id);
        double d = 0.0;
        if (o.shape) {
          d = distance(*o.shape, o.pose, query, pose).distance;
        } else {
          d = std::visit([&](const auto& s) { return distance(s, pose, *o.model, o.pose).distance; }, query);
        }
        if (d == 0.0) want_hits.push_back(id);
        if (d < 0.2) want_within.push_back(id);
        if (!want_nearest || d < want_nearest->first) want_nearest = std::pair(d, id);
      }
      std::vector<ObjectId> got_hits, got_batch, got_within;
      for (const ObjectHit& h : collide(scene, query, pose, {.mode = QueryMode::all_pairs}, 2)) {
        got_hits.push_back(h.id);
        shape_hits += scene.object(h.id).shape.has_value();
        for (const TrianglePair& p : h.result.pairs) EXPECT_EQ(p.b, 0u);  // the query shape is B
      }
      for (const ObjectHit& h : batch[i]) got_batch.push_back(h.id);
      for (const ObjectDistance& d : distance_within(scene, query, pose, 0.2)) got_within.push_back(d.id);
      EXPECT_EQ(got_hits, want_hits) << "round " << round << " pose " << i;
      EXPECT_EQ(got_batch, want_hits) << "round " << round << " pose " << i;
      EXPECT_EQ(got_within, want_within) << "round " << round << " pose " << i;
      const auto nearest = distance(scene, query, pose);
      ASSERT_TRUE(nearest.has_value());
      EXPECT_EQ(nearest->id, want_nearest->second);
      EXPECT_EQ(nearest->result.distance, want_nearest->first);
      EXPECT_NEAR((nearest->result.point_a - nearest->result.point_b).norm(), nearest->result.distance, 1e-12);
      hits += static_cast<int>(want_hits.size());
    }
  }
  EXPECT_GT(hits, 5);
  EXPECT_GT(shape_hits, 0);
  Scene scene;
  (void)scene.add(Shape(Sphere(1.0)), Pose{});
  Pose bad;
  bad.translation.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)collide(scene, Shape(Sphere(1.0)), bad), InputError);
  EXPECT_THROW((void)distance(scene, Shape(Box(1.0, 1.0, 1.0)), bad), InputError);
}

TEST(SceneShapes, AddNeedsAModelOrAShape) {
  Scene scene;
  EXPECT_THROW((void)scene.add(SceneObject{}), InputError);
  SceneObject both;
  both.model = make_model(scene_test::tetrahedron());
  both.shape = Sphere(1.0);
  EXPECT_THROW((void)scene.add(both), InputError);
  const ObjectId ball = scene.add(Shape(Sphere(0.5)), at(1, 2, 3), "ball");
  const Aabb box = scene.world_bounds(ball);
  EXPECT_NEAR(box.min.x(), 0.5, 1e-8);
  EXPECT_NEAR(box.max.z(), 3.5, 1e-8);
  EXPECT_EQ(scene.model_count(), 0u);
}

TEST(SceneShapes, SceneFileTakesShapes) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("tightbvh_scene_shapes_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto write = [&](const std::string& text) {
    std::ofstream(dir / "scene.json") << text;
    return dir / "scene.json";
  };
  const std::string pose0 = R"("pose": [1,0,0, 0,1,0, 0,0,1, 0,0,0])";
  const std::string pose1 = R"("pose": [1,0,0, 0,1,0, 0,0,1, 1.4,0,0])";
  const SceneFile f = load_scene_file(write(R"({"models": {}, "objects": [
      {"name": "ball", "shape": "sphere", "radius": 0.5, )" + pose0 + R"(},
      {"name": "crate", "shape": "box", "size": [1, 2, 3], )" + pose1 + R"(},
      {"name": "link", "shape": "capsule", "radius": 0.1, "length": 2, "pose": [1,0,0, 0,1,0, 0,0,1, 0,0,5]}]})"));
  ASSERT_EQ(f.scene.size(), 3u);
  EXPECT_EQ(shape_name(*f.scene.object(*f.scene.find("crate")).shape), std::string("box"));
  const auto hits = collide(f.scene);
  EXPECT_TRUE(hits.empty());  // ball (to x = 0.5) and crate (from x = 0.9): 0.4 apart
  const auto nearest = distance(f.scene);
  ASSERT_TRUE(nearest.has_value());
  EXPECT_NEAR(nearest->result.distance, 0.4, 1e-15);

  const auto error_of = [&](const std::string& objects) -> std::string {
    try {
      (void)load_scene_file(write(R"({"models": {}, "objects": [)" + objects + "]}"));
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(error_of(R"({"name": "a", "shape": "cone", "radius": 1, )" + pose0 + "}").find(
                "objects[0].shape: unknown shape 'cone'"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "shape": "sphere", "radius": -1, )" + pose0 + "}").find("objects[0]: "),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "shape": "sphere", )" + pose0 + "}").find("objects[0]: missing \"radius\""),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "shape": "box", "size": [1, 2], )" + pose0 + "}").find("objects[0].size: three"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "shape": "sphere", "radius": 1, "model": "m", )" + pose0 + "}")
                .find("either \"model\" or \"shape\""),
            std::string::npos);
  // Cylinders and convex hulls, by points or from a mesh file next to the scene file.
  std::ofstream(dir / "tet.off") << "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const SceneFile g = load_scene_file(write(R"({"models": {}, "objects": [
      {"name": "drum", "shape": "cylinder", "radius": 0.5, "length": 2, )" + pose0 + R"(},
      {"name": "cube", "shape": "convex", "points": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,1]],
       "pose": [1,0,0, 0,1,0, 0,0,1, 1,0,0]},
      {"name": "tet", "shape": "convex", "path": "tet.off", "pose": [1,0,0, 0,1,0, 0,0,1, 0,0,3]}]})"));
  ASSERT_EQ(g.scene.size(), 3u);
  const Shape& drum = *g.scene.object(*g.scene.find("drum")).shape;
  ASSERT_TRUE(std::holds_alternative<Cylinder>(drum));
  EXPECT_EQ(std::get<Cylinder>(drum).length, 2.0);
  EXPECT_EQ(std::get<Convex>(*g.scene.object(*g.scene.find("cube")).shape).vertices.size(), 8u);
  EXPECT_EQ(std::get<Convex>(*g.scene.object(*g.scene.find("tet")).shape).faces.size(), 4u);
  const auto g_nearest = distance(g.scene);
  ASSERT_TRUE(g_nearest.has_value());
  EXPECT_NEAR(g_nearest->result.distance, 0.5, 1e-12);  // the drum's side (x = 0.5) to the cube (x = 1)
  EXPECT_NE(error_of(R"({"name": "a", "shape": "cylinder", "radius": 1, )" + pose0 + "}")
                .find("objects[0]: missing \"length\""),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "shape": "convex", )" + pose0 + "}").find("objects[0]: a convex shape has either"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "shape": "convex", "points": [[0,0,0],[1,0,0],[0,1,0]], )" + pose0 + "}")
                .find("objects[0]: Convex: points: a solid hull needs at least 4"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "shape": "convex", "points": [[0,0,0],[1,0]], )" + pose0 + "}")
                .find("objects[0].points[1]: three numbers"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "shape": "convex", "path": "nowhere.off", )" + pose0 + "}").find("objects[0].path: "),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "shape": "cone", "radius": 1, )" + pose0 + "}").find("cylinder, convex)"),
            std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tightbvh
