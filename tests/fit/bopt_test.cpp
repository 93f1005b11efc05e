// Tests of Bopt's silhouette polygon (src/fit/bopt.cpp): the ordered walk along the hull's
// silhouette cycle must give exactly the polygon of the sorting path (convex_hull_2d of the
// silhouette's projected vertices), or report that it cannot (then bopt() sorts).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "fit/fitters.hpp"
#include "fit/frame.hpp"
#include "geometry/predicates.hpp"
#include "node_sets.hpp"
#include "test_util.hpp"

namespace tightbvh {
namespace {

using fit_detail::HullGeometry;

struct CycleCounts {
  std::size_t directions = 0;
  std::size_t walked = 0;     // directions where silhouette_cycle succeeded
  std::size_t identical = 0;  // ... and gave the sorted polygon point for point
  std::size_t on_adjacency = 0;  // directions on hulls whose cycle is walked on the face adjacency
};

// Directions that meet the degenerate cases: random ones, the coordinate axes and the grid
// directions (faces parallel to v on lattices and CAD parts), the hull's face normals and edge
// directions (faces seen edge on, edges projecting to a point: `special`).
std::vector<Vec3> test_directions(const ConvexHull3& hull, std::uint64_t seed, bool special = true) {
  std::vector<Vec3> out;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 20; ++i) out.emplace_back(normal(rng), normal(rng), normal(rng));
  for (const auto& v : fit_detail::primitive_grid(2)) out.emplace_back(v[0], v[1], v[2]);
  if (!special) return out;
  for (std::size_t f = 0; f < hull.face_normals.size() && f < 40; ++f) out.push_back(hull.face_normals[f]);
  for (std::size_t e = 0; e < hull.edges.size() && e < 40; ++e)
    out.push_back(hull.vertices[hull.edges[e].vertex[1]] - hull.vertices[hull.edges[e].vertex[0]]);
  return out;
}

// Wherever the walk succeeds its polygon is convex and counter-clockwise and gives the sorted
// polygon's minimum-area rectangle (the same area to rounding); usually the same points. They can
// differ where rounding lets a projected vertex of a face seen edge on stick out of the line of
// its neighbours: the sorting path, which also takes such faces' far vertices, then keeps it.
void expect_cycle_matches_sorting(std::span<const Vec3> points, std::uint64_t seed, CycleCounts& counts) {
  const ConvexHull3 hull = convex_hull(points);
  if (hull.dimension != 3) return;
  HullGeometry g;
  g.reset(hull, points[0]);
  fit_detail::BoptScratch walk, sort;
  for (const Vec3& v : test_directions(hull, seed)) {
    const Mat3 frame = fit_detail::frame_from_axis(v);
    const Vec3 a = frame.col(0), u = frame.col(1), w = frame.col(2);
    const std::size_t m = fit_detail::silhouette_sorted(g, a, u, w, sort);
    ++counts.directions;
    counts.on_adjacency += !g.face_adjacent.empty();
    if (!fit_detail::silhouette_cycle(g, a, u, w, walk)) continue;
    ++counts.walked;
    const auto& poly = walk.projected;
    ASSERT_GE(poly.size(), 3u);
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec2& p = poly[i];
      const Vec2& q = poly[(i + 1) % poly.size()];
      const Vec2& r = poly[(i + 2) % poly.size()];
      ASSERT_GT(detail::orient2d(p.x(), p.y(), q.x(), q.y(), r.x(), r.y()), 0) << "not strictly convex at " << i;
    }
    const double walked_area = min_area_rect(poly).area();
    const double sorted_area = min_area_rect(std::span<const Vec2>(sort.projected.data(), m)).area();
    ASSERT_NEAR(walked_area, sorted_area, 1e-9 * sorted_area) << "direction " << v.transpose();
    bool same = poly.size() == m;
    for (std::size_t i = 0; same && i < m; ++i) same = poly[i] == sort.projected[i];
    counts.identical += same;
  }
}

std::vector<std::vector<Vec3>> degenerate_solids() {
  std::vector<std::vector<Vec3>> sets;
  for (int k : {2, 3, 4}) {
    std::vector<Vec3> grid;
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j)
        for (int l = 0; l < k; ++l) grid.emplace_back(0.1 * i, 0.1 * j, 0.1 * l);
    sets.push_back(grid);
  }
  {
    std::vector<Vec3> surface;  // a 5 x 5 grid on every face of a cube
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 5; ++j)
        for (int l = 0; l < 5; ++l)
          if (i % 4 == 0 || j % 4 == 0 || l % 4 == 0) surface.emplace_back(0.3 * i, 0.3 * j, 0.3 * l);
    sets.push_back(surface);
  }
  {
    const std::vector<Vec2> profile{{0, 0}, {2, 0}, {4, 0}, {4, 1}, {3, 2}, {1, 2}, {0, 1}, {2, 1}, {0.5, 0}};
    std::vector<Vec3> extruded;
    for (double y : {0.0, 0.3, 0.6, 1.2})
      for (const Vec2& q : profile) extruded.emplace_back(q.x() * 1.1, y, q.y() * 0.7);
    sets.push_back(extruded);
  }
  {
    std::vector<Vec3> octahedron{{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    sets.push_back(octahedron);
  }
  for (std::uint64_t seed = 1; seed <= 10; ++seed) sets.push_back(test::gaussian_points(4 + 3 * seed, seed));
  test::append_far_copies(sets);
  return sets;
}

TEST(BoptSilhouette, CycleWalkGivesTheSortedPolygonOnDegenerateSets) {
  CycleCounts counts;
  std::uint64_t seed = 1;
  for (const auto& points : degenerate_solids()) expect_cycle_matches_sorting(points, seed++, counts);
  // Faces seen exactly edge on (lattices along grid directions) are classified as back faces,
  // so the walk still succeeds on most of them.
  EXPECT_GT(counts.walked, counts.directions * 8 / 10) << counts.walked << " of " << counts.directions;
  EXPECT_GT(counts.identical, counts.walked * 9 / 10) << counts.identical << " of " << counts.walked;
  std::printf("degenerate sets: %zu directions, %zu walked, %zu identical\n", counts.directions, counts.walked, counts.identical);
}

TEST(BoptSilhouette, CycleWalkGivesTheSortedPolygonOnTreeNodes) {
  CycleCounts counts;
  std::uint64_t seed = 1;
  for (const char* mesh : {"meshes/knot1.off", "meshes/elephant.off"}) {
    const auto nodes = test::node_sets(mesh, 2);
    std::size_t i = 0;
    for (const auto& node : nodes) {
      if (i++ % 7 != 0) continue;  // every 7th node: all sizes, a few seconds
      expect_cycle_matches_sorting(node.vertices, seed++, counts);
    }
  }
  EXPECT_GT(counts.directions, 10000u);
  EXPECT_GT(counts.on_adjacency, 5000u);  // both ways of finding the cycle are compared
  EXPECT_GT(counts.walked, counts.directions * 9 / 10) << counts.walked << " of " << counts.directions;
  EXPECT_GT(counts.identical, counts.walked * 9 / 10) << counts.identical << " of " << counts.walked;
  std::printf("tree nodes: %zu directions, %zu walked, %zu identical\n", counts.directions, counts.walked, counts.identical);
}

// bopt() takes the walk for generic directions (random and grid ones; face normals and edge
// directions, where faces are seen edge on, may fall back to sorting).
TEST(BoptSilhouette, BoptUsesTheWalkForGenericDirections) {
  for (const char* name : {"meshes/knot1.off", "meshes/elephant.off"}) {
    const auto points = test::mesh_vertices(name);
    const ConvexHull3 hull = convex_hull(points);
    HullGeometry g;
    g.reset(hull, points[0]);
    fit_detail::BoptScratch scratch;
    for (const Vec3& v : test_directions(hull, 5, false)) (void)fit_detail::bopt(g, v, scratch);
    EXPECT_EQ(scratch.calls, 69u);
    EXPECT_LE(scratch.sorted_silhouettes, 1u) << name;
  }
}

}  // namespace
}  // namespace tightbvh
