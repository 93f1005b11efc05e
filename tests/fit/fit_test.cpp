// Properties of every fitter (src/fit/*.cpp): containment, ordering against the exact box,
// invariance, known optima, degenerate inputs, and exact vs a dense random search.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <thread>

#include "test_util.hpp"
#include "tightbvh/hull.hpp"

namespace tightbvh {
namespace {

using test::valid_box_containing;

const FitMethod kAll[] = {FitMethod::aabb,   FitMethod::pca,         FitMethod::pca_vertex, FitMethod::diameter,
                          FitMethod::approx, FitMethod::approx_snap, FitMethod::exact,
                          FitMethod::eberly2015, FitMethod::approx_kernel, FitMethod::normal_bopt, FitMethod::dito};

double volume_of(std::span<const Vec3> points, FitMethod m, const FitOptions& base = {}) {
  FitOptions o = base;
  o.method = m;
  return fit_points(points, o).volume();
}

std::vector<Vec3> uniform_cube(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> p(n);
  for (auto& x : p) x = Vec3(u(rng), 0.6 * u(rng), 0.3 * u(rng));
  return p;
}

std::vector<Vec3> sphere_points(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::vector<Vec3> p(n);
  for (auto& x : p) x = Vec3(g(rng), g(rng), g(rng)).normalized();
  return p;
}

// A few sets of every kind: Gaussian, uniform in a box, on a sphere, rotated.
std::vector<std::vector<Vec3>> random_sets() {
  std::vector<std::vector<Vec3>> sets;
  std::mt19937_64 rng(99);
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    sets.push_back(test::gaussian_points(8 + 20 * seed, seed));
    auto cube = uniform_cube(10 + 30 * seed, 100 + seed);
    const Mat3 r = test::random_rotation(rng);
    for (auto& p : cube) p = r * p;
    sets.push_back(cube);
  }
  sets.push_back(sphere_points(100, 7));
  return sets;
}

std::vector<std::vector<Vec3>> mesh_sets() {
  std::vector<std::vector<Vec3>> sets;
  for (const char* name : {"meshes/elephant.off", "meshes/knot1.off", "meshes/corpus/cgal/fandisk.off",
                           "meshes/corpus/cgal/tetrahedron.off", "meshes/corpus/cgal/star.off",
                           "meshes/corpus/cgal/icosahedron.off"}) {
    auto v = test::mesh_vertices(name);
    if (!v.empty()) sets.push_back(std::move(v));
  }
  return sets;
}

TEST(Fit, EveryFitterContainsRandomAndMeshPoints) {
  auto sets = random_sets();
  for (auto& m : mesh_sets()) sets.push_back(std::move(m));
  ASSERT_GE(sets.size(), 15u);
  FitWorkspace ws;
  for (std::size_t i = 0; i < sets.size(); ++i)
    for (FitMethod m : kAll) {
      const Obb box = fit_points(sets[i], {.method = m}, ws);
      EXPECT_TRUE(valid_box_containing(box, sets[i])) << to_string(m) << " set " << i;
      EXPECT_GT(box.volume(), 0.0);
    }
}

TEST(Fit, ExactIsSmallestAndApproxWithinEpsilon) {
  auto sets = random_sets();
  for (auto& m : mesh_sets()) sets.push_back(std::move(m));
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const auto& s = sets[i];
    const double exact = volume_of(s, FitMethod::exact);
    const double tight = 1.0 + 1e-9;
    for (FitMethod m : kAll) EXPECT_LE(exact, volume_of(s, m) * tight) << to_string(m) << " set " << i;
    for (const double eps : {0.1, 0.02}) {
      const double approx = volume_of(s, FitMethod::approx, {.epsilon = eps});
      EXPECT_LE(exact, approx * tight) << "set " << i;
      EXPECT_LE(approx, (1.0 + eps) * exact) << "set " << i << " eps " << eps;
    }
  }
}

TEST(Fit, VolumeInvariantUnderRotationAndTranslation) {
  std::mt19937_64 rng(2024);
  auto sets = random_sets();
  sets.resize(6);
  sets.push_back(test::mesh_vertices("meshes/elephant.off"));
  for (const auto& s : sets) {
    const double exact = volume_of(s, FitMethod::exact);
    const double approx = volume_of(s, FitMethod::approx);
    for (const double shift : {0.0, 1.0, 1e6}) {
      const Mat3 r = test::random_rotation(rng);
      const Vec3 t = shift * Vec3(1.0, -0.7, 0.3);
      std::vector<Vec3> moved(s.size());
      for (std::size_t i = 0; i < s.size(); ++i) moved[i] = r * s[i] + t;
      const double e2 = volume_of(moved, FitMethod::exact);
      EXPECT_NEAR(e2, exact, 1e-7 * exact) << "shift " << shift;
      // approx depends on B*(S), whose approximate diameter is not rotation invariant, but it
      // stays within its guarantee of the (invariant) optimum.
      const double a2 = volume_of(moved, FitMethod::approx);
      EXPECT_LE(a2, 1.05 * exact);
      EXPECT_LE(approx, 1.05 * exact);
      for (FitMethod m : kAll) {
        const Obb box = fit_points(moved, {.method = m});
        EXPECT_TRUE(valid_box_containing(box, moved)) << to_string(m) << " shift " << shift;
      }
    }
  }
}

TEST(Fit, RegularTetrahedronInUnitSphere) {
  // Eberly 2024, eq. (1): the minimum box is a cube with three faces flush with the three
  // edges at a vertex (no face flush with a hull face), volume 8 / sqrt(27).
  const std::vector<Vec3> tet{{0, 0, 1},
                              {2 * std::sqrt(2.0) / 3, 0, -1.0 / 3},
                              {-std::sqrt(2.0) / 3, std::sqrt(6.0) / 3, -1.0 / 3},
                              {-std::sqrt(2.0) / 3, -std::sqrt(6.0) / 3, -1.0 / 3}};
  const double expected = 8.0 / std::sqrt(27.0);
  EXPECT_NEAR(volume_of(tet, FitMethod::exact), expected, 1e-9 * expected);
  // Face-flush boxes (what Eberly 2015 finds) are strictly larger.
  std::mt19937_64 rng(4);
  const Mat3 r = test::random_rotation(rng);
  std::vector<Vec3> rotated;
  for (const Vec3& p : tet) rotated.push_back(r * p + Vec3(3, -2, 1e6));
  EXPECT_NEAR(volume_of(rotated, FitMethod::exact), expected, 1e-7 * expected);
  EXPECT_LE(volume_of(tet, FitMethod::approx, {.epsilon = 0.01}), 1.01 * expected);
}

TEST(Fit, Section65FourPointSet) {
  // Barequet & Har-Peled Table 6.1: the optimum 0.03995 for
  // S = {(-1,-0.1,0), (-1,0.1,0), (1,0,-0.1), (1,0,0.1)}. The true optimum is 0.04 exactly
  // (length 2 along x times the 0.02 square of the projected cross rotated by 45 degrees;
  // our dense random search agrees), which is 0.03995 to the table's three significant digits.
  const std::vector<Vec3> s{{-1, -0.1, 0}, {-1, 0.1, 0}, {1, 0, -0.1}, {1, 0, 0.1}};
  EXPECT_NEAR(volume_of(s, FitMethod::exact), 0.03995, 0.0001);
  EXPECT_NEAR(volume_of(s, FitMethod::exact), 0.04, 1e-12);
  EXPECT_NEAR(volume_of(s, FitMethod::approx), 0.03995, 0.0001);
  EXPECT_NEAR(volume_of(s, FitMethod::approx, {.grid = 2}), 0.04, 1e-12);  // the B*(S)-G(2) row
  // The B*(S) row (0.07980): the minimum box aligned with a diameter. All four diameters
  // (|AC| = |AD| = |BC| = |BD|) give exactly 0.08 here (2.005 times the 0.0399 rectangle of the
  // projected right triangle); 0.0798 is 0.25% lower, which we cannot reproduce.
  EXPECT_NEAR(volume_of(s, FitMethod::diameter), 0.07980, 0.0003);
}

// Volume of the AABB of the points in the frame r (columns = axes).
double frame_volume(std::span<const Vec3> points, const Mat3& r) {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Vec3& p : points) {
    const Vec3 q = r.transpose() * p;
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  return (hi - lo).prod();
}

// Dense random search over rotations with a shrinking random local refinement.
double random_search(std::span<const Vec3> points, std::mt19937_64& rng) {
  double best = std::numeric_limits<double>::infinity();
  std::vector<std::pair<double, Mat3>> seeds;
  for (int i = 0; i < 4000; ++i) {
    const Mat3 r = test::random_rotation(rng);
    seeds.emplace_back(frame_volume(points, r), r);
  }
  std::sort(seeds.begin(), seeds.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::normal_distribution<double> g;
  for (int s = 0; s < 8; ++s) {
    auto [v, r] = seeds[s];
    for (double step = 0.05; step > 1e-9; step *= 0.7)
      for (int k = 0; k < 40; ++k) {
        const Vec3 w(g(rng), g(rng), g(rng));
        const Mat3 c = Eigen::AngleAxisd(step * w.norm(), w.normalized()).toRotationMatrix() * r;
        const double cv = frame_volume(points, c);
        if (cv < v) v = cv, r = c;
      }
    best = std::min(best, v);
  }
  return best;
}

TEST(Fit, ExactNeverBeatenByRandomRotationSearch) {
  std::mt19937_64 rng(31337);
  for (int trial = 0; trial < 24; ++trial) {
    const std::size_t n = 8 + static_cast<std::size_t>(trial);
    auto points = trial % 3 == 0 ? sphere_points(n, 500 + trial)
                                 : (trial % 3 == 1 ? uniform_cube(n, 600 + trial) : test::gaussian_points(n, 700 + trial));
    const double exact = volume_of(points, FitMethod::exact);
    const double searched = random_search(points, rng);
    EXPECT_LE(exact, searched * (1.0 + 1e-9)) << "trial " << trial << " n " << n;
  }
}

TEST(Fit, BoxCornersGiveTheBoxItself) {
  std::mt19937_64 rng(8);
  for (int trial = 0; trial < 5; ++trial) {
    const Obb box{Vec3(trial, -2.0 * trial, 0.5), test::random_rotation(rng), Vec3(1.0 + trial, 0.5, 0.25 + 0.1 * trial)};
    const auto corners = box.corners();
    const std::span<const Vec3> c(corners.data(), corners.size());
    const double v = box.volume();
    EXPECT_NEAR(volume_of(c, FitMethod::exact), v, 1e-9 * v);
    EXPECT_NEAR(volume_of(c, FitMethod::pca_vertex), v, 1e-9 * v);
    EXPECT_LE(volume_of(c, FitMethod::approx), (1.0 + 1e-3) * v);
    for (FitMethod m : kAll) EXPECT_TRUE(valid_box_containing(fit_points(c, {.method = m}), c));
  }
}

TEST(Fit, DegenerateInputsGiveZeroVolumeBoxes) {
  std::mt19937_64 rng(12);
  const Mat3 r = test::random_rotation(rng);
  std::vector<std::vector<Vec3>> sets;
  sets.push_back({{1, 2, 3}});
  sets.push_back({{1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}});
  sets.push_back({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {0.5, 0.5, 0.5}, {2, 2, 2}});
  std::vector<Vec3> plane;
  for (int i = 0; i < 50; ++i) plane.push_back(r * Vec3(std::cos(i), 2 * std::sin(i * 1.3), 0) + Vec3(5, 5, 5));
  sets.push_back(plane);
  std::vector<Vec3> far_line;
  for (int i = 0; i < 20; ++i) far_line.push_back(r * Vec3(i * 0.1, 0, 0) + Vec3(1e6, 1e6, 1e6));
  sets.push_back(far_line);
  for (const auto& s : sets)
    for (FitMethod m : kAll) {
      if (m == FitMethod::aabb) continue;  // an AABB of a slanted segment is a genuine box
      const Obb box = fit_points(s, {.method = m});
      EXPECT_TRUE(valid_box_containing(box, s)) << to_string(m);
      EXPECT_LE(box.volume(), 1e-9 * std::max(1.0, std::pow(box.half_extents.maxCoeff(), 3))) << to_string(m);
    }
  // The planar set: the rectangle in the plane is the minimum-area one (compare with exact
  // search of rectangles: the 2D hull's calipers), so every hull method agrees on it.
  const Obb exact = fit_points(plane, {.method = FitMethod::exact});
  const Obb approx = fit_points(plane, {.method = FitMethod::approx});
  const auto area = [](const Obb& b) {
    Vec3 h = b.half_extents;
    std::sort(h.data(), h.data() + 3);
    return 4 * h[1] * h[2];
  };
  EXPECT_NEAR(area(exact), area(approx), 1e-9 * area(exact));
}

TEST(Fit, NearlyDegenerateAndLatticeInputs) {
  // A lattice (many coplanar and collinear points, exact ties everywhere), a slab 1e-9 thick,
  // and a needle: every hull method must stay valid and ordered.
  std::vector<std::vector<Vec3>> sets;
  std::vector<Vec3> lattice;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 3; ++k) lattice.emplace_back(i, 0.5 * j, 0.25 * k);
  sets.push_back(lattice);
  std::mt19937_64 rng(77);
  const Mat3 r = test::random_rotation(rng);
  auto slab = uniform_cube(200, 5);
  for (auto& p : slab) p = r * Vec3(p.x(), p.y(), 1e-9 * p.z());
  sets.push_back(slab);
  auto needle = uniform_cube(100, 6);
  for (auto& p : needle) p = r * Vec3(p.x(), 1e-4 * p.y(), 1e-4 * p.z());
  sets.push_back(needle);
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const double exact = volume_of(sets[i], FitMethod::exact);
    for (FitMethod m : kAll) {
      const Obb box = fit_points(sets[i], {.method = m});
      EXPECT_TRUE(valid_box_containing(box, sets[i])) << to_string(m) << " set " << i;
      EXPECT_LE(exact, box.volume() * (1 + 1e-6) + 1e-300) << to_string(m) << " set " << i;
    }
  }
  EXPECT_NEAR(volume_of(lattice, FitMethod::exact), 4.0 * 1.5 * 0.5, 1e-12);
}

TEST(Fit, ConcurrentWorkspacesGiveTheSameBoxes) {
  // The builder fits nodes in parallel, one workspace per thread (no shared state in the fitters).
  auto sets = random_sets();
  std::vector<std::vector<double>> expected(sets.size());
  for (std::size_t i = 0; i < sets.size(); ++i)
    for (FitMethod m : {FitMethod::diameter, FitMethod::approx, FitMethod::exact})
      expected[i].push_back(volume_of(sets[i], m));
  std::vector<int> mismatches(4, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      FitWorkspace ws;
      for (std::size_t i = 0; i < sets.size(); ++i) {
        int k = 0;
        for (FitMethod m : {FitMethod::diameter, FitMethod::approx, FitMethod::exact})
          mismatches[t] += fit_points(sets[i], {.method = m}, ws).volume() != expected[i][k++];
      }
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(mismatches[t], 0) << "thread " << t;
}

TEST(Fit, RejectsNonFinite) {
  for (FitMethod m : kAll) {
    std::vector<Vec3> points = test::gaussian_points(20, 1);
    points[7].z() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW((void)fit_points(points, {.method = m}), InputError) << to_string(m);
    points[7].z() = -std::numeric_limits<double>::infinity();
    EXPECT_THROW((void)fit_points(points, {.method = m}), InputError) << to_string(m);
  }
  EXPECT_THROW((void)grid_for_epsilon(0.0), InputError);
  EXPECT_THROW((void)grid_for_epsilon(std::numeric_limits<double>::quiet_NaN()), InputError);
}

// Sets of at most 32 distinct points skip the 3D hull in approx and diameter (Bopt projects every
// point, src/fit/fit.cpp kSmallSet). The same set repeated to more than 128 input points takes
// the hull path: both must give the same box volume, contain the points, and approx must stay
// within (1 + eps) of exact. Also tiny tree-node-like sets: a few triangles of a mesh, with
// repeated corners, far from the origin; and nearly flat small sets (these keep the hull path).
TEST(Fit, SmallSetsWithoutHullMatchTheHullPath) {
  std::mt19937_64 rng(31);
  std::vector<std::vector<Vec3>> sets;
  for (std::size_t n : {4, 5, 6, 8, 12, 17, 24, 32}) {
    sets.push_back(test::gaussian_points(n, 100 + n));
    auto cube = uniform_cube(n, 200 + n);
    const Mat3 r = test::random_rotation(rng);
    for (auto& p : cube) p = r * p + Vec3(1e5, -2e5, 3e5);
    sets.push_back(cube);
  }
  sets.push_back({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}});  // regular tetrahedron
  const auto corners = test::mesh_corners("meshes/elephant.off");
  ASSERT_FALSE(corners.empty());
  for (std::size_t first : {0, 300, 3000, 9000})
    for (std::size_t triangles : {2, 3, 5, 10})
      sets.emplace_back(corners.begin() + static_cast<std::ptrdiff_t>(first),
                        corners.begin() + static_cast<std::ptrdiff_t>(first + 3 * triangles));
  auto flat = uniform_cube(20, 9);
  for (auto& p : flat) p.z() *= 1e-9;
  sets.push_back(flat);
  FitWorkspace ws;
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const auto& s = sets[i];
    std::vector<Vec3> repeated;
    while (repeated.size() <= 128) repeated.insert(repeated.end(), s.begin(), s.end());
    const double exact = volume_of(s, FitMethod::exact);
    for (FitMethod m : {FitMethod::approx, FitMethod::diameter}) {
      const Obb small = fit_points(s, {.method = m}, ws);
      EXPECT_TRUE(valid_box_containing(small, s)) << to_string(m) << " set " << i;
      const Obb hull = fit_points(repeated, {.method = m}, ws);
      EXPECT_NEAR(small.volume(), hull.volume(), 1e-9 * hull.volume() + 1e-300) << to_string(m) << " set " << i;
      EXPECT_LE(exact, small.volume() * (1 + 1e-9) + 1e-300) << to_string(m) << " set " << i;
    }
    for (const double eps : {0.1, 0.02})
      EXPECT_LE(volume_of(s, FitMethod::approx, {.epsilon = eps}), (1.0 + eps) * exact + 1e-300)
          << "set " << i << " eps " << eps;
    if (s.size() % 3 == 0)
      EXPECT_TRUE(valid_box_containing(fit_triangles(s, {.method = FitMethod::approx}, ws), s)) << "set " << i;
  }
}

// Corpus meshes where the axis improvement of Section 6.5 alone stops on a ridge 2% above the
// optimum (with k = 2: bull 1.025, 3torus 1.021); the tilt search of the best direction must
// reach within 0.5% of the exact box.
TEST(Fit, ApproxEscapesImprovementRidgesOnCorpusMeshes) {
  int checked = 0;
  for (const char* name : {"meshes/corpus/cgal/bull.off", "meshes/corpus/cgal/3torus.off"}) {
    const auto points = test::mesh_vertices(name);
    if (points.empty()) continue;  // corpus not fetched
    ++checked;
    const double exact = volume_of(points, FitMethod::exact);
    EXPECT_LE(volume_of(points, FitMethod::approx), 1.005 * exact) << name;
    EXPECT_GE(volume_of(points, FitMethod::approx), exact * (1 - 1e-9)) << name;
  }
  if (checked == 0) GTEST_SKIP() << "corpus not fetched (meshes/fetch-corpus)";
}

TEST(Fit, ApproxImprovesWithGridRadius) {
  const auto points = sphere_points(100, 3);
  const double exact = volume_of(points, FitMethod::exact);
  double previous = std::numeric_limits<double>::infinity();
  for (int k : {1, 2, 4, 8}) {
    const double v = volume_of(points, FitMethod::approx, {.grid = k, .improve = false});
    EXPECT_GE(v, exact * (1 - 1e-9));
    // Grids nest (G(k) within G(2k)), so doubling k never loses.
    if (k > 1 && (k & (k - 1)) == 0) EXPECT_LE(v, previous * (1 + 1e-12));
    previous = v;
  }
}

}  // namespace
}  // namespace tightbvh
