#pragma once
/// @file
/// Point queries against a posed mesh: the closest point on the surface, the signed distance and
/// inside / outside / on the surface, for many points at once.
///
/// Each point (world frame) is mapped into the mesh frame by the inverse pose; the surface is the
/// union of the closed triangles (degenerate ones are the segment or point they are). The closest
/// point on one triangle is Ericson's (Real-Time Collision Detection, §5.1.5, Voronoi regions):
/// the projection onto the plane when it falls strictly inside the triangle, otherwise the nearest
/// point of its three edges (closest_point_on_triangle). The tree is searched best first (the node
/// of least bound next), with a point–box lower bound that never exceeds the distance to the box's
/// triangles; the search ends when the least bound left exceeds the best distance so far or, before
/// any triangle, is at least options.max_distance. Among triangles at the same least distance the lowest index wins, so the
/// answer is bit for bit closest_points_brute_force()'s.
///
/// The sign (signed_distance) and contains() are classify_point()'s (inside.hpp: exact ray parity
/// with exact predicates), for the point as mapped into the mesh frame (with the identity pose,
/// the coordinates given). They need a closed mesh (closed.hpp): InputError otherwise, saying why.
///
/// Batches run on `threads` threads (0: all cores), the points visited in Morton order, each search
/// seeded with the triangle of the previous point's answer (which changes the work, never the
/// answer); results are in point order and identical for any thread count.
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "tightbvh/inside.hpp"
#include "tightbvh/math.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh {

/// How the point queries run.
struct PointQueryOptions {
  /// Only triangles closer than this count (>= 0, or infinity): a point with none reports
  /// ClosestPoint::beyond_max_distance, and the search skips every node at least this far.
  double max_distance = std::numeric_limits<double>::infinity();
  unsigned threads = 0;  ///< Threads of a batch; 0: all cores (hardware concurrency).
};

/// The triangle index of a ClosestPoint that found no triangle within the max_distance.
inline constexpr std::uint32_t kNoTriangle = std::numeric_limits<std::uint32_t>::max();

/// The answer of one point: its closest point on the surface, world frame.
struct ClosestPoint {
  /// The distance to the surface (>= 0); signed_distance(): negative inside, 0 on the surface.
  /// options.max_distance (with the sign, for signed_distance()) when beyond_max_distance.
  double distance = std::numeric_limits<double>::infinity();
  /// The closest point on the surface (world frame); the query point itself when beyond_max_distance.
  Vec3 point = Vec3::Zero();
  /// The index (into Mesh::triangles) of the triangle `point` lies on; kNoTriangle when beyond_max_distance.
  std::uint32_t triangle = kNoTriangle;
  /// `point` as u a + v b + w c of the triangle's corners (a, b, c) = its vertices in index order
  /// (u + v + w = 1, each in [0, 1]); zero when beyond_max_distance.
  Vec3 barycentric = Vec3::Zero();
  /// No triangle is closer than options.max_distance: `distance` is that bound, the other fields
  /// as said above.
  bool beyond_max_distance = false;
};

/// The closest point of one triangle to a point, all in one frame.
struct TrianglePoint {
  double distance = 0.0;              ///< |p - point|, >= 0
  Vec3 point = Vec3::Zero();          ///< on the closed triangle (a, b, c)
  Vec3 barycentric = Vec3::Zero();    ///< `point` as u a + v b + w c (u + v + w = 1, each in [0, 1])
};

/// The closest point to `p` of the closed triangle (a, b, c), as described in the file comment
/// (Ericson §5.1.5). A degenerate triangle (a segment or a point) gives the closest point of the
/// segment or point it is.
[[nodiscard]] TrianglePoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// The closest point on `mesh` (at `pose`, mesh frame to world) of each of `points` (world frame),
/// in point order. `tree` built over `mesh`. InputError for a mismatched tree, a pose that is not a
/// finite proper rotation (kRotationTolerance, scene.hpp), a point that is not finite (naming its
/// index) or a negative or NaN max_distance. Empty tree: every point beyond.
[[nodiscard]] std::vector<ClosestPoint> closest_points(const Tree& tree, const Mesh& mesh, const Pose& pose,
                                                       std::span<const Vec3> points,
                                                       const PointQueryOptions& options = {});
/// closest_points() on a model's tree and mesh.
[[nodiscard]] std::vector<ClosestPoint> closest_points(const Model& model, const Pose& pose,
                                                       std::span<const Vec3> points,
                                                       const PointQueryOptions& options = {});

/// closest_points() with the distance signed: negative inside the solid the model's mesh bounds,
/// 0 on its surface (exactly: classify_point), positive outside. InputError as closest_points(),
/// and when the mesh is not closed (with Closedness::problem).
[[nodiscard]] std::vector<ClosestPoint> signed_distance(const Model& model, const Pose& pose,
                                                        std::span<const Vec3> points,
                                                        const PointQueryOptions& options = {});

/// Where each point (world frame) is relative to the solid of the model's mesh at `pose`
/// (classify_point, exact), in point order, on `threads` threads (0: all cores). InputError as
/// signed_distance().
[[nodiscard]] std::vector<Containment> contains(const Model& model, const Pose& pose, std::span<const Vec3> points,
                                                unsigned threads = 0);

/// Reference: closest_points() over every triangle (no tree), the same point–triangle function
/// and transform, the first triangle (in index order) at the least distance; options.threads unused.
[[nodiscard]] std::vector<ClosestPoint> closest_points_brute_force(const Mesh& mesh, const Pose& pose,
                                                                   std::span<const Vec3> points,
                                                                   const PointQueryOptions& options = {});

}  // namespace tightbvh
