#pragma once
// Small meshes, models and random poses shared by the scene tests.
#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "../collide/query_fixtures.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/pose.hpp"

namespace tightbvh::scene_test {

// A closed tetrahedron, outward triangles.
inline Mesh tetrahedron(double size = 1.0) {
  Mesh m;
  m.vertices = {Vec3(0, 0, 0), size * Vec3(1, 0, 0), size * Vec3(0, 1, 0), size * Vec3(0, 0, 1)};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

// `mesh` moved and scaled so that its bounding box's longest side is `size`, centred at 0.
inline Mesh rescaled(Mesh mesh, double size = 1.0) {
  const Aabb box = bounds_of(mesh.vertices);
  const double scale = size / box.extents().maxCoeff();
  for (Vec3& v : mesh.vertices) v = (v - box.center()) * scale;
  return mesh;
}

// Closed meshes (the solid tests use them): a box, a tetrahedron, a sphere.
inline std::vector<ModelPtr> closed_models() {
  return {make_model(query_test::cube(Vec3(-0.5, -0.4, -0.3), 0.9)), make_model(tetrahedron(1.1)),
          make_model(query_test::uv_sphere(6, 8, 0.5))};
}

// The closed ones plus every k-th triangle of the shipped meshes, rescaled to unit size.
inline std::vector<ModelPtr> mixed_models() {
  std::vector<ModelPtr> models = closed_models();
  models.push_back(make_model(rescaled(query_test::subset(query_test::shipped("meshes/elephant.off"), 40))));
  models.push_back(make_model(rescaled(query_test::subset(query_test::shipped("meshes/knot1.off"), 30))));
  models.push_back(make_model(rescaled(query_test::subset(query_test::shipped("meshes/fandisk.off"), 40))));
  return models;
}

inline Pose random_pose(std::mt19937_64& rng, double extent) {
  std::uniform_real_distribution<double> u(0.0, extent);
  std::normal_distribution<double> n;
  Pose p;
  p.rotation = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
  p.translation = Vec3(u(rng), u(rng), u(rng));
  return p;
}

}  // namespace tightbvh::scene_test
