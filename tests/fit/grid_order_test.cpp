// Tests of the vectorised passes of approx's grid scan (src/fit/grid_search.cpp, grid_order.hpp,
// hull_geometry.cpp) and of Bopt's walk start: each must give what the scalar code gives, bit for
// bit, since the scan's order, its skipped directions and so the trees depend on these values.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <vector>

#include "fit/fitters.hpp"
#include "fit/grid_order.hpp"
#include "fit/workspace.hpp"
#include "node_sets.hpp"
#include "test_util.hpp"

namespace tightbvh {
namespace {

using fit_detail::HullGeometry;

// Small and degenerate sets: random ones of odd and even sizes (the SSE2 and AVX loops take two
// and four at a time), coplanar, collinear, repeated points, and all of them far from the origin.
std::vector<std::vector<Vec3>> small_sets() {
  std::vector<std::vector<Vec3>> sets;
  for (std::uint64_t n = 1; n <= 17; ++n) sets.push_back(test::gaussian_points(n, 100 + n));
  std::vector<Vec3> coplanar, collinear, repeated;
  for (int i = 0; i < 7; ++i) {
    coplanar.emplace_back(0.3 * i, 0.1 * i * i, 0.0);
    collinear.emplace_back(0.5 * i, -0.25 * i, 0.125 * i);
  }
  repeated = test::gaussian_points(5, 7);
  repeated.insert(repeated.end(), repeated.begin(), repeated.end());
  sets.push_back(coplanar);
  sets.push_back(collinear);
  sets.push_back(repeated);
  test::append_far_copies(sets);
  return sets;
}

std::vector<Vec3> directions(std::uint64_t seed, std::size_t count) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<Vec3> out;
  for (const auto& v : fit_detail::primitive_grid(2)) out.emplace_back(v[0], v[1], v[2]);
  while (out.size() < count) out.emplace_back(normal(rng), normal(rng), normal(rng));
  return out;
}

// extent_along (two points per SSE2 instruction) against the plain loop over v . p.
TEST(GridOrder, ExtentAlongIsTheScalarLoopBitForBit) {
  std::size_t compared = 0;
  for (const auto& points : small_sets()) {
    HullGeometry g;
    g.reset_points(points, points[0]);
    for (const Vec3& v : directions(points.size(), 80)) {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const Vec3& p : g.local) lo = std::min(lo, v.dot(p)), hi = std::max(hi, v.dot(p));
      const fit_detail::Extent e = fit_detail::extent_along(g, v);
      EXPECT_EQ(e.lo, lo);
      EXPECT_EQ(e.hi, hi);
      ++compared;
    }
  }
  EXPECT_GT(compared, 3000u);
}

// The ordering pass: projection ranges and cheap bounds over lanes (AVX where the CPU has it,
// else SSE2) against the scalar expressions, on whole lanes of grid and random directions.
TEST(GridOrder, LanesAreTheScalarBoundsBitForBit) {
  constexpr std::size_t kLanes = 52;
  for (const auto& points : small_sets()) {
    if (affine_dimension(points).dimension < 3) continue;  // the fitters' hull-free sets are solid
    HullGeometry g;
    g.reset_points(points, points[0]);
    fit_detail::BoptScratch scratch;
    const fit_detail::VolumeBound bound(g, fit_detail::lemma_box(g, scratch));
    const std::vector<Vec3> dirs = directions(points.size() + 1000, kLanes);
    alignas(32) double dx[kLanes], dy[kLanes], dz[kLanes], lo[kLanes], hi[kLanes], out[kLanes];
    for (std::size_t i = 0; i < kLanes; ++i) {
      dx[i] = dirs[i].x(), dy[i] = dirs[i].y(), dz[i] = dirs[i].z();
      lo[i] = std::numeric_limits<double>::infinity(), hi[i] = -lo[i];
      for (const Vec3& p : g.local) {
        const double d = (dx[i] * p.x() + dy[i] * p.y()) + dz[i] * p.z();
        lo[i] = std::min(lo[i], d), hi[i] = std::max(hi[i], d);
      }
    }
    if (fit_detail::has_avx_grid_order()) {
#ifdef TIGHTBVH_AVX_GRID_ORDER
      alignas(32) double avx_lo[kLanes], avx_hi[kLanes];
      fit_detail::projection_ranges_avx(g.local.front().data(), g.local.size(), dx, dy, dz, avx_lo, avx_hi, kLanes);
      for (std::size_t i = 0; i < kLanes; ++i) {
        EXPECT_EQ(avx_lo[i], lo[i]) << "direction " << i;
        EXPECT_EQ(avx_hi[i], hi[i]) << "direction " << i;
      }
#endif
    }
    bound.cheap_lanes(dx, dy, dz, lo, hi, out, kLanes);  // AVX lanes where the CPU has them
    for (std::size_t i = 0; i < kLanes; ++i) EXPECT_EQ(out[i], bound.cheap(dirs[i], hi[i] - lo[i])) << "direction " << i;
    bound.cheap_lanes(dx, dy, dz, lo, hi, out, kLanes - 2);  // not whole AVX lanes: SSE2
    for (std::size_t i = 0; i + 2 < kLanes; ++i) EXPECT_EQ(out[i], bound.cheap(dirs[i], hi[i] - lo[i])) << "direction " << i;
  }
}

// The scan without the local improvement is Section 6.4's minimum over the grid: the least Bopt
// volume over all primitive directions of Grid(B*(S)) with L-inf norm <= 2 (or B*(S) when that is
// smaller), whatever order the scan takes them in and whatever its bounds skip.
void expect_scan_is_grid_minimum(std::span<const Vec3> points, std::size_t& checked) {
  const ConvexHull3 hull = convex_hull(points);
  if (hull.dimension != 3) return;
  for (const bool with_hull : {true, false}) {
    HullGeometry g;
    if (with_hull) {
      g.reset(hull, points[0]);
    } else {
      g.reset_points(points, points[0]);
    }
    fit_detail::BoptScratch scratch;
    const fit_detail::AxisBox bstar = fit_detail::lemma_box(g, scratch);
    double brute = bstar.volume();
    const Vec3 extent = bstar.hi - bstar.lo;
    for (const auto& c : fit_detail::primitive_grid(2)) {
      Vec3 v = Vec3::Zero();
      for (int j = 0; j < 3; ++j) v += c[j] * (extent[j] * bstar.axes.col(j));
      brute = std::min(brute, fit_detail::bopt(g, v, scratch).volume());
    }
    const double scan = fit_detail::grid_search(g, bstar, 2, false, scratch).volume();
    EXPECT_LE(scan, brute * (1 + 1e-12)) << points.size() << " points, hull " << with_hull;
    EXPECT_GE(scan, brute * (1 - 1e-12)) << points.size() << " points, hull " << with_hull;
    ++checked;
  }
}

TEST(GridOrder, ScanIsTheMinimumOverTheGrid) {
  std::size_t checked = 0;
  for (const auto& points : small_sets()) expect_scan_is_grid_minimum(points, checked);
  std::size_t i = 0;
  for (const auto& node : test::node_sets("meshes/knot1.off", 2)) {
    if (i++ % 13 != 0) continue;
    expect_scan_is_grid_minimum(node.vertices, checked);
  }
  EXPECT_GT(checked, 900u);
}

// Bopt on hull-free sets of <= 6 points takes the rectangle from the pair search
// (min_area_rect_of_points, bopt.cpp's kPairSearchMax): every pair direction gives a rectangle
// containing the projection and one of them is the calipers' hull edge (Freeman & Shapira), so the
// box has Bopt's volume on the hull geometry (silhouette and calipers) up to rounding.
TEST(GridOrder, PairSearchBoptIsTheHullBopt) {
  std::size_t compared = 0;
  for (const auto& points : small_sets()) {
    const ConvexHull3 hull = convex_hull(points);
    if (hull.dimension != 3 || hull.vertices.size() > 6) continue;
    HullGeometry with_hull, without_hull;
    with_hull.reset(hull, points[0]);
    without_hull.reset_points(hull.vertices, points[0]);
    fit_detail::BoptScratch scratch;
    for (const Vec3& v : directions(points.size() + 2000, 120)) {
      const fit_detail::AxisBox a = fit_detail::bopt(without_hull, v, scratch);
      const fit_detail::AxisBox b = fit_detail::bopt(with_hull, v, scratch);
      EXPECT_NEAR(a.volume(), b.volume(), 1e-12 * b.volume()) << points.size() << " points";
      // The box holds every point (local coordinates: the projections lie in [lo, hi]).
      for (const Vec3& p : without_hull.local) {
        const Vec3 q = a.axes.transpose() * p;
        EXPECT_TRUE((q.array() >= a.lo.array() - 1e-12).all() && (q.array() <= a.hi.array() + 1e-12).all());
      }
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000u);
}

// Bopt's silhouette walk starts from where its last climb ended on the same geometry: a node's
// box must not depend on what the workspace fitted before (trees are the same on any number of
// threads). Every fifth node of knot1 (hulls up to hundreds of vertices, walked on the face
// adjacency) fitted alone, then again after all the others in reverse order.
TEST(GridOrder, TreeNodeBoxDoesNotDependOnEarlierFits) {
  const auto all = test::node_sets("meshes/knot1.off", 8);
  std::vector<const test::NodeSet*> nodes;
  for (std::size_t i = 0; i < all.size(); i += 5) nodes.push_back(&all[i]);
  std::vector<Obb> alone;
  for (const auto* node : nodes) {
    FitWorkspace fresh;
    alone.push_back(fit_detail::fit_tree_node_approx(node->corners, node->vertices, {}, fresh));
  }
  FitWorkspace shared;
  std::size_t walked = 0;
  for (std::size_t k = nodes.size(); k-- > 0;) {
    const Obb box = fit_detail::fit_tree_node_approx(nodes[k]->corners, nodes[k]->vertices, {}, shared);
    walked += !shared.scratch().geometry.face_adjacent.empty();
    EXPECT_EQ(box.center, alone[k].center) << "node " << k;
    EXPECT_EQ(box.axes, alone[k].axes) << "node " << k;
    EXPECT_EQ(box.half_extents, alone[k].half_extents) << "node " << k;
  }
  EXPECT_GT(walked, 20u);
}

}  // namespace
}  // namespace tightbvh
