// Tree-vs-tree minimum distance: PQP's descent (Larsen, Gottschalk, Lin & Manocha 2000, "Fast
// distance queries with rectangular swept sphere volumes") on our boxes, with the separating-axis
// lower bound of obb_distance.hpp. See include/tightbvh/distance.hpp.
#include "tightbvh/distance.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>

#include "batch.hpp"
#include "query_common.hpp"
#include "query_workspace.hpp"
#include "solid.hpp"
#include "tightbvh/obb_distance.hpp"
#include "tightbvh/tri_distance.hpp"
#include "traverse.hpp"

namespace tightbvh {
namespace {

using query_detail::BoundedPair;
using query_detail::map_point;

// The best triangle pair so far, in A's frame.
struct Best {
  double distance = std::numeric_limits<double>::infinity();
  bool found = false;
  TrianglePair pair;
  Vec3 point_a = Vec3::Zero();  // on A's triangle, A's frame
  Vec3 point_b = Vec3::Zero();  // on B's mapped triangle, A's frame
};

// One distance query: the descent state and its three steps (node bound, leaf pair, walk).
class DistanceSearch {
 public:
  DistanceSearch(const Tree& ta, const Mesh& ma, const Tree& tb, const Mesh& mb, const Pose& rel,
                 const DistanceOptions& options, QueryWorkspace::Scratch& ws)
      : ta_(ta), ma_(ma), tb_(tb), mb_(mb), rel_(rel), options_(options), ws_(ws) {
    margin_ = query_detail::box_allowance(ta, tb, rel);
  }

  void run() {
    ws_.mapped_b.begin(tb_.nodes.size());
    std::vector<BoundedPair>& stack = ws_.distance_stack;
    stack.clear();
    stack.push_back({0, 0, lower_bound(0, 0)});
    while (!stack.empty()) {
      const BoundedPair np = stack.back();
      stack.pop_back();
      if (prunable(np.bound)) continue;
      const Node& na = ta_.nodes[np.a];
      const Node& nb = tb_.nodes[np.b];
      if (na.is_leaf() && nb.is_leaf()) {
        leaves(np.a, np.b);
        if (best_.found && best_.distance == 0.0) break;  // touching: nothing is closer
        continue;
      }
      descend(np, na, nb, stack);
    }
  }

  [[nodiscard]] const Best& best() const { return best_; }
  [[nodiscard]] const DistanceStats& stats() const { return stats_; }

 private:
  // Never more than the distance between the two nodes' triangles: the box bound minus the
  // allowance for rounding in the transform and the float boxes' axes (as collide's box test).
  double lower_bound(std::uint32_t ia, std::uint32_t ib) {
    ++stats_.node_pairs;
    const CompactBox& ba = ta_.nodes[ia].box;
    const CompactBox& bb = tb_.nodes[ib].box;
    const query_detail::MappedBox& mapped = ws_.mapped_b.mapped(ib, bb, rel_);
    const auto [c, d] = query_detail::in_box_frame(ba, mapped.axes, mapped.center);
    // The bound combines gaps along A's float axes as if orthonormal: off by a relative ~1e-6 of
    // itself (compact_box.hpp), hence the factor; the allowance covers the projected radii.
    const double bound = obb_distance_lower_bound(c, d, ba.half_extents_d(), bb.half_extents_d());
    return std::max(0.0, bound * (1.0 - kCompactBoxSlack) - margin_);
  }

  // The pair cannot hold a triangle pair that beats the best so far by more than the allowed
  // error (PQP's test), or one closer than the upper bound.
  [[nodiscard]] bool prunable(double bound) const {
    return bound >= options_.upper_bound ||
           bound * (1.0 + options_.relative_error) + options_.absolute_error >= best_.distance;
  }

  // Splits the larger node (DescendRule, as collide) and pushes both child pairs that may still
  // matter, the one with the smaller bound last (visited first: the best shrinks sooner).
  void descend(const BoundedPair& np, const Node& na, const Node& nb, std::vector<BoundedPair>& stack) {
    BoundedPair first, second;
    if (query_detail::splits_a(na, nb, options_.descend)) {
      first = {na.first, np.b, 0.0};
      second = {na.first + 1, np.b, 0.0};
    } else {
      first = {np.a, nb.first, 0.0};
      second = {np.a, nb.first + 1, 0.0};
    }
    first.bound = lower_bound(first.a, first.b);
    second.bound = lower_bound(second.a, second.b);
    if (second.bound < first.bound) std::swap(first, second);
    if (!prunable(second.bound)) stack.push_back(second);
    if (!prunable(first.bound)) stack.push_back(first);
  }

  void leaves(std::uint32_t ia_node, std::uint32_t ib_node) {
    const Node& na = ta_.nodes[ia_node];
    const Node& nb = tb_.nodes[ib_node];
    for (std::uint32_t j = 0; j < nb.count; ++j) {
      const std::uint32_t ib = tb_.triangle_order[nb.first + j];
      const Triangle& tri_b = mb_.triangles[ib];
      const Vec3 q0 = map_point(rel_, mb_.vertices[tri_b[0]]);
      const Vec3 q1 = map_point(rel_, mb_.vertices[tri_b[1]]);
      const Vec3 q2 = map_point(rel_, mb_.vertices[tri_b[2]]);
      for (std::uint32_t i = 0; i < na.count; ++i) {
        const std::uint32_t ia = ta_.triangle_order[na.first + i];
        const Triangle& tri_a = ma_.triangles[ia];
        ++stats_.triangle_pairs;
        const TriangleDistance d =
            tri_tri_distance(ma_.vertices[tri_a[0]], ma_.vertices[tri_a[1]], ma_.vertices[tri_a[2]], q0, q1, q2);
        if (d.distance < best_.distance && d.distance < options_.upper_bound) {
          best_ = {d.distance, true, {ia, ib}, d.point_p, d.point_q};
          if (d.distance == 0.0) return;
        }
      }
    }
  }

  const Tree& ta_;
  const Mesh& ma_;
  const Tree& tb_;
  const Mesh& mb_;
  const Pose& rel_;
  const DistanceOptions& options_;
  QueryWorkspace::Scratch& ws_;
  double margin_ = 0.0;
  Best best_;
  DistanceStats stats_;
};

void check_options(const DistanceOptions& options) {
  const auto bad = [](double x) { return !(x >= 0.0); };  // negative or NaN
  if (bad(options.absolute_error) || !std::isfinite(options.absolute_error))
    throw InputError("distance: absolute_error must be finite and >= 0, got " + std::to_string(options.absolute_error));
  if (bad(options.relative_error) || !std::isfinite(options.relative_error))
    throw InputError("distance: relative_error must be finite and >= 0, got " + std::to_string(options.relative_error));
  if (bad(options.upper_bound))
    throw InputError("distance: upper_bound must be >= 0 (or infinity), got " + std::to_string(options.upper_bound));
}

// The answer in the frames the caller wants: A's frame -> world by pa, -> B's frame by rel^-1.
DistanceResult make_result(const Best& best, const Pose& pa, const Pose& rel, double upper_bound) {
  DistanceResult result;
  if (!best.found) {
    result.distance = upper_bound;
    result.beyond_upper_bound = true;
    return result;
  }
  result.distance = best.distance;
  result.pair = best.pair;
  result.point_a_local = best.point_a;
  result.point_b_local = rel.inverse().apply(best.point_b);
  result.point_a = pa.apply(best.point_a);
  result.point_b = pa.apply(best.point_b);
  return result;
}

// Solid and the surfaces apart (or only known to be at least the upper bound apart): a piece
// inside the other solid makes the distance 0, with that piece's vertex as both points.
void apply_solid(const query_detail::SolidHit& hit, const Pose& pa, DistanceResult& result) {
  if (hit.inside == Inside::none) return;
  const DistanceStats stats = result.stats;
  result = {};
  result.distance = 0.0;
  result.inside = hit.inside;
  result.point_a = result.point_b = pa.apply(hit.point_a_frame);
  result.point_a_local = hit.point_a_frame;
  result.point_b_local = hit.point_b_frame;
  result.stats = stats;
}

}  // namespace

DistanceResult distance(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb, const Pose& pb,
                        const DistanceOptions& options, QueryWorkspace& workspace) {
  check_options(options);
  if (a.nodes.empty() || b.nodes.empty()) {
    DistanceResult empty;
    empty.beyond_upper_bound = true;
    return empty;
  }
  query_detail::check_tree_fits_mesh("distance", a, ma, "A");
  query_detail::check_tree_fits_mesh("distance", b, mb, "B");
  std::optional<query_detail::SolidMeshes> solid;  // checked before the descent: open meshes always throw
  if (options.solid) solid.emplace("distance", ma, options.closed_a, mb, options.closed_b);
  const Pose rel = relative_pose(pa, pb);
  DistanceSearch search(a, ma, b, mb, rel, options, workspace.scratch());
  search.run();
  DistanceResult result = make_result(search.best(), pa, rel, options.upper_bound);
  result.stats = search.stats();
  if (solid && result.distance > 0.0) apply_solid(solid->overlap(a, ma, b, mb, rel), pa, result);
  return result;
}

DistanceResult distance(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb, const Pose& pb,
                        const DistanceOptions& options) {
  QueryWorkspace workspace;
  return distance(a, ma, pa, b, mb, pb, options, workspace);
}

std::vector<DistanceResult> distance_batch(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb,
                                           std::span<const Pose> poses_b, const DistanceOptions& options,
                                           unsigned threads) {
  return query_detail::run_batch<DistanceResult>(
      "distance", ma, mb, poses_b, options, threads,
      [&](const Pose& pose, const DistanceOptions& per_pose, QueryWorkspace& workspace) {
        return distance(a, ma, pa, b, mb, pose, per_pose, workspace);
      });
}

DistanceResult distance_brute_force(const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb,
                                    const DistanceOptions& options) {
  std::optional<query_detail::SolidMeshes> solid;
  if (options.solid) solid.emplace("distance_brute_force", ma, options.closed_a, mb, options.closed_b);
  const Pose rel = relative_pose(pa, pb);
  std::vector<Vec3> mapped(mb.vertices.size());
  for (std::size_t i = 0; i < mb.vertices.size(); ++i) mapped[i] = map_point(rel, mb.vertices[i]);
  Best best;
  std::uint64_t pairs = 0;
  for (std::uint32_t ia = 0; ia < ma.triangles.size() && best.distance > 0.0; ++ia) {
    const auto [p0, p1, p2] = ma.corners(ia);
    for (std::uint32_t ib = 0; ib < mb.triangles.size(); ++ib) {
      const Triangle& t = mb.triangles[ib];
      ++pairs;
      const TriangleDistance d = tri_tri_distance(p0, p1, p2, mapped[t[0]], mapped[t[1]], mapped[t[2]]);
      if (d.distance < best.distance) {
        best = {d.distance, true, {ia, ib}, d.point_p, d.point_q};
        if (d.distance == 0.0) break;
      }
    }
  }
  DistanceResult result = make_result(best, pa, rel, std::numeric_limits<double>::infinity());
  result.stats.triangle_pairs = pairs;
  if (solid && result.distance > 0.0) apply_solid(solid->overlap_brute_force(ma, mb, rel), pa, result);
  return result;
}

}  // namespace tightbvh
