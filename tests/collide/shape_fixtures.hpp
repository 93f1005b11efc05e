#pragma once
// The shape tests' shared checks (tests/collide/shape_query_test.cpp, shape_convex_test.cpp): the
// test meshes, shape poses around them, how far a point is outside each shape, and every query of
// a shape against brute force over random poses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "query_fixtures.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/point_query.hpp"
#include "tightbvh/shape.hpp"

namespace tightbvh::shape_test {

namespace qt = query_test;

// The test meshes: a decimated shipped mesh, a random soup with degenerate triangles (segments and
// points), a unit cube.
inline std::vector<Mesh> test_meshes() {
  return {qt::subset(qt::shipped("meshes/elephant.off"), 8), qt::random_soup(150, 41), qt::cube()};
}

// Shape poses around the mesh: the shape's center at `gap` times the mesh's bounding radius from
// its center (inside, near the surface, apart), random rotation.
inline std::vector<Pose> shape_poses(const Mesh& mesh, std::uint64_t seed, int count) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n;
  const qt::Sphere s = qt::bounding_sphere(mesh);
  const double gaps[] = {0.0, 0.3, 0.6, 0.8, 0.95, 1.1, 1.4};
  std::vector<Pose> poses;
  for (int i = 0; i < count; ++i) {
    const Vec3 dir = Vec3(n(rng), n(rng), n(rng)).normalized();
    poses.push_back({qt::random_rotation(rng), s.center + gaps[i % 7] * s.radius * dir});
  }
  return poses;
}

inline bool near_relative(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max({1.0, std::abs(a), std::abs(b)}); }

// How far the world point `x` is outside the shape at pose `ps` (negative inside).
inline double outside(const Sphere& s, const Pose& ps, const Vec3& x) { return (x - ps.translation).norm() - s.radius; }
inline double outside(const Capsule& s, const Pose& ps, const Vec3& x) {
  const Vec3 local = ps.inverse().apply(x);
  const double z = std::clamp(local.z(), -0.5 * s.length, 0.5 * s.length);
  return (local - Vec3(0.0, 0.0, z)).norm() - s.radius;
}
inline double outside(const Box& s, const Pose& ps, const Vec3& x) {
  const Vec3 gap = ps.inverse().apply(x).cwiseAbs() - 0.5 * s.size;
  const double out = gap.cwiseMax(0.0).norm();
  return out > 0.0 ? out : gap.maxCoeff();
}
inline double outside(const Cylinder& s, const Pose& ps, const Vec3& x) {
  const Vec3 local = ps.inverse().apply(x);
  const double radial = std::hypot(local.x(), local.y()) - s.radius, axial = std::abs(local.z()) - 0.5 * s.length;
  if (radial <= 0.0 && axial <= 0.0) return std::max(radial, axial);
  return std::hypot(std::max(radial, 0.0), std::max(axial, 0.0));
}
inline double outside(const Convex& s, const Pose& ps, const Vec3& x) {
  const Vec3 local = ps.inverse().apply(x);
  double plane = -std::numeric_limits<double>::infinity(), surface = std::numeric_limits<double>::infinity();
  for (const auto& f : s.faces) {
    const Vec3 &a = s.vertices[f[0]], &b = s.vertices[f[1]], &c = s.vertices[f[2]];
    plane = std::max(plane, (b - a).cross(c - a).normalized().dot(local - a));
    surface = std::min(surface, closest_point_on_triangle(local, a, b, c).distance);
  }
  return plane <= 0.0 ? plane : surface;
}


// What the random poses covered, so that the comparisons are known to include each case.
struct Coverage {
  int touching = 0, within_margin_only = 0, apart = 0;
  std::uint64_t triangles_measured = 0, brute_measured = 0;
};

// Every query of `shape` at `ps` against the mesh (posed by pm) agrees with brute force.
template <class S>
void expect_matches_brute_force(Coverage& coverage, const S& shape, const Pose& ps, const Tree& tree, const Mesh& mesh, const Pose& pm,
                                double margin, double margin_factor, const std::string& where) {
  SCOPED_TRACE(where);
  const QueryOptions all{.mode = QueryMode::all_pairs};
  const ShapeQueryResult hits = collide(shape, ps, tree, mesh, pm, all);
  const ShapeQueryResult brute = collide_brute_force(shape, ps, mesh, pm, all);
  EXPECT_EQ(hits.triangles, brute.triangles);
  EXPECT_EQ(hits.hit, brute.hit);
  const ShapeQueryResult first = collide(shape, ps, tree, mesh, pm);
  EXPECT_EQ(first.hit, brute.hit);
  if (first.hit) {
    ASSERT_EQ(first.triangles.size(), 1u);
    EXPECT_TRUE(std::binary_search(brute.triangles.begin(), brute.triangles.end(), first.triangles[0]));
  }
  const ShapeDistanceResult d = distance(shape, ps, tree, mesh, pm);
  const ShapeDistanceResult bd = distance_brute_force(shape, ps, mesh, pm);
  // Apart: a margin of half, exactly, or 1.5 times the distance (the middle one on the boundary).
  if (bd.distance > 0.0) margin = bd.distance * margin_factor;
  const QueryOptions within{.mode = QueryMode::all_pairs, .margin = margin};
  EXPECT_EQ(collide(shape, ps, tree, mesh, pm, within).triangles,
            collide_brute_force(shape, ps, mesh, pm, within).triangles);
  EXPECT_TRUE(near_relative(d.distance, bd.distance)) << d.distance << " vs " << bd.distance;
  EXPECT_EQ(d.intersecting, brute.hit);
  EXPECT_EQ(d.distance == 0.0, brute.hit);
  EXPECT_FALSE(d.beyond_upper_bound);
  // The reported triangle is at that distance, and the points realise it.
  EXPECT_NEAR((d.point_shape - d.point_mesh).norm(), d.distance, 1e-9 * (1.0 + d.distance));
  const double scale = 1e-9 * (1.0 + ps.translation.norm());
  if (d.intersecting)  // a point of the triangle inside the shape
    EXPECT_LE(outside(shape, ps, d.point_shape), scale);
  else  // on the shape's surface
    EXPECT_NEAR(outside(shape, ps, d.point_shape), 0.0, scale);
  const auto [ta, tb, tc] = mesh.corners(d.triangle);
  EXPECT_LE(closest_point_on_triangle(pm.inverse().apply(d.point_mesh), ta, tb, tc).distance, scale);
  // Margin semantics: a triangle is within the margin iff its distance is.
  const bool any_within = !collide_brute_force(shape, ps, mesh, pm, within).triangles.empty();
  EXPECT_EQ(any_within, bd.distance <= margin);
  coverage.touching += brute.hit ? 1 : 0;
  coverage.within_margin_only += !brute.hit && any_within ? 1 : 0;
  coverage.apart += any_within ? 0 : 1;
  coverage.triangles_measured += d.stats.triangle_pairs;
  coverage.brute_measured += bd.stats.triangle_pairs;
  // upper_bound: below the distance, the query says so; above, the same answer.
  if (d.distance > 0.0) {
    const ShapeDistanceResult cut = distance(shape, ps, tree, mesh, pm, {.upper_bound = 0.5 * d.distance});
    EXPECT_TRUE(cut.beyond_upper_bound);
    EXPECT_EQ(cut.distance, 0.5 * d.distance);
    const ShapeDistanceResult rough = distance(shape, ps, tree, mesh, pm, {.relative_error = 0.1});
    EXPECT_GE(rough.distance, bd.distance);
    EXPECT_LE(rough.distance, 1.1 * bd.distance * (1.0 + 1e-12));
  }
}

template <class MakeShape>
void check_random(MakeShape make, std::uint64_t seed) {
  int mesh_index = 0;
  for (const Mesh& mesh : test_meshes()) {
    const Tree tree = build(mesh);
    const double radius = qt::bounding_sphere(mesh).radius;
    std::mt19937_64 rng(seed + mesh_index);
    std::uniform_real_distribution<double> u(0.05, 0.4);
    int i = 0;
    Coverage coverage;
    for (const Pose& ps : shape_poses(mesh, seed + 17 * mesh_index, 21)) {
      const Pose pm{qt::random_rotation(rng), Vec3(u(rng), -u(rng), u(rng))};
      const Pose world_ps = pm * ps;  // the shape placed relative to the posed mesh
      const auto shape = make(radius * u(rng), radius * u(rng), radius * u(rng));
      expect_matches_brute_force(coverage, shape, world_ps, tree, mesh, pm, 0.05 * radius, 0.5 * (1 + i % 3),
                                 "mesh " + std::to_string(mesh_index) + " pose " + std::to_string(i));
      ++i;
    }
    EXPECT_GT(coverage.touching, 0) << "mesh " << mesh_index;
    EXPECT_GT(coverage.within_margin_only, 0) << "mesh " << mesh_index;
    EXPECT_GT(coverage.apart, 0) << "mesh " << mesh_index;
    // The tree prunes: distance measures far fewer triangles than the brute force.
    if (mesh.triangles.size() > 100) EXPECT_LT(4 * coverage.triangles_measured, coverage.brute_measured) << "mesh " << mesh_index;
    ++mesh_index;
  }
}

}  // namespace tightbvh::shape_test
