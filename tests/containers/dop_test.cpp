// Tests of the k-DOPs (src/containers/dop.cpp): containment, exact volumes against known
// polytopes and Monte Carlo estimates, redundant slabs, overlap, bad input.
#include "tightbvh/dop.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <vector>

#include "../fit/test_util.hpp"
#include "tightbvh/aabb.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh {
namespace {

constexpr DopKind kinds[] = {DopKind::diamond, DopKind::dop14, DopKind::dop18, DopKind::dop26};

std::vector<Vec3> cube_corners(double half, const Vec3& offset = Vec3::Zero()) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) p.push_back(offset + half * Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  return p;
}
std::vector<Vec3> octahedron(const Vec3& offset = Vec3::Zero()) {
  std::vector<Vec3> p;
  for (int k = 0; k < 3; ++k) p.push_back(offset + Vec3::Unit(k)), p.push_back(offset - Vec3::Unit(k));
  return p;
}
std::vector<Vec3> cuboctahedron(const Vec3& offset = Vec3::Zero()) {
  std::vector<Vec3> p;
  for (int k = 0; k < 3; ++k)
    for (int s = 0; s < 4; ++s) {
      Vec3 q = Vec3::Zero();
      q[(k + 1) % 3] = s & 1 ? 1 : -1;
      q[(k + 2) % 3] = s & 2 ? 1 : -1;
      p.push_back(offset + q);
    }
  return p;
}

double volume_of(const std::vector<Vec3>& p, DopKind kind) { return bounding_dop(p, kind).volume(); }

TEST(Dop, KnownVolumes) {
  for (const Vec3 offset : {Vec3(0, 0, 0), Vec3(1e6, -2e6, 3e6)}) {
    const double tol = offset.isZero() ? 1e-12 : 1e-8;
    SCOPED_TRACE(offset.transpose());
    // Cube [-1/2, 1/2]^3: the diamond is |x|+|y|+|z| <= 3/2 (Sunday's bounding octahedron); every
    // other kind is the cube itself (diamond and edge slabs redundant, through corners / edges).
    const auto cube = cube_corners(0.5, offset);
    EXPECT_NEAR(volume_of(cube, DopKind::diamond), 4.0 / 3.0 * 1.5 * 1.5 * 1.5, 4.5 * tol);
    for (DopKind k : {DopKind::dop14, DopKind::dop18, DopKind::dop26}) EXPECT_NEAR(volume_of(cube, k), 1.0, tol);
    // Octahedron |x|+|y|+|z| <= 1: exact for every kind holding the diamond.
    const auto oct = octahedron(offset);
    for (DopKind k : {DopKind::diamond, DopKind::dop14, DopKind::dop26})
      EXPECT_NEAR(volume_of(oct, k), 4.0 / 3.0, tol);
    // 18-DOP of the octahedron: |x|+|y| <= 1, |x|+|z| <= 1, |y|+|z| <= 1 (x, y, z <= 1 redundant);
    // by symmetry 48 x the part 0 <= z <= y <= x, where x <= 1 - y: volume 48 * 1/24 = 2.
    EXPECT_NEAR(volume_of(oct, DopKind::dop18), 2.0, 2 * tol);
    // Cuboctahedron (Sunday's box + diamond): the cube [-1, 1]^3 without 8 corners of volume 1/6.
    const auto cubo = cuboctahedron(offset);
    EXPECT_NEAR(volume_of(cubo, DopKind::dop14), 20.0 / 3.0, 7 * tol);
    EXPECT_NEAR(volume_of(cubo, DopKind::dop26), 20.0 / 3.0, 7 * tol);
    EXPECT_NEAR(volume_of(cubo, DopKind::dop18), 8.0, 8 * tol);
    EXPECT_NEAR(volume_of(cubo, DopKind::diamond), 4.0 / 3.0 * 8.0, 11 * tol);
  }
}

// A bounding box of the polytope, to sample in.
Aabb sample_box(const Dop& dop) {
  Aabb box;
  if (dop.kind != DopKind::diamond) {
    box.min = Vec3(dop.min[0], dop.min[1], dop.min[2]);
    box.max = Vec3(dop.max[0], dop.max[1], dop.max[2]);
    return box;
  }
  // a = x+y+z, b = x+y-z, c = x-y+z, d = x-y-z: x = (a+d)/2, y = (a-c)/2, z = (a-b)/2.
  const auto& lo = dop.min;
  const auto& hi = dop.max;
  box.min = 0.5 * Vec3(lo[0] + lo[3], lo[0] - hi[2], lo[0] - hi[1]);
  box.max = 0.5 * Vec3(hi[0] + hi[3], hi[0] - lo[2], hi[0] - lo[1]);
  return box;
}

TEST(Dop, VolumeMatchesMonteCarlo) {
  std::mt19937_64 rng(21);
  for (int trial = 0; trial < 3; ++trial) {
    const auto points = test::gaussian_points(25, 100 + trial);
    for (DopKind kind : kinds) {
      const Dop dop = bounding_dop(points, kind);
      const Aabb box = sample_box(dop);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      const int samples = 300000;
      int inside = 0;
      for (int s = 0; s < samples; ++s) {
        const Vec3 q = box.min + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(box.max - box.min);
        inside += dop.contains(q);
      }
      const double estimate = box.volume() * inside / samples;
      EXPECT_NEAR(dop.volume(), estimate, 0.02 * estimate) << "trial " << trial << " kind " << static_cast<int>(kind);
    }
  }
}

TEST(Dop, NestedVolumesAndContainment) {
  int meshes = 0;
  for (const auto& e : std::filesystem::directory_iterator(test::source_dir() / "meshes")) {
    if (e.path().extension() != ".off") continue;
    ++meshes;
    const auto v = load_mesh(e.path()).vertices;
    std::array<double, 4> vol{};
    for (int i = 0; i < 4; ++i) {
      const Dop dop = bounding_dop(v, kinds[i]);
      for (std::size_t j = 0; j < v.size(); ++j) ASSERT_TRUE(dop.contains(v[j])) << e.path() << " vertex " << j;
      vol[i] = dop.volume();
      EXPECT_GT(vol[i], 0.0);
    }
    const double box = bounds_of(v).volume(), eps = 1e-12 * box;
    EXPECT_LE(vol[1], box + eps);      // 14 inside the box
    EXPECT_LE(vol[1], vol[0] + eps);   // 14 inside the diamond
    EXPECT_LE(vol[3], vol[1] + eps);   // 26 inside 14
    EXPECT_LE(vol[3], vol[2] + eps);   // 26 inside 18
    EXPECT_LE(vol[2], box + eps);
  }
  EXPECT_GE(meshes, 1);
}

TEST(Dop, DegenerateSets) {
  // Flat sets have volume 0 exactly when a slab direction is normal to them.
  struct Case {
    std::vector<Vec3> points;
    std::array<bool, 4> flat;  // per kind: diamond, 14, 18, 26
  };
  const std::vector<Case> cases{
      {{Vec3(1, 2, 3)}, {true, true, true, true}},
      {std::vector<Vec3>(5, Vec3(-1, 0, 2)), {true, true, true, true}},
      {{Vec3(0, 0, 0), Vec3(1, 2, 3), Vec3(2, 4, 6), Vec3(0.5, 1, 1.5)}, {true, true, false, true}},  // collinear, normal to (1, 1, -1)
      {{Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0, 1, 1), Vec3(1, 1, 1), Vec3(0.3, 0.2, 1)}, {false, true, true, true}},
      // offset, in a plane with normal (1, 1, -1) (a diamond direction)
      {{Vec3(1e6, 1e6, 1e6), Vec3(1e6 + 1, 1e6, 1e6 + 1), Vec3(1e6, 1e6 + 1, 1e6 + 1)}, {true, true, false, true}}};
  for (const Case& c : cases)
    for (int i = 0; i < 4; ++i) {
      const Dop dop = bounding_dop(c.points, kinds[i]);
      for (const Vec3& p : c.points) EXPECT_TRUE(dop.contains(p));
      const double v = dop.volume();
      EXPECT_TRUE(std::isfinite(v));
      if (c.flat[i])
        EXPECT_NEAR(v, 0.0, 1e-9);
      else
        EXPECT_GE(v, 0.0);
    }
}

TEST(Dop, Overlaps) {
  const auto a = octahedron(), b = octahedron(Vec3(0.9, 0.9, 0.9));
  // The boxes overlap on every axis; the diamond slab x+y+z separates (Sunday's disjointness test).
  const Dop a14 = bounding_dop(a, DopKind::dop14), b14 = bounding_dop(b, DopKind::dop14);
  EXPECT_FALSE(overlaps(a14, b14));
  EXPECT_TRUE(overlaps(a14, a14));
  EXPECT_TRUE(overlaps(bounding_dop(a, DopKind::dop18), bounding_dop(b, DopKind::dop18)));
  EXPECT_TRUE(overlaps(a14, bounding_dop(octahedron(Vec3(0.5, 0.5, 0.5)), DopKind::dop14)));
  EXPECT_THROW((void)overlaps(a14, bounding_dop(b, DopKind::diamond)), InputError);
}

TEST(Dop, Errors) {
  try {
    (void)bounding_dop(std::vector<Vec3>{}, DopKind::dop14);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "dop: empty point set");
  }
  std::vector<Vec3> p(9, Vec3::Zero());
  p[7].z() = std::numeric_limits<double>::quiet_NaN();
  try {
    (void)bounding_dop(p, DopKind::diamond);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "dop: point 7 has a non-finite coordinate (NaN or Inf)");
  }
}

}  // namespace
}  // namespace tightbvh
