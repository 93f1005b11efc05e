// Point queries against a posed mesh: closest points (Ericson, Real-Time Collision Detection,
// §5.1.5, per triangle; a best-first search with a point–box lower bound over the tree), the
// signed distance and contains (classify_point's exact ray parity). See
// include/tightbvh/point_query.hpp.
#include "tightbvh/point_query.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "../tree/parallel.hpp"
#include "query_common.hpp"
#include "solid.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/compact_box.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/scene.hpp"

namespace tightbvh {
namespace {

// A triangle whose squared normal is below this fraction of |ab|^2 |ac|^2 (the sine of its angle
// at a below 1e-4) is thin: its face candidate is compared with its edges (the face region's
// barycentrics lose precision there, and for a degenerate one they mean nothing).
constexpr double kThinTriangle = 1e-8;

// The point of segment uv closest to p: the parameter t in [0, 1] of u + t (v - u).
[[nodiscard]] double segment_parameter(const Vec3& p, const Vec3& u, const Vec3& v) {
  const Vec3 d = v - u;
  const double dd = d.dot(d);
  if (!(dd > 0.0)) return 0.0;  // a point
  return std::clamp((p - u).dot(d) / dd, 0.0, 1.0);
}

// The nearest point of the triangle's three edges (ab, bc, ca; the first on a tie): the vertex
// and edge regions of Ericson's §5.1.5 at once, and the whole of a degenerate triangle.
[[nodiscard]] TrianglePoint closest_on_edges(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double tab = segment_parameter(p, a, b), tbc = segment_parameter(p, b, c), tca = segment_parameter(p, c, a);
  const Vec3 qab = a + tab * (b - a), qbc = b + tbc * (c - b), qca = c + tca * (a - c);
  const double dab = (p - qab).squaredNorm(), dbc = (p - qbc).squaredNorm(), dca = (p - qca).squaredNorm();
  TrianglePoint best{dab, qab, Vec3(1.0 - tab, tab, 0.0)};
  if (dbc < best.distance) best = {dbc, qbc, Vec3(0.0, 1.0 - tbc, tbc)};
  if (dca < best.distance) best = {dca, qca, Vec3(tca, 0.0, 1.0 - tca)};
  best.distance = std::sqrt(best.distance);
  return best;
}

// The query point in the mesh frame: one expression for the search and its brute-force reference.
[[nodiscard]] Vec3 to_mesh_frame(const Pose& inverse, const Vec3& p) { return query_detail::map_point(inverse, p); }

// The squared raw bound of the distance from p to anything inside the node's float slab box
// { x : |a_i . (x - c)| <= e_i }: for x in it, |a_i . (x - p)| >= s_i = |a_i . (p - c)| - e_i, so
// |A^T (x - p)| >= r = sqrt(sum of s_i^2 over s_i > 0); returns r^2 (no square root per node:
// the search compares it with a squared threshold, Threshold).
[[nodiscard]] inline double box_key(const CompactBox& box, const Vec3& p) {
  const Vec3 d = p - box.center_d();
  double sum = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double s = std::abs(box.axes.col(i).cast<double>().dot(d)) - static_cast<double>(box.half_extents[i]);
    if (s > 0.0) sum += s * s;
  }
  return sum;
}

// When a node of key r^2 (box_key) can be skipped: |A^T v| <= (1 + 4e-7) |v| (the float axes are
// orthonormal to about 2e-7, compact_box.hpp), so r (1 - kCompactBoxSlack) - margin never exceeds
// the distance to the node's triangles (`margin` covers the rounding of the dot products). That
// bound exceeds a distance d iff r^2 > ((d + margin) / (1 - kCompactBoxSlack))^2; the threshold
// is raised by a relative 1e-12 for its own rounding (far below the slack), so it never skips a
// node it should visit.
[[nodiscard]] inline double squared_threshold(double distance, double margin) {
  const double r = (distance + margin) / (1.0 - kCompactBoxSlack);
  return r * r * (1.0 + 1e-12);
}

// The best triangle so far for one point, mesh frame.
struct Best {
  bool found = false;
  double distance = 0.0;
  std::uint32_t triangle = kNoTriangle;
  TrianglePoint at;

  // Whether triangle t at distance d replaces the best: closer, or as close with a lower index
  // (so the answer does not depend on the order triangles are met); only closer than `limit`.
  [[nodiscard]] bool takes(double d, std::uint32_t t, double limit) const {
    return found ? d < distance || (d == distance && t < triangle) : d < limit;
  }
  void take(const TrianglePoint& r, std::uint32_t t) { found = true, distance = r.distance, triangle = t, at = r; }
};

// A node to visit and its key (box_key).
struct Pending {
  std::uint32_t node;
  double key;
};

// A wide node (ref >= 0: its index) or a leaf (ref < 0: its child reference) to visit, with the
// lower bound of its box's distance to the point (search_wide).
struct WidePending {
  std::int32_t ref;
  float key;
};

// Per worker: the search's heap, kept between points, and the triangle of its last answer (the
// next point's seed, see search()).
struct Scratch {
  std::vector<Pending> heap;
  std::vector<std::uint32_t> ray_stack;  // classify_point's node stack
  std::vector<query_detail::WideRayItem> wide_stack;  // classify_point_wide's
  std::vector<WidePending> wide_heap;                 // search_wide's
  std::uint32_t last = kNoTriangle;
};

// Best first: the node with the least bound next (a binary heap by key), so the search ends as
// soon as the least bound left is above the best distance so far (equal is kept, for the lowest
// index on a tie) or, before any triangle, at least `limit`. `seed` (a triangle index, or
// kNoTriangle) is measured first: the previous point's triangle, close when the points are (they
// are visited in Morton order), gives a small distance to prune with from the start. The answer
// does not depend on it: every node whose bound is at most the final distance is still visited,
// so the least distance and, among equals, the lowest index are found whatever the seed.
[[nodiscard]] Best search(const Tree& tree, const Mesh& mesh, const Vec3& p, double limit, std::uint32_t seed,
                          std::vector<Pending>& heap) {
  Best best;
  if (tree.nodes.empty()) return best;
  const double margin = kBoxMargin * (query_detail::box_scale(tree.nodes[0].box) + p.cwiseAbs().maxCoeff());
  double threshold = squared_threshold(limit, margin);  // infinity for no limit
  if (seed != kNoTriangle) {
    const auto [a, b, c] = mesh.corners(seed);
    const TrianglePoint r = closest_point_on_triangle(p, a, b, c);
    if (best.takes(r.distance, seed, limit)) {
      best.take(r, seed);
      threshold = squared_threshold(best.distance, margin);
    }
  }
  // Strictly above (the threshold is raised for rounding, so equality needs no skipping): a key
  // that overflows to infinity is then still visited when there is no limit.
  const auto prunable = [&](double key) { return key > threshold; };
  const auto later = [](const Pending& x, const Pending& y) { return x.key > y.key; };
  heap.clear();
  Pending top{0, box_key(tree.nodes[0].box, p)};
  for (;;) {
    if (prunable(top.key)) break;
    const Node& node = tree.nodes[top.node];
    if (node.is_leaf()) {
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        const std::uint32_t t = tree.triangle_order[k];
        const auto [a, b, c] = mesh.corners(t);
        const TrianglePoint r = closest_point_on_triangle(p, a, b, c);
        if (best.takes(r.distance, t, limit)) {
          best.take(r, t);
          threshold = squared_threshold(best.distance, margin);
        }
      }
    } else {
      // The nearer child goes on at once unless the heap holds a nearer node; the other waits.
      Pending near{node.first, box_key(tree.nodes[node.first].box, p)};
      Pending far{node.first + 1, box_key(tree.nodes[node.first + 1].box, p)};
      if (far.key < near.key) std::swap(near, far);
      if (!prunable(far.key)) {
        heap.push_back(far);
        std::push_heap(heap.begin(), heap.end(), later);
      }
      if (!prunable(near.key) && (heap.empty() || near.key <= heap.front().key)) {
        top = near;
        continue;
      }
      if (!prunable(near.key)) {
        heap.push_back(near);
        std::push_heap(heap.begin(), heap.end(), later);
      }
    }
    if (heap.empty()) break;
    std::pop_heap(heap.begin(), heap.end(), later);
    top = heap.back();
    heap.pop_back();
  }
  return best;
}

// What the search over a model's wide nodes (search_wide) needs for every point, computed once a
// batch: every node's reference point (child_ref from the root's, as the builder and the
// descents compute them), the identity frame, its bound factor, and the point hoisted as a box
// of half extents 0 with the identity's axes (its M, for hoist_identity).
struct WidePoints {
  explicit WidePoints(const query_detail::WideTree& wide)
      : frame(query_detail::wide_frame(Pose::identity(), 0.0, wide.eta, 0.0)),
        constants(query_detail::wide_bound_constants(frame)), refs(wide.nodes.size(), wide.root_ref) {
    point.axes[0] = point.axes[4] = point.axes[8] = 1.0f;
    hoisted = query_detail::hoist(frame, query_detail::WidePair{{0.0f, 0.0f, 0.0f}, 0.0f}, point);
    std::vector<std::size_t> stack;
    if (!wide.nodes.empty()) stack.push_back(0);
    while (!stack.empty()) {
      const std::size_t n = stack.back();
      stack.pop_back();
      for (int lane = 0; lane < query_detail::kWideLanes; ++lane)
        if (const std::int32_t child = wide.nodes[n].child[lane]; child > 0) {
          refs[static_cast<std::size_t>(child)] = query_detail::child_ref(refs[n], wide.nodes[n], lane);
          stack.push_back(static_cast<std::size_t>(child));
        }
    }
  }
  query_detail::WideFrame frame;
  query_detail::WideBoundConstants constants;
  std::vector<Vec3> refs;
  query_detail::WideBox point{};
  query_detail::WideHoisted hoisted{};
};

// search() over the model's wide nodes: best first by the float lower bounds of the four
// children of a node at once (wide_point_bounds: the distance from the point to each child's
// box, never above it), the same rules (a bound strictly above the best distance, or before any
// triangle above `limit`, is skipped; equal is kept), the same seed, the same point-triangle
// function: the same answer.
[[nodiscard]] Best search_wide(const query_detail::WideTree& wide, const WidePoints& wp, const Tree& tree,
                               const Mesh& mesh, const Vec3& p, double limit, std::uint32_t seed,
                               std::vector<WidePending>& heap) {
  Best best;
  if (wide.nodes.empty()) return best;
  const auto measure = [&](std::uint32_t t) {
    const auto [a, b, c] = mesh.corners(t);
    const TrianglePoint r = closest_point_on_triangle(p, a, b, c);
    if (best.takes(r.distance, t, limit)) best.take(r, t);
  };
  if (seed != kNoTriangle) measure(seed);
  const auto prunable = [&](float key) { return static_cast<double>(key) > (best.found ? best.distance : limit); };
  const auto later = [](const WidePending& x, const WidePending& y) { return x.key > y.key; };
  const query_detail::WidePermutation identity{{0, 1, 2}, {1.0f, 1.0f, 1.0f}};
  const auto push = [&](const WidePending& x) {
    heap.push_back(x);
    std::push_heap(heap.begin(), heap.end(), later);
  };
  heap.clear();
  WidePending top{0, 0.0f};
  for (;;) {
    if (prunable(top.key)) break;
    if (top.ref < 0) {
      const query_detail::WideTree::LeafRange leaf = wide.leaf(top.ref);
      for (std::uint32_t k = leaf.first; k < leaf.first + leaf.count; ++k) measure(tree.triangle_order[k]);
    } else {
      const query_detail::WideNode& node = wide.nodes[static_cast<std::size_t>(top.ref)];
      const query_detail::WideHoisted h = query_detail::hoist_identity(wp.frame, wp.hoisted, wp.point, p,
                                                                       wp.refs[static_cast<std::size_t>(top.ref)]);
      float bounds[query_detail::kWideLanes];
      query_detail::wide_point_bounds(h, identity, node, wp.constants, bounds);
      // The nearest child goes on at once unless the heap holds a nearer entry; the others wait.
      WidePending nearest{0, 0.0f};
      bool any = false;
      for (int lane = 0; lane < query_detail::kWideLanes; ++lane) {
        if (node.child[lane] == 0 || prunable(bounds[lane])) continue;
        const WidePending child{node.child[lane], bounds[lane]};
        if (!any) {
          nearest = child, any = true;
        } else if (child.key < nearest.key) {
          push(nearest);
          nearest = child;
        } else {
          push(child);
        }
      }
      if (any && (heap.empty() || nearest.key <= heap.front().key)) {
        top = nearest;
        continue;
      }
      if (any) push(nearest);
    }
    if (heap.empty()) break;
    std::pop_heap(heap.begin(), heap.end(), later);
    top = heap.back();
    heap.pop_back();
  }
  return best;
}

// The answer in the world frame; `p` the query point (world).
[[nodiscard]] ClosestPoint to_result(const Best& best, const Pose& pose, const Vec3& p, double limit) {
  ClosestPoint r;
  if (!best.found) {
    r.distance = limit;
    r.point = p;
    r.beyond_max_distance = true;
    return r;
  }
  r.distance = best.distance;
  r.point = pose.apply(best.at.point);
  r.triangle = best.triangle;
  r.barycentric = best.at.barycentric;
  return r;
}

void check_points(const char* who, std::span<const Vec3> points) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite()) {
      std::ostringstream s;
      s << who << ": point " << i << " is not finite (" << points[i].x() << ", " << points[i].y() << ", "
        << points[i].z() << ")";
      throw InputError(s.str());
    }
}

void check_options(const char* who, const PointQueryOptions& options) {
  if (!(options.max_distance >= 0.0))  // negative or NaN
    throw InputError(std::string(who) + ": max_distance must be >= 0 (or infinity), got " +
                     std::to_string(options.max_distance));
}

void check_input(const char* who, const Tree* tree, const Mesh& mesh, const Pose& pose, std::span<const Vec3> points) {
  if (tree != nullptr && tree->triangle_order.size() != mesh.triangles.size())
    throw InputError(std::string(who) + ": the tree was built over " + std::to_string(tree->triangle_order.size()) +
                     " triangles but the mesh has " + std::to_string(mesh.triangles.size()));
  require_valid_pose(pose, who, "the pose");
  check_points(who, points);
}

// The points' indices sorted along a Morton curve (21 bits per axis over the points' bounding box;
// ties by index): consecutive points are then mostly close, so each one's search starts from a
// near triangle (search()'s seed). The order changes no answer, only the work.
[[nodiscard]] std::vector<std::uint32_t> morton_order(std::span<const Vec3> points) {
  std::vector<std::uint32_t> order(points.size());
  if (points.empty()) return order;
  Vec3 lo = points[0], hi = lo;
  for (const Vec3& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Vec3 scale = (hi - lo).cwiseMax(Vec3::Constant(1e-300)).cwiseInverse() * 2097151.0;
  const auto spread = [](std::uint64_t x) {  // the 21 bits of x to every third bit
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
  };
  // The cell along one axis; 0 for NaN (a span that overflows to infinity).
  const auto cell = [](double x) { return x >= 0.0 ? static_cast<std::uint64_t>(std::min(x, 2097151.0)) : 0; };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 q = (points[i] - lo).cwiseProduct(scale);
    keys[i] = {spread(cell(q.x())) | spread(cell(q.y())) << 1 | spread(cell(q.z())) << 2, static_cast<std::uint32_t>(i)};
  }
  std::sort(keys.begin(), keys.end());
  for (std::size_t i = 0; i < keys.size(); ++i) order[i] = keys[i].second;
  return order;
}

// fn(k, scratch) for every k in [0, count) on `threads` threads (0: all cores), in chunks of
// consecutive k (so a worker's consecutive points are neighbours in Morton order).
template <class Fn>
void for_each_point(std::size_t count, unsigned threads, Fn&& fn) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(count, 1)));
  detail::WorkerPool<Scratch> pool(threads);
  // Chunks of up to 256 points: a point takes about a microsecond (see WorkerPool::run).
  const std::size_t chunk = std::clamp<std::size_t>(count / (16 * std::size_t{threads}), 1, 256);
  pool.run(count, fn, chunk);
}

void require_model_closed(const Model& model, const char* who) {
  if (!model.closedness().closed)
    throw InputError(std::string(who) + ": the mesh is not closed: " + model.closedness().problem +
                     " (the sign and containment need the solid a closed mesh bounds)");
}

}  // namespace

TrianglePoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson §5.1.5: p's projection onto the plane has barycentrics (va, vb, vc) / (va + vb + vc)
  // (scaled signed areas); it is in the face region when all three are positive.
  const Vec3 ab = b - a, ac = c - a, ap = p - a, bp = p - b, cp = p - c;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap), d3 = ab.dot(bp), d4 = ac.dot(bp), d5 = ab.dot(cp), d6 = ac.dot(cp);
  const double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
  if (!(va > 0.0 && vb > 0.0 && vc > 0.0)) return closest_on_edges(p, a, b, c);
  const double denom = va + vb + vc;
  const double v = vb / denom, w = vc / denom;
  TrianglePoint face{0.0, a + v * ab + w * ac, Vec3(1.0 - v - w, v, w)};
  face.distance = (p - face.point).norm();
  if (ab.cross(ac).squaredNorm() > kThinTriangle * ab.squaredNorm() * ac.squaredNorm()) return face;
  const TrianglePoint edges = closest_on_edges(p, a, b, c);
  return edges.distance < face.distance ? edges : face;
}

std::vector<ClosestPoint> closest_points(const Tree& tree, const Mesh& mesh, const Pose& pose,
                                         std::span<const Vec3> points, const PointQueryOptions& options) {
  check_options("closest_points", options);
  check_input("closest_points", &tree, mesh, pose, points);
  const Pose inverse = pose.inverse();
  const std::vector<std::uint32_t> order = morton_order(points);
  std::vector<ClosestPoint> results(points.size());
  for_each_point(points.size(), options.threads, [&](std::size_t k, Scratch& scratch) {
    const std::size_t i = order[k];
    const Best best =
        search(tree, mesh, to_mesh_frame(inverse, points[i]), options.max_distance, scratch.last, scratch.heap);
    scratch.last = best.triangle;
    results[i] = to_result(best, pose, points[i], options.max_distance);
  });
  return results;
}

// On a model: search_wide over its wide nodes, the same answers as closest_points on its tree.
std::vector<ClosestPoint> closest_points(const Model& model, const Pose& pose, std::span<const Vec3> points,
                                         const PointQueryOptions& options) {
  check_options("closest_points", options);
  check_input("closest_points", nullptr, model.mesh(), pose, points);
  const Pose inverse = pose.inverse();
  const query_detail::WideTree& wide = query_detail::wide_of(model);
  const WidePoints wp(wide);
  const std::vector<std::uint32_t> order = morton_order(points);
  std::vector<ClosestPoint> results(points.size());
  for_each_point(points.size(), options.threads, [&](std::size_t k, Scratch& scratch) {
    const std::size_t i = order[k];
    const Best best = search_wide(wide, wp, model.tree(), model.mesh(), to_mesh_frame(inverse, points[i]),
                                  options.max_distance, scratch.last, scratch.wide_heap);
    scratch.last = best.triangle;
    results[i] = to_result(best, pose, points[i], options.max_distance);
  });
  return results;
}

std::vector<ClosestPoint> signed_distance(const Model& model, const Pose& pose, std::span<const Vec3> points,
                                          const PointQueryOptions& options) {
  check_options("signed_distance", options);
  require_model_closed(model, "signed_distance");
  check_input("signed_distance", nullptr, model.mesh(), pose, points);
  const Pose inverse = pose.inverse();
  const query_detail::WideTree& wide = query_detail::wide_of(model);
  const query_detail::WideRays rays(model.tree(), wide);
  const WidePoints wp(wide);
  const std::vector<std::uint32_t> order = morton_order(points);
  std::vector<ClosestPoint> results(points.size());
  for_each_point(points.size(), options.threads, [&](std::size_t k, Scratch& scratch) {
    const std::size_t i = order[k];
    const Vec3 local = to_mesh_frame(inverse, points[i]);
    const Best best =
        search_wide(wide, wp, model.tree(), model.mesh(), local, options.max_distance, scratch.last, scratch.wide_heap);
    scratch.last = best.triangle;
    ClosestPoint r = to_result(best, pose, points[i], options.max_distance);
    switch (query_detail::classify_point_wide(model.tree(), wide, rays, model.mesh(), local, scratch.wide_stack,
                                              scratch.ray_stack)) {
      case Containment::inside: r.distance = -r.distance; break;
      case Containment::on_surface: r.distance = 0.0; break;
      case Containment::outside: break;
    }
    results[i] = r;
  });
  return results;
}

std::vector<Containment> contains(const Model& model, const Pose& pose, std::span<const Vec3> points,
                                  unsigned threads) {
  require_model_closed(model, "contains");
  check_input("contains", nullptr, model.mesh(), pose, points);
  const Pose inverse = pose.inverse();
  const query_detail::WideTree& wide = query_detail::wide_of(model);
  const query_detail::WideRays rays(model.tree(), wide);
  std::vector<Containment> results(points.size());
  for_each_point(points.size(), threads, [&](std::size_t i, Scratch& scratch) {
    results[i] = query_detail::classify_point_wide(model.tree(), wide, rays, model.mesh(),
                                                   to_mesh_frame(inverse, points[i]), scratch.wide_stack,
                                                   scratch.ray_stack);
  });
  return results;
}

std::vector<ClosestPoint> closest_points_brute_force(const Mesh& mesh, const Pose& pose, std::span<const Vec3> points,
                                                     const PointQueryOptions& options) {
  check_options("closest_points_brute_force", options);
  check_input("closest_points_brute_force", nullptr, mesh, pose, points);
  const Pose inverse = pose.inverse();
  std::vector<ClosestPoint> results(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 p = to_mesh_frame(inverse, points[i]);
    Best best;
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto [a, b, c] = mesh.corners(t);
      const TrianglePoint r = closest_point_on_triangle(p, a, b, c);
      if (best.takes(r.distance, t, options.max_distance)) best.take(r, t);
    }
    results[i] = to_result(best, pose, points[i], options.max_distance);
  }
  return results;
}

}  // namespace tightbvh
