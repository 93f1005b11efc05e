// Tests of the convex hulls and rotating calipers (src/geometry/hull.cpp, src/geometry/min_rect.cpp).
// The 3D hull (our Quickhull) is checked exactly: against a brute-force set of extreme points on
// small degenerate sets, and against qhull (bench/oracles/qhull_oracle.cpp) on meshes.
#include "tightbvh/hull.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <new>
#include <random>
#include <set>
#include <string>

#include "geometry/predicates.hpp"
#include "qhull_oracle.hpp"
#include "../fit/test_util.hpp"
#include "tightbvh/fit.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/min_rect.hpp"

// Counts allocations, to check that repeated hulls with a warm workspace allocate nothing. Every
// unaligned form is replaced, so that no block crosses between these and the runtime's (or
// AddressSanitizer's) own new/delete.
namespace {
std::atomic<long> g_allocations{0};
void* counted_allocation(std::size_t size) noexcept {
  ++g_allocations;
  return std::malloc(size == 0 ? 1 : size);
}
}  // namespace
void* operator new(std::size_t size) {
  if (void* p = counted_allocation(size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  if (void* p = counted_allocation(size)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return counted_allocation(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return counted_allocation(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

namespace tightbvh {
namespace {

using Key = std::array<double, 3>;
Key key(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

using detail::collinear;

// Exact checks of a solid hull of `points`: vertices are input points at distinct positions;
// faces are non-degenerate and counter-clockwise seen from outside, every input point is on
// the inner side of (or on) every face plane (exact orient3d <= 0); every directed edge
// appears once and its reverse once (a closed, consistently oriented surface); Euler's
// formula; the edge list and the vertex adjacency match the faces; unit normals, outward,
// equal for exactly coplanar neighbours.
::testing::AssertionResult valid_solid_hull(const ConvexHull3& hull, std::span<const Vec3> points) {
  using ::testing::AssertionFailure;
  if (hull.dimension != 3) return AssertionFailure() << "dimension " << hull.dimension;
  const std::size_t nv = hull.vertices.size(), nf = hull.faces.size();
  const double scale = bounds_of(points).diagonal();
  if (nv < 4 || hull.input_index.size() != nv || hull.face_normals.size() != nf)
    return AssertionFailure() << "sizes: " << nv << " vertices, " << hull.input_index.size() << " indices, " << nf
                              << " faces, " << hull.face_normals.size() << " normals";
  std::set<Key> positions;
  for (std::size_t v = 0; v < nv; ++v) {
    if (hull.input_index[v] >= points.size() || hull.vertices[v] != points[hull.input_index[v]])
      return AssertionFailure() << "vertex " << v << " is not its input point";
    if (!positions.insert(key(hull.vertices[v])).second) return AssertionFailure() << "duplicate vertex " << v;
  }
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  std::vector<int> used(nv, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto& t = hull.faces[f];
    for (std::uint32_t v : t)
      if (v >= nv) return AssertionFailure() << "face " << f << " has a bad vertex";
    const Vec3 &a = hull.vertices[t[0]], &b = hull.vertices[t[1]], &c = hull.vertices[t[2]];
    if (collinear(a, b, c)) return AssertionFailure() << "face " << f << " is degenerate";
    const detail::OrientPlane plane(a, b, c);
    for (std::size_t i = 0; i < points.size(); ++i)
      if (plane.sign(points[i]) > 0) return AssertionFailure() << "point " << i << " is above face " << f;
    for (int k = 0; k < 3; ++k) {
      ++used[t[k]];
      if (++directed[{t[k], t[(k + 1) % 3]}] != 1) return AssertionFailure() << "directed edge twice, face " << f;
    }
    const Vec3& n = hull.face_normals[f];
    if (std::abs(n.norm() - 1.0) > 1e-12) return AssertionFailure() << "normal " << f << " not unit";
    // (The accurate cross product: a sliver face's rounded one can be zero.)
    if (n.dot(detail::accurate_normal(a, b, c)) <= 0.0) return AssertionFailure() << "normal " << f << " points inward";
    for (const Vec3& p : points)
      if (n.dot(p - a) > 1e-9 * scale) return AssertionFailure() << "a point is above normal " << f;
  }
  for (const auto& [e, count] : directed)
    if (directed.count({e.second, e.first}) != 1) return AssertionFailure() << "edge without its reverse";
  for (std::size_t v = 0; v < nv; ++v)
    if (used[v] == 0) return AssertionFailure() << "vertex " << v << " in no face";
  const auto ne = static_cast<long>(hull.edges.size());
  if (2 * ne != 3 * static_cast<long>(nf) || static_cast<long>(nv) - ne + static_cast<long>(nf) != 2)
    return AssertionFailure() << "V - E + F = " << nv << " - " << ne << " + " << nf;
  std::set<std::pair<std::uint32_t, std::uint32_t>> undirected;
  for (const HullEdge& e : hull.edges) {
    if (!undirected.insert(std::minmax(e.vertex[0], e.vertex[1])).second) return AssertionFailure() << "edge twice";
    for (std::uint32_t f : e.face) {
      const auto& t = hull.faces[f];
      if (std::count(t.begin(), t.end(), e.vertex[0]) != 1 || std::count(t.begin(), t.end(), e.vertex[1]) != 1)
        return AssertionFailure() << "edge not on its face";
    }
    const auto& t0 = hull.faces[e.face[0]];
    const auto& t1 = hull.faces[e.face[1]];
    std::uint32_t opposite = t1[0];
    for (std::uint32_t v : t1)
      if (v != e.vertex[0] && v != e.vertex[1]) opposite = v;
    const bool coplanar =
        detail::orient3d(hull.vertices[t0[0]], hull.vertices[t0[1]], hull.vertices[t0[2]], hull.vertices[opposite]) == 0;
    if (coplanar && hull.face_normals[e.face[0]] != hull.face_normals[e.face[1]])
      return AssertionFailure() << "coplanar faces " << e.face[0] << ", " << e.face[1] << " with different normals";
  }
  if (hull.neighbor_offsets.size() != nv + 1 || hull.neighbors.size() != 2 * hull.edges.size())
    return AssertionFailure() << "adjacency sizes";
  for (std::size_t v = 0; v < nv; ++v)
    for (std::uint32_t k = hull.neighbor_offsets[v]; k < hull.neighbor_offsets[v + 1]; ++k)
      if (!undirected.count(std::minmax(static_cast<std::uint32_t>(v), hull.neighbors[k])))
        return AssertionFailure() << "adjacency of " << v << " has a non-edge";
  return ::testing::AssertionSuccess();
}

// The strictly extreme points of a solid set (as positions), by brute force with exact
// predicates: a plane through three non-collinear points with every point weakly on one side
// supports a facet, and every facet is found this way; a point is a vertex of the hull iff no
// other point lies on all the facet planes through it (an interior point has none, a point
// inside a facet or an edge shares them with that facet's or edge's other points).
std::set<Key> brute_force_extreme(std::span<const Vec3> points) {
  std::vector<Vec3> d(points.begin(), points.end());
  std::sort(d.begin(), d.end(), [](const Vec3& a, const Vec3& b) { return key(a) < key(b); });
  d.erase(std::unique(d.begin(), d.end()), d.end());
  const std::size_t m = d.size();
  std::vector<std::array<std::size_t, 3>> facets;
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = i + 1; j < m; ++j)
      for (std::size_t k = j + 1; k < m; ++k) {
        if (collinear(d[i], d[j], d[k])) continue;
        const detail::OrientPlane plane(d[i], d[j], d[k]);
        bool below = true, above = true;
        for (std::size_t q = 0; q < m && (below || above); ++q) {
          const int s = plane.sign(d[q]);
          below = below && s <= 0;
          above = above && s >= 0;
        }
        if (below || above) facets.push_back({i, j, k});
      }
  std::set<Key> extreme;
  for (std::size_t q = 0; q < m; ++q) {
    std::vector<detail::OrientPlane> through;
    for (const auto& t : facets) {
      const detail::OrientPlane plane(d[t[0]], d[t[1]], d[t[2]]);
      if (plane.sign(d[q]) == 0) through.push_back(plane);
    }
    bool vertex = true;
    for (std::size_t r = 0; r < m && vertex; ++r)
      vertex = r == q || std::any_of(through.begin(), through.end(), [&](const auto& p) { return p.sign(d[r]) != 0; });
    if (vertex) extreme.insert(key(d[q]));
  }
  return extreme;
}

std::set<Key> vertex_positions(const ConvexHull3& hull) {
  std::set<Key> out;
  for (const Vec3& v : hull.vertices) out.insert(key(v));
  return out;
}

// The hull is valid and its vertices are exactly the brute-force extreme points.
::testing::AssertionResult exact_hull(std::span<const Vec3> points, HullWorkspace& workspace) {
  ConvexHull3 hull;
  convex_hull(points, hull, workspace);
  if (auto valid = valid_solid_hull(hull, points); !valid) return valid;
  const std::set<Key> expected = brute_force_extreme(points), got = vertex_positions(hull);
  if (got != expected)
    return ::testing::AssertionFailure() << got.size() << " vertices, " << expected.size() << " extreme points";
  return ::testing::AssertionSuccess();
}

void expect_valid_solid_hull(const ConvexHull3& hull, std::span<const Vec3> points) {
  EXPECT_TRUE(valid_solid_hull(hull, points));
}

TEST(Hull3, CubeWithInteriorAndDuplicatePointsAndCoplanarFaces) {
  std::vector<Vec3> points;
  for (int i = 0; i < 8; ++i) points.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  for (int i = 0; i < 8; ++i) points.push_back(points[i]);  // duplicates
  points.emplace_back(0.5, 0.5, 0.5);                         // interior
  points.emplace_back(0.5, 0.5, 1.0);                         // on a face
  points.emplace_back(0.5, 0.0, 0.0);                         // on an edge
  const ConvexHull3 hull = convex_hull(points);
  expect_valid_solid_hull(hull, points);
  EXPECT_EQ(hull.vertices.size(), 8u);
}

TEST(Hull3, RandomSetsAndSphere) {
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const auto points = test::gaussian_points(10 + 50 * seed, seed);
    expect_valid_solid_hull(convex_hull(points), points);
  }
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  std::vector<Vec3> sphere(500);
  for (auto& p : sphere) p = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
  const ConvexHull3 hull = convex_hull(sphere);
  expect_valid_solid_hull(hull, sphere);
  EXPECT_EQ(hull.vertices.size(), 500u);
}

// Meshes whose points mostly lie on flat or ruled hull faces (qhull runs with 'Q8': near-inside
// points are not partitioned, which must not let any point end up outside a face).
TEST(Hull3, CorpusMeshesWithManyCoplanarPoints) {
  for (const char* name : {"meshes/corpus/cgal/blade.off", "meshes/corpus/cgal/cylinder_locally_refined.off",
                           "meshes/corpus/cgal/fandisk_large.off"}) {
    const auto points = test::mesh_vertices(name);
    if (points.empty()) continue;  // corpus not fetched
    expect_valid_solid_hull(convex_hull(points), points);
  }
}

TEST(Hull3, FarFromOrigin) {
  auto points = test::gaussian_points(200, 9);
  for (auto& p : points) p += Vec3(1e6, 2e6, -1e6);
  expect_valid_solid_hull(convex_hull(points), points);
}

// Degenerate solid sets: grids (massive coplanarity and collinearity), lattice points on
// spheres (cospherical, with coplanar subsets), duplicates, many points on the faces and edges
// of a cube, a pyramid and a tilted facet with many points in it, an extruded profile (points on
// lines parallel to an axis, as in extruded CAD shapes), a nearly coplanar slab; each also
// translated far from the origin.
std::vector<std::vector<Vec3>> degenerate_sets() {
  std::vector<std::vector<Vec3>> sets;
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> eighth(1, 7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k : {2, 3, 4}) {
    for (double step : {1.0, 0.1}) {
      std::vector<Vec3> grid;
      for (int i = 0; i < k; ++i)
        for (int j = 0; j < k; ++j)
          for (int l = 0; l < k; ++l) grid.emplace_back(step * i, step * j, step * l);
      sets.push_back(grid);
    }
  }
  for (std::size_t n : {20, 35, 50}) {
    std::vector<Vec3> all;
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 5; ++j)
        for (int l = 0; l < 5; ++l) all.emplace_back(i, j, l);
    std::shuffle(all.begin(), all.end(), rng);
    sets.emplace_back(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n));
  }
  for (int r2 : {25, 50}) {
    std::vector<Vec3> sphere;
    for (int x = -8; x <= 8; ++x)
      for (int y = -8; y <= 8; ++y)
        for (int z = -8; z <= 8; ++z)
          if (x * x + y * y + z * z == r2) sphere.emplace_back(x, y, z);
    sets.push_back(sphere);
  }
  {
    std::normal_distribution<double> normal;
    std::vector<Vec3> sphere(40);
    for (auto& p : sphere) p = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    sets.push_back(sphere);
  }
  {
    auto base = test::gaussian_points(15, 3);
    std::vector<Vec3> copies;
    for (int c = 0; c < 3; ++c) copies.insert(copies.end(), base.begin(), base.end());
    std::shuffle(copies.begin(), copies.end(), rng);
    sets.push_back(copies);
  }
  {
    std::vector<Vec3> cube;
    for (int i = 0; i < 8; ++i) cube.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
    const auto coordinate = [&] { return eighth(rng) / 8.0; };
    for (int i = 0; i < 24; ++i) {  // on faces
      Vec3 p(coordinate(), coordinate(), coordinate());
      p[i % 3] = (i / 3) % 2;
      cube.push_back(p);
    }
    for (int i = 0; i < 12; ++i) {  // on edges
      Vec3 p = Vec3::Constant(coordinate());
      p[i % 3] = i % 2, p[(i + 1) % 3] = (i / 2) % 2;
      cube.push_back(p);
    }
    for (int i = 0; i < 5; ++i) cube.emplace_back(coordinate(), coordinate(), coordinate());
    std::shuffle(cube.begin(), cube.end(), rng);
    sets.push_back(cube);
  }
  {
    // A 5 x 5 grid on every face of a cube, shuffled: most points inside flat facets.
    std::vector<Vec3> surface;
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 5; ++j)
        for (int l = 0; l < 5; ++l)
          if (i % 4 == 0 || j % 4 == 0 || l % 4 == 0) surface.emplace_back(0.3 * i, 0.3 * j, 0.3 * l);
    std::shuffle(surface.begin(), surface.end(), rng);
    sets.push_back(surface);
  }
  {
    std::vector<Vec3> pyramid;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) pyramid.emplace_back(i, j, 0);
    const Vec3 apex(1.5, 1.5, 2.0);
    pyramid.push_back(apex);
    for (const Vec3 corner : {Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(0, 3, 0), Vec3(3, 3, 0)}) {
      pyramid.push_back(0.5 * (corner + apex));  // on the slanted edges
      pyramid.push_back(0.25 * corner + 0.75 * apex);
    }
    sets.push_back(pyramid);
  }
  for (int apexes : {1, 2}) {  // a facet in the tilted plane z = x + 2y
    std::vector<Vec3> tilted;
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 5; ++j) tilted.emplace_back(i, j, i + 2 * j);
    tilted.emplace_back(2.0, 2.0, 10.0);
    if (apexes == 2) tilted.emplace_back(2.0, 2.0, -3.0);
    sets.push_back(tilted);
  }
  {
    // An extruded profile: a polygon in (x, z) with points on its edges, times six heights.
    const std::vector<Vec2> profile{{0, 0}, {2, 0}, {4, 0}, {4, 1}, {3, 2}, {1, 2}, {0, 1}, {2, 1}, {0.5, 0}};
    std::vector<Vec3> extruded;
    for (double y : {0.0, 0.3, 0.6, 1.2, 1.5, 1.7})
      for (const Vec2& q : profile) extruded.emplace_back(q.x() * 1.1, y, q.y() * 0.7);
    sets.push_back(extruded);
  }
  {
    std::vector<Vec3> slab(40);
    for (auto& p : slab) p = Vec3(unit(rng), unit(rng), 1e-9 * unit(rng));
    sets.push_back(slab);
  }
  for (std::uint64_t seed = 1; seed <= 30; ++seed) sets.push_back(test::gaussian_points(3 + seed, seed));
  test::append_far_copies(sets);
  return sets;
}

TEST(Hull3, VerticesAreExactlyTheExtremePointsOfDegenerateSets) {
  HullWorkspace workspace;  // one workspace for all: reuse must not leak state between calls
  const auto sets = degenerate_sets();
  for (std::size_t i = 0; i < sets.size(); ++i) EXPECT_TRUE(exact_hull(sets[i], workspace)) << "set " << i;
}

// A point barely above a face: its exact orientation is positive while the rounded determinant
// is not. It is the face's only outside point, so it must still be picked (and be a vertex).
TEST(Hull3, OutsidePointWithANonPositiveRoundedDeterminant) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.05, 0.3);
  const Vec3 a(0.1, 0.2, 0.3), b(1.3, 0.1, 0.7), c(0.2, 1.1, 0.4);
  const Vec3 below = (a + b + c) / 3.0 - 0.5 * (b - a).cross(c - a);
  const detail::OrientPlane plane(a, b, c);
  int found = 0;
  HullWorkspace workspace;
  for (int trial = 0; trial < 200000 && found < 20; ++trial) {
    const double s = unit(rng), t = unit(rng);
    const Vec3 q = a + s * (b - a) + t * (c - a);
    if (plane.sign(q) <= 0 || plane.normal.dot(q - a) > 0.0) continue;
    ++found;
    const std::vector<Vec3> points{a, b, c, below, q};
    EXPECT_TRUE(exact_hull(points, workspace)) << "trial " << trial;
  }
  EXPECT_GT(found, 0);
}

// Meshes: exactly valid, and the vertices are qhull's ('Qt Q8', the oracle's options) up to
// points that qhull classes as coplanar within its precision. Those must really be extreme: a
// face of the hull of the other points has them strictly above it, with every other point
// weakly below (checked exactly).
TEST(Hull3, VerticesMatchQhullOnMeshes) {
  std::vector<std::string> names{"meshes/camel.off", "meshes/elephant.off", "meshes/fandisk.off", "meshes/knot1.off",
                                 "meshes/knot2.off"};
  for (const char* corpus : {"blade", "cylinder_locally_refined", "fandisk_large", "retinal", "bear_bis", "turbine",
                             "mech-holes-shark", "poly2x^2+y^2-0.062500", "sphere966", "cube-meshed"})
    names.push_back(std::string("meshes/corpus/cgal/") + corpus + ".off");
  HullWorkspace workspace;
  oracle::QhullWorkspace qhull_workspace;
  for (const std::string& name : names) {
    const auto points = test::mesh_vertices(name);
    if (points.empty()) continue;  // corpus not fetched
    SCOPED_TRACE(name);
    ConvexHull3 ours, theirs;
    convex_hull(points, ours, workspace);
    ASSERT_TRUE(valid_solid_hull(ours, points));
    ASSERT_TRUE(oracle::qhull_hull(points, theirs, qhull_workspace));
    const std::set<Key> a = vertex_positions(ours), b = vertex_positions(theirs);
    std::vector<Key> only_ours, only_qhull;
    std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(only_ours));
    std::set_difference(b.begin(), b.end(), a.begin(), a.end(), std::back_inserter(only_qhull));
    // Points qhull keeps but we do not are inside conv(our vertices) (the hull is valid), so not
    // extreme; qhull should not report any.
    EXPECT_TRUE(only_qhull.empty()) << only_qhull.size() << " vertices only in qhull's hull";
    EXPECT_LE(only_ours.size(), a.size() / 20) << "too many differences to be qhull's precision";
    const double scale = bounds_of(points).diagonal();
    double farthest_outside_qhull = -std::numeric_limits<double>::infinity();
    for (const Key& k : only_ours) {
      const Vec3 p(k[0], k[1], k[2]);
      double distance = -std::numeric_limits<double>::infinity();
      for (std::size_t f = 0; f < theirs.faces.size(); ++f)
        distance = std::max(distance, theirs.face_normals[f].dot(p - theirs.vertices[theirs.faces[f][0]]));
      farthest_outside_qhull = std::max(farthest_outside_qhull, distance);
      EXPECT_LE(distance, 1e-12 * scale) << "vertex far outside qhull's hull";
      std::vector<Vec3> others;
      for (const Vec3& q : points)
        if (q != p) others.push_back(q);
      const ConvexHull3 rest = convex_hull(others);
      bool certified = false;
      for (std::size_t f = 0; f < rest.faces.size() && !certified; ++f) {
        const detail::OrientPlane plane(rest.vertices[rest.faces[f][0]], rest.vertices[rest.faces[f][1]],
                                        rest.vertices[rest.faces[f][2]]);
        certified = plane.sign(p) > 0 &&
                    std::all_of(others.begin(), others.end(), [&](const Vec3& q) { return plane.sign(q) <= 0; });
      }
      EXPECT_TRUE(certified) << "vertex not certified extreme";
    }
    if (!only_ours.empty())
      std::printf("%s: %zu vertices, qhull %zu; ours has %zu more, at most %.1e x diagonal outside qhull's hull\n",
                  name.c_str(), a.size(), b.size(), only_ours.size(), farthest_outside_qhull / scale);
  }
}

// Non-finite input: an InputError that names the first bad point, never a crash, a loop or a
// message about something else.
TEST(Hull3, NonFiniteInputIsNamed) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  HullWorkspace workspace;
  ConvexHull3 hull;
  for (const double bad : {nan, inf, -inf}) {
    for (std::size_t at : {0u, 5u, 99u}) {
      for (int coordinate = 0; coordinate < 3; ++coordinate) {
        auto points = test::gaussian_points(100, at + 1);
        points[at][coordinate] = bad;
        try {
          convex_hull(points, hull, workspace);
          ADD_FAILURE() << "no error for a non-finite point " << at;
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("point " + std::to_string(at) + " has a non-finite coordinate"),
                    std::string::npos)
              << e.what();
        }
      }
    }
  }
  auto points = test::gaussian_points(100, 4);
  for (std::size_t i = 3; i < points.size(); i += 7) points[i] = Vec3::Constant(nan);
  EXPECT_THROW(convex_hull(points, hull, workspace), InputError);
}

// Once the workspace and the output have grown, hulls allocate nothing.
TEST(Hull3, NoAllocationWithAWarmWorkspace) {
  const std::vector<std::vector<Vec3>> inputs{test::gaussian_points(2000, 1), degenerate_sets()[6],
                                              test::mesh_vertices("meshes/fandisk.off")};
  HullWorkspace workspace;
  ConvexHull3 hull;
  for (const auto& points : inputs) convex_hull(points, hull, workspace);
  const long before = g_allocations.load();
  for (int round = 0; round < 3; ++round)
    for (const auto& points : inputs) convex_hull(points, hull, workspace);
  EXPECT_EQ(g_allocations.load() - before, 0);
}

// The checks above can fail: broken hulls are rejected.
TEST(Hull3, CheckerRejectsBrokenHulls) {
  const auto points = test::gaussian_points(200, 8);
  const ConvexHull3 good = convex_hull(points);
  ASSERT_TRUE(valid_solid_hull(good, points));
  ConvexHull3 flipped = good;
  std::swap(flipped.faces[3][0], flipped.faces[3][1]);
  EXPECT_FALSE(valid_solid_hull(flipped, points));
  ConvexHull3 moved = good;
  moved.vertices[0] *= 0.9;  // moved off the input point
  EXPECT_FALSE(valid_solid_hull(moved, points));
  std::vector<Vec3> outside = points;
  outside.push_back(good.vertices[0] * 1.5);  // a point the hull does not contain
  EXPECT_FALSE(valid_solid_hull(good, outside));
  ConvexHull3 normals = good;
  normals.face_normals[0] = -normals.face_normals[0];
  EXPECT_FALSE(valid_solid_hull(normals, points));
  // A cube whose faces were each split into two triangles; one extra vertex inside a face makes
  // the vertex set differ from the brute-force extreme points.
  std::vector<Vec3> cube;
  for (int i = 0; i < 8; ++i) cube.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  EXPECT_EQ(brute_force_extreme(cube).size(), 8u);
  cube.emplace_back(0.5, 0.5, 1.0);
  cube.emplace_back(0.5, 0.0, 0.0);
  cube.emplace_back(0.5, 0.5, 0.5);
  EXPECT_EQ(brute_force_extreme(cube).size(), 8u);
  cube.emplace_back(0.5, 0.5, 1.0 + 1e-12);
  EXPECT_EQ(brute_force_extreme(cube).size(), 9u);
}

TEST(Hull3, DegenerateDimensions) {
  EXPECT_EQ(convex_hull(std::vector<Vec3>{{1, 2, 3}, {1, 2, 3}}).dimension, 0);
  const ConvexHull3 line = convex_hull(std::vector<Vec3>{{0, 0, 0}, {2, 2, 2}, {1, 1, 1}, {-1, -1, -1}});
  EXPECT_EQ(line.dimension, 1);
  ASSERT_EQ(line.vertices.size(), 2u);
  EXPECT_NEAR((line.vertices[1] - line.vertices[0]).norm(), std::sqrt(27.0), 1e-12);
  std::vector<Vec3> plane;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uni(-1, 1);
  for (int i = 0; i < 100; ++i) plane.emplace_back(uni(rng), uni(rng), 0.0);
  plane.emplace_back(-2, -2, 0);
  plane.emplace_back(2, -2, 0);
  plane.emplace_back(2, 2, 0);
  plane.emplace_back(-2, 2, 0);
  const ConvexHull3 flat = convex_hull(plane);
  EXPECT_EQ(flat.dimension, 2);
  EXPECT_EQ(flat.vertices.size(), 4u);
  EXPECT_NEAR(std::abs(flat.plane_normal.z()), 1.0, 1e-12);
  EXPECT_THROW((void)convex_hull(std::vector<Vec3>{}), InputError);
}

TEST(Hull2, MonotoneChainDropsCollinearAndDuplicates) {
  std::vector<Vec2> pts{{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {0, 2}, {1, 1}, {0, 0}, {0, 1}};
  const std::size_t n = convex_hull_2d(pts);
  ASSERT_EQ(n, 4u);
  double area = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = pts[i];
    const Vec2& b = pts[(i + 1) % n];
    area += a.x() * b.y() - a.y() * b.x();
  }
  EXPECT_DOUBLE_EQ(area / 2, 4.0);  // counter-clockwise: positive
  std::vector<Vec2> same{{1, 1}, {1, 1}, {1, 1}};
  EXPECT_EQ(convex_hull_2d(same), 1u);
  std::vector<Vec2> line{{0, 0}, {1, 1}, {3, 3}, {2, 2}};
  EXPECT_EQ(convex_hull_2d(line), 2u);
}

// Nearly collinear sets: rounded cross products can keep a point in both the lower and the upper
// chain, which can make a careless chain longer than the input (a heap overflow under ASan).
TEST(Hull2, NearlyCollinearSetsGiveAStrictlyConvexHullOfTheInput) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const double slope = unit(rng) * 3, offset = unit(rng);
    std::vector<Vec2> input(3 + trial % 40);
    for (Vec2& p : input) {
      const double t = unit(rng);
      p = Vec2(t, slope * t + offset);
    }
    std::vector<Vec2> hull = input;
    const std::size_t n = convex_hull_2d(hull);
    ASSERT_LE(n, input.size());
    hull.resize(n);
    if (n < 3) continue;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2& a = hull[i];
      const Vec2& b = hull[(i + 1) % n];
      const Vec2& c = hull[(i + 2) % n];
      ASSERT_GT(detail::orient2d(a.x(), a.y(), b.x(), b.y(), c.x(), c.y()), 0) << "trial " << trial;
      for (const Vec2& p : input) ASSERT_GE(detail::orient2d(a.x(), a.y(), b.x(), b.y(), p.x(), p.y()), 0);
    }
  }
}

// The input that overflowed the 2D hull inside Bopt: two triangles of elephant.off sharing an edge.
TEST(Hull2, ElephantTrianglesThatOverflowedTheChain) {
  const Mesh mesh = load_mesh(std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/elephant.off");
  std::vector<Vec3> corners;
  triangle_corners(mesh, std::vector<std::uint32_t>{3984, 3985}, corners);
  for (const FitMethod method : {FitMethod::diameter, FitMethod::approx, FitMethod::exact}) {
    const Obb box = fit_triangles(corners, {.method = method});
    for (const Vec3& c : corners) EXPECT_TRUE(box.contains(c, containment_tolerance(box))) << to_string(method);
  }
}

TEST(MinRect, RotatedRectangleIsRecovered) {
  for (double angle : {0.0, 0.3, 0.7853981633974483, 1.2, 2.9}) {
    const Eigen::Rotation2Dd r(angle);
    std::vector<Vec2> pts;
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> ux(-3, 3), uy(-1, 1);
    for (int i = 0; i < 200; ++i) pts.push_back(r * Vec2(ux(rng), uy(rng)));
    for (const Vec2 c : {Vec2(-3, -1), Vec2(3, -1), Vec2(3, 1), Vec2(-3, 1)}) pts.push_back(r * c);
    const std::size_t n = convex_hull_2d(pts);
    const Rect2 rect = min_area_rect(std::span<const Vec2>(pts.data(), n));
    EXPECT_NEAR(rect.area(), 12.0, 1e-9) << angle;  // 6 x 2
  }
}

// The least area of the rectangles flush with an edge of the convex polygon `poly`, brute force
// (each edge's rectangle over all vertices, measured from the edge's first vertex).
double least_edge_rect_area(std::span<const Vec2> poly) {
  const std::size_t n = poly.size();
  double least = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 u = (poly[(i + 1) % n] - poly[i]).normalized();
    const Vec2 v(-u.y(), u.x());
    double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
    for (const Vec2& p : poly) {
      a0 = std::min(a0, u.dot(p - poly[i])), a1 = std::max(a1, u.dot(p - poly[i]));
      b0 = std::min(b0, v.dot(p - poly[i])), b1 = std::max(b1, v.dot(p - poly[i]));
    }
    least = std::min(least, (a1 - a0) * (b1 - b0));
  }
  return least;
}

TEST(MinRect, BruteForceOverEdgeDirections) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<Vec2> pts(5 + trial);
    for (auto& p : pts) p = Vec2(normal(rng), 0.3 * normal(rng));
    const std::size_t n = convex_hull_2d(pts);
    const std::span<const Vec2> poly(pts.data(), n);
    const double brute = least_edge_rect_area(poly);
    const Rect2 rect = min_area_rect(poly);
    EXPECT_NEAR(rect.area(), brute, 1e-12 * brute);
    for (const Vec2& p : poly) {
      const Vec2 q(rect.axis.dot(p), -rect.axis.y() * p.x() + rect.axis.x() * p.y());
      EXPECT_TRUE(q.x() >= rect.min.x() - 1e-12 && q.x() <= rect.max.x() + 1e-12);
      EXPECT_TRUE(q.y() >= rect.min.y() - 1e-12 && q.y() <= rect.max.y() + 1e-12);
    }
  }
}

// min_area_rect takes an edge scan in AVX lanes up to kMinAreaRectEdgeScanMax vertices (where the
// CPU has AVX) and the calipers above: on either side of that size, convex polygons of 3 to 80
// vertices (a rotated, squashed circle, near and far from the origin) get the least area over
// their edge directions, brute force, up to rounding, and a rectangle containing every vertex.
TEST(MinRect, EitherSideOfTheEdgeScanSizeMatchesBruteForce) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (std::size_t n = 3; n <= 80; ++n)
    for (const double offset : {0.0, 1e3, 1e6}) {
      const double angle = 6.283185307179586 * uniform(rng), squash = 0.2 + 0.8 * uniform(rng);
      const Eigen::Rotation2Dd r(angle);
      std::vector<Vec2> poly;
      for (std::size_t i = 0; i < n; ++i) {
        const double t = 6.283185307179586 * (static_cast<double>(i) + 0.4 * uniform(rng)) / static_cast<double>(n);
        poly.push_back(r * Vec2(std::cos(t), squash * std::sin(t)) + Vec2(offset, -offset));
      }
      ASSERT_EQ(convex_hull_2d(poly), n);  // still convex and counter-clockwise, nothing dropped
      const double brute = least_edge_rect_area(poly);
      const Rect2 rect = min_area_rect(poly);
      EXPECT_NEAR(rect.area(), brute, (offset == 0.0 ? 1e-12 : 1e-9) * brute) << n << " vertices, offset " << offset;
      for (const Vec2& p : poly) {
        const Vec2 q(rect.axis.dot(p), -rect.axis.y() * p.x() + rect.axis.x() * p.y());
        EXPECT_TRUE(q.x() >= rect.min.x() && q.x() <= rect.max.x()) << n;
        EXPECT_TRUE(q.y() >= rect.min.y() && q.y() <= rect.max.y()) << n;
      }
    }
}

// The first pair direction of least area by the plain loop over the pairs (what
// min_area_rect_of_points computes in SSE2 or AVX lanes), as a unit axis.
Vec2 least_pair_axis(std::span<const Vec2> pts) {
  double best_area = std::numeric_limits<double>::infinity();
  Vec2 best = Vec2::Zero();
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::size_t j = i + 1; j < pts.size(); ++j) {
      const Vec2 e = pts[j] - pts[i];
      const double len2 = e.squaredNorm();
      if (!(len2 > 0.0)) continue;
      const Vec2 v(-e.y(), e.x());
      double u_lo = e.dot(pts[0]), u_hi = u_lo, v_lo = v.dot(pts[0]), v_hi = v_lo;
      for (const Vec2& q : pts.subspan(1)) {
        u_lo = std::min(u_lo, e.dot(q)), u_hi = std::max(u_hi, e.dot(q));
        v_lo = std::min(v_lo, v.dot(q)), v_hi = std::max(v_hi, v.dot(q));
      }
      if (const double area = (u_hi - u_lo) * (v_hi - v_lo) / len2; area < best_area) best_area = area, best = e;
    }
  return best.norm() > 0.0 ? Vec2(best / best.norm()) : Vec2::UnitX();
}

// min_area_rect_of_points (normal-bopt's rectangle for <= 8 projected points, approx's Bopt for
// <= 6, no hull) against the hull and rotating calipers: the same area up to rounding, on random
// sets, sets with repeated points, collinear sets, a single point and integer points (ties); every
// point inside. Its lanes (SSE2, AVX) give the plain pair loop's rectangle bit for bit, also on
// sets far from the origin (where the areas, from absolute projections, are only near the
// calipers').
TEST(MinRect, OfPointsMatchesHullAndCalipers) {
  std::mt19937_64 rng(23);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 700; ++trial) {
    const std::size_t n = 1 + trial % kMinAreaRectOfPointsMax;
    const int kind = trial % 7;
    std::vector<Vec2> pts(n);
    for (auto& p : pts) p = Vec2(normal(rng), 0.3 * normal(rng));
    if (kind == 1 && n > 2) pts[n - 1] = pts[0];                                                 // repeated
    if (kind == 2) for (auto& p : pts) p = Vec2(p.x(), 2.0 * p.x() + 1.0);                       // collinear
    if (kind == 3) for (auto& p : pts) p = pts[0];                                               // one point
    if (kind == 4) for (auto& p : pts) p = Vec2(std::round(4 * p.x()), std::round(4 * p.y()));  // ties
    if (kind == 5) for (auto& p : pts) p += Vec2(1e6, -2e6);                                     // far away
    const Rect2 rect = min_area_rect_of_points(pts);
    const Vec2 axis = least_pair_axis(pts);
    EXPECT_EQ(rect.axis, axis) << "trial " << trial;
    const Vec2 perp(-axis.y(), axis.x());
    Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const Vec2& p : pts) lo = lo.cwiseMin(Vec2(axis.dot(p), perp.dot(p))), hi = hi.cwiseMax(Vec2(axis.dot(p), perp.dot(p)));
    EXPECT_EQ(rect.min, lo) << "trial " << trial;
    EXPECT_EQ(rect.max, hi) << "trial " << trial;
    if (kind != 5) {
      std::vector<Vec2> hull = pts;
      const std::size_t m = convex_hull_2d(hull);
      const Rect2 want = min_area_rect(std::span<const Vec2>(hull.data(), m));
      EXPECT_NEAR(rect.area(), want.area(), 1e-12 * (1.0 + want.area())) << "trial " << trial;
    }
    EXPECT_NEAR(rect.axis.norm(), 1.0, 1e-15);
    for (const Vec2& p : pts) {
      const Vec2 q(rect.axis.dot(p), -rect.axis.y() * p.x() + rect.axis.x() * p.y());
      EXPECT_TRUE(q.x() >= rect.min.x() && q.x() <= rect.max.x()) << "trial " << trial;
      EXPECT_TRUE(q.y() >= rect.min.y() && q.y() <= rect.max.y()) << "trial " << trial;
    }
  }
}

// Every fitter gives a valid box containing the points (fit_points), never an error.
void expect_every_fitter_contains(std::span<const Vec3> points, const std::string& what) {
  for (const char* name : {"aabb", "pca", "pca-vertex", "diameter", "approx", "approx-snap", "exact"}) {
    FitOptions options;
    options.method = *parse_fit_method(name);
    // approx-snap and exact cost seconds on larger thin sets (exact: hull graph walks on slabs).
    if (options.method == FitMethod::approx_snap && points.size() > 16) continue;
    if (options.method == FitMethod::exact && points.size() > 64) continue;
    try {
      EXPECT_TRUE(test::valid_box_containing(fit_points(points, options), points)) << what << ", " << name;
    } catch (const std::exception& e) {
      ADD_FAILURE() << what << ", " << name << ": " << e.what();
    }
  }
}

// The hull agrees with affine_dimension(); a solid one passes the exact checks, and small sets
// have exactly the brute-force extreme points as vertices.
void expect_consistent_hull(std::span<const Vec3> points, HullWorkspace& workspace, const std::string& what) {
  ConvexHull3 hull;
  try {
    convex_hull(points, hull, workspace);
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": " << e.what();
    return;
  }
  EXPECT_EQ(hull.dimension, affine_dimension(points).dimension) << what;
  if (hull.dimension == 3) {
    EXPECT_TRUE(valid_solid_hull(hull, points)) << what;
    if (points.size() <= 40) EXPECT_TRUE(exact_hull(points, workspace)) << what;
  }
}

// Node sets of twice-subdivided shipped meshes on which the hull threw "no solid simplex among
// the extreme points" (tests/geometry/data/sliver_hull_nodes/README.md).
TEST(Hull3, SliverFaceNodesOfSubdividedMeshes) {
  const auto folder = test::source_dir() / "tests/geometry/data/sliver_hull_nodes";
  std::size_t files = 0;
  HullWorkspace workspace;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".xyz") continue;
    ++files;
    std::ifstream in(entry.path());
    std::vector<Vec3> points;
    double x, y, z;
    while (in >> x >> y >> z) points.emplace_back(x, y, z);
    const std::string what = entry.path().filename().string();
    ASSERT_GE(points.size(), 24u) << what;
    expect_consistent_hull(points, workspace, what);
    EXPECT_EQ(affine_dimension(points).dimension, 3) << what;
    expect_every_fitter_contains(points, what);
  }
  EXPECT_EQ(files, 5u);
}

// A point moved off its exact position by `noise` (relative to `scale`) along `normal`; noise
// < 0 means one ulp up or down per coordinate, at random.
Vec3 perturbed(Vec3 p, double noise, double scale, const Vec3& normal, std::mt19937_64& rng) {
  if (noise < 0.0) {
    for (int k = 0; k < 3; ++k) {
      const int step = static_cast<int>(rng() % 3) - 1;
      if (step != 0) p[k] = std::nextafter(p[k], step * std::numeric_limits<double>::infinity());
    }
    return p;
  }
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  return p + unit(rng) * noise * scale * normal;
}

// Points on a random plane and on a random line, exactly (up to the rounding of their
// coordinates) and perturbed by one ulp, 1e-15 and 1e-12 of the scale; planar grids of midpoints
// (a grid subdivided by midpoints, as subdivision does to flat patches). Every set gets a hull
// consistent with its classification, and a valid box from every fitter.
TEST(Hull3, NearDegenerateRandomSetsAndMidpointGrids) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  HullWorkspace workspace;
  const double noises[] = {0.0, -1.0, 1e-15, 1e-12};
  for (int trial = 0; trial < 12; ++trial) {
    const Mat3 frame = test::random_rotation(rng);
    const double scale = std::pow(10.0, unit(rng) * 3);
    const Vec3 offset = Vec3(unit(rng), unit(rng), unit(rng)) * (trial % 3 == 0 ? 1e6 : 1.0);
    const std::size_t n = 4 + static_cast<std::size_t>(trial) * 9;
    for (const double noise : noises) {
      const std::string what = "trial " + std::to_string(trial) + ", noise " + std::to_string(noise);
      std::vector<Vec3> plane, line;
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3 on_plane = offset + scale * (unit(rng) * frame.col(0) + unit(rng) * frame.col(1));
        plane.push_back(perturbed(on_plane, noise, scale, frame.col(2), rng));
        const Vec3 on_line = offset + scale * unit(rng) * frame.col(0);
        line.push_back(perturbed(on_line, noise, scale, unit(rng) > 0 ? frame.col(1) : frame.col(2), rng));
      }
      expect_consistent_hull(plane, workspace, "plane, " + what);
      expect_every_fitter_contains(plane, "plane, " + what);
      expect_consistent_hull(line, workspace, "line, " + what);
      expect_every_fitter_contains(line, "line, " + what);
    }
    // A grid of midpoints: repeated halving of a random triangle's edges.
    std::vector<Vec3> grid{offset + scale * frame.col(0), offset + scale * frame.col(1), offset - scale * frame.col(0)};
    for (int level = 0; level < 3; ++level) {
      const std::size_t m = grid.size();
      for (std::size_t i = 0; i < m; ++i)
        for (std::size_t j = i + 1; j < m; ++j) grid.push_back(0.5 * (grid[i] + grid[j]));
      std::sort(grid.begin(), grid.end(), [](const Vec3& a, const Vec3& b) { return key(a) < key(b); });
      grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
      if (grid.size() > 300) grid.resize(300);
    }
    // A random polytope's triangulated surface subdivided by midpoints three times (its
    // vertices): facets full of points within rounding of their plane, and edge midpoints of
    // midpoints within rounding of their line, as in subdivided meshes.
    std::vector<Vec3> corners;
    for (int i = 0; i < 6 + trial % 5; ++i) corners.push_back(offset + scale * Vec3(unit(rng), unit(rng), unit(rng)));
    const ConvexHull3 polytope = convex_hull(corners);
    Mesh surface;
    surface.vertices = polytope.vertices;
    for (const auto& f : polytope.faces) surface.triangles.push_back(f);
    for (int level = 0; level < 3; ++level) surface = subdivide_midpoints(surface);
    expect_consistent_hull(surface.vertices, workspace, "subdivided polytope, trial " + std::to_string(trial));
    expect_every_fitter_contains(surface.vertices, "subdivided polytope, trial " + std::to_string(trial));
    // With one point lifted off the plane a little: a thin solid whose faces are slivers.
    std::vector<Vec3> lifted = grid;
    lifted.push_back(grid[0] + 1e-9 * scale * frame.col(2));
    for (const auto* set : {&grid, &lifted}) {
      const std::string what = std::string(set == &grid ? "grid" : "lifted grid") + ", trial " + std::to_string(trial);
      expect_consistent_hull(*set, workspace, what);
      expect_every_fitter_contains(*set, what);
    }
  }
}

}  // namespace
}  // namespace tightbvh
