// eberly2015 (src/fit/eberly2015.cpp): Eberly 2015's face-flush and orthogonal-edge-triple
// boxes. Never below exact, never above pca; strictly above exact on the regular tetrahedron.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "fit/fitters.hpp"
#include "test_util.hpp"
#include "tightbvh/hull.hpp"
#include "tightbvh/fit.hpp"

namespace tightbvh {
namespace {

using test::valid_box_containing;

double volume_of(std::span<const Vec3> points, FitMethod m) { return fit_points(points, {.method = m}).volume(); }

// The regular tetrahedron inscribed in the unit sphere (edge length sqrt(8/3)).
std::vector<Vec3> unit_sphere_tetrahedron() {
  return {{0, 0, 1},
          {2 * std::sqrt(2.0) / 3, 0, -1.0 / 3},
          {-std::sqrt(2.0) / 3, std::sqrt(6.0) / 3, -1.0 / 3},
          {-std::sqrt(2.0) / 3, -std::sqrt(6.0) / 3, -1.0 / 3}};
}

TEST(Eberly2015, InTheMethodTable) {
  EXPECT_EQ(parse_fit_method("eberly2015"), FitMethod::eberly2015);
  EXPECT_EQ(to_string(FitMethod::eberly2015), "eberly2015");
  const auto all = all_fit_methods();
  EXPECT_NE(std::find(all.begin(), all.end(), FitMethod::eberly2015), all.end());
  const auto names = fit_method_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "eberly2015"), names.end());
}

TEST(Eberly2015, MissesTheRegularTetrahedronsCube) {
  // The minimum box is the cube whose faces hold the tetrahedron's edges (side sqrt(4/3), volume
  // 8/sqrt(27) for the unit-sphere tetrahedron): no face is flush with a hull face and no three
  // edges are mutually orthogonal (opposite edges are, adjacent ones meet at 60 degrees), so
  // Eberly 2015 (Sections 2-3) cannot find it (Eberly 2024, eq. (1)).
  const double cube = 8.0 / std::sqrt(27.0);
  std::mt19937_64 rng(11);
  for (const double scale : {1.0, 2.5, 1e-3}) {
    const Mat3 r = test::random_rotation(rng);
    std::vector<Vec3> tet;
    for (const Vec3& p : unit_sphere_tetrahedron()) tet.push_back(scale * (r * p) + Vec3(3, -2, 7));
    const double expected = cube * scale * scale * scale;
    const double exact = volume_of(tet, FitMethod::exact);
    const double eberly = volume_of(tet, FitMethod::eberly2015);
    EXPECT_NEAR(exact, expected, 1e-9 * expected) << "scale " << scale;
    EXPECT_GT(eberly, exact * (1 + 1e-3)) << "scale " << scale;
    EXPECT_TRUE(valid_box_containing(fit_points(tet, {.method = FitMethod::eberly2015}), tet));
  }
  // The best face-flush box: a face and its opposite vertex give the height sqrt(16/9) = 4/3
  // and the face triangle (side s = sqrt(8/3)) needs a rectangle s x s sqrt(3)/2: volume
  // 4/3 * (8/3) * sqrt(3)/2 = 16 / (3 sqrt(3)) = 2 * 8/sqrt(27).
  EXPECT_NEAR(volume_of(unit_sphere_tetrahedron(), FitMethod::eberly2015), 2 * cube, 1e-9 * cube);
}

std::vector<Vec3> box_corners(const Vec3& half, const Mat3& r, const Vec3& t) {
  std::vector<Vec3> out;
  for (int i = 0; i < 8; ++i)
    out.push_back(r * Vec3((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(), (i & 4) ? half.z() : -half.z()) + t);
  return out;
}

void expect_between_exact_and_pca(std::span<const Vec3> points, const std::string& what) {
  const Obb box = fit_points(points, {.method = FitMethod::eberly2015});
  EXPECT_TRUE(valid_box_containing(box, points)) << what;
  const double exact = volume_of(points, FitMethod::exact);
  EXPECT_GE(box.volume(), exact * (1 - 1e-9)) << what;
  EXPECT_LE(box.volume(), volume_of(points, FitMethod::pca) * (1 + 1e-9)) << what;
}

TEST(Eberly2015, BetweenExactAndPca) {
  std::mt19937_64 rng(5);
  const Vec3 half(1.5, 0.75, 0.25);
  const auto corners = box_corners(half, Mat3::Identity(), Vec3::Zero());
  EXPECT_NEAR(volume_of(corners, FitMethod::eberly2015), 8 * half.prod(), 1e-12);
  expect_between_exact_and_pca(corners, "box corners");
  const auto rotated = box_corners(half, test::random_rotation(rng), Vec3(1e3, -5, 2));
  EXPECT_NEAR(volume_of(rotated, FitMethod::eberly2015), 8 * half.prod(), 1e-9);
  expect_between_exact_and_pca(rotated, "rotated box");
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    const auto gauss = test::gaussian_points(20 + 15 * seed, seed);
    expect_between_exact_and_pca(gauss, "gaussian " + std::to_string(seed));
    std::uniform_real_distribution<double> u(-1, 1);
    const Mat3 r = test::random_rotation(rng);
    std::vector<Vec3> slab(60);
    for (auto& p : slab) p = r * Vec3(u(rng), 0.3 * u(rng), 0.05 * u(rng));
    expect_between_exact_and_pca(slab, "slab " + std::to_string(seed));
  }
}

// Section 3's candidates, seen through the internal scratch counters.
fit_detail::Eberly2015Scratch internals_of(std::span<const Vec3> points) {
  const ConvexHull3 hull = convex_hull(points);
  fit_detail::HullGeometry g;
  g.reset(hull, points[0]);
  fit_detail::Eberly2015Scratch scratch;
  fit_detail::BoptScratch bopt_scratch;
  (void)fit_detail::eberly2015_box(g, scratch, bopt_scratch);
  return scratch;
}

TEST(Eberly2015, FindsOrthogonalEdgeTriples) {
  // A box with its 8 corners cut off by small triangles: 6 octagons + 8 triangles = 14 face
  // directions; the shortened box edges give the one triple of mutually orthogonal directions
  // (with equal cuts c the triangle edges (0, c, +-c) and x would make three more).
  std::vector<Vec3> points;
  const Vec3 half(2, 1, 0.5);
  const Vec3 c(0.1, 0.15, 0.2);
  for (int i = 0; i < 8; ++i) {
    const Vec3 s((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    const Vec3 corner = s.cwiseProduct(half);
    for (int k = 0; k < 3; ++k) {
      Vec3 p = corner;
      p[k] -= s[k] * c[k];
      points.push_back(p);
    }
  }
  const auto cut = internals_of(points);
  EXPECT_EQ(cut.face_directions, 14u);
  EXPECT_EQ(cut.edge_triples, 1u);
  const auto tet = internals_of(unit_sphere_tetrahedron());
  EXPECT_EQ(tet.face_directions, 4u);
  EXPECT_EQ(tet.edge_triples, 0u);
  std::mt19937_64 rng(9);
  const Mat3 r = test::random_rotation(rng);
  for (auto& p : points) p = r * p;
  EXPECT_NEAR(volume_of(points, FitMethod::eberly2015), 8 * half.prod(), 1e-9);
  expect_between_exact_and_pca(points, "cut box");
}

TEST(Eberly2015, ShippedMeshNotBelowExact) {
  const auto points = test::mesh_vertices("meshes/fandisk.off");
  ASSERT_FALSE(points.empty());
  expect_between_exact_and_pca(points, "fandisk");
}

TEST(Eberly2015, DegenerateSets) {
  const std::vector<std::vector<Vec3>> sets{
      {{1, 2, 3}},
      {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}},
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.2, 0}},
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (const auto& s : sets) {
    const Obb box = fit_points(s, {.method = FitMethod::eberly2015});
    EXPECT_TRUE(valid_box_containing(box, s));
    EXPECT_GE(box.volume(), volume_of(s, FitMethod::exact) * (1 - 1e-9));
  }
}

}  // namespace
}  // namespace tightbvh
