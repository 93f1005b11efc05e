#pragma once
/// @file
/// Minimum distance between two posed triangle meshes, with the closest points and triangles.
///
/// The distance is that of the closed triangle sets (tri_distance.hpp): exactly 0 iff collide()
/// reports a hit (some triangle pair touches), > 0 otherwise. Both use the same frame: B's
/// vertices mapped into A's mesh frame by relative_pose(pa, pb) (collide.hpp).
///
/// Traversal, in two phases. First collide()'s first_hit walk (its box test and touching triangle
/// test): touching meshes cost about what collide() costs, and the distance is 0 exactly when
/// collide() hits. It sets aside the node pairs whose boxes are apart and the leaf pairs that do
/// not touch; from those, PQP's bound-and-prune search (Larsen et al. 2000) but best first (the
/// node pair with the smallest bound split next), with a lower bound per node pair
/// (obb_distance.hpp, minus the allowance of collide()'s box test for rounding and the float
/// boxes' axes); the search ends when the smallest bound cannot beat the best triangle pair so far
/// (allowing for the requested error). B's boxes are mapped into A's frame lazily once per
/// query and node (the QueryWorkspace's cache).
///
/// Thread safety as collide(): any number of queries may run concurrently, each with its own
/// QueryWorkspace.
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "tightbvh/collide.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/query_workspace.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh {

/// How distance() and distance_batch() query.
struct DistanceOptions {
  /// Stop once the answer d is provably within d_true <= d <= d_true * (1 + relative_error) +
  /// absolute_error (both >= 0; 0 and 0: the exact minimum). In the meshes' length unit.
  double absolute_error = 0.0;
  double relative_error = 0.0;  ///< The relative part of the allowed error (see absolute_error).
  /// Only pairs closer than this count (>= 0): when the meshes are not closer, the query stops
  /// early and says so (DistanceResult::beyond_upper_bound).
  double upper_bound = std::numeric_limits<double>::infinity();
  DescendRule descend = DescendRule::larger_volume;  ///< Which node of a pair is split.
  /// Solids (as QueryOptions::solid): when the surfaces are apart but a piece of one lies inside
  /// the other solid, the distance is 0 (DistanceResult::inside says which). Both meshes must be
  /// closed (InputError otherwise); closed_a / closed_b as in QueryOptions.
  bool solid = false;
  const Closedness* closed_a = nullptr;  ///< check_closed(ma) for `solid`, or null (computed per query).
  const Closedness* closed_b = nullptr;  ///< check_closed(mb) for `solid`, or null (computed per query).
};

/// The work a distance query did.
struct DistanceStats {
  std::uint64_t node_pairs = 0;      ///< node pairs box-tested (touching phase) or bounded (descent)
  std::uint64_t triangle_pairs = 0;  ///< triangle pairs tested for touching or measured

  /// Field-wise equality.
  friend bool operator==(const DistanceStats&, const DistanceStats&) = default;
};

/// The answer of distance().
struct DistanceResult {
  /// The minimum distance (within the options' error), or options.upper_bound when
  /// beyond_upper_bound (then `pair` and the points are not set); +infinity for an empty tree.
  double distance = std::numeric_limits<double>::infinity();
  /// The meshes are at least options.upper_bound apart (no pair closer was found).
  bool beyond_upper_bound = false;
  TrianglePair pair;                  ///< original triangle indices (into ma.triangles, mb.triangles)
  Vec3 point_a = Vec3::Zero();        ///< the closest point on A, world frame
  Vec3 point_b = Vec3::Zero();        ///< the closest point on B, world frame
  Vec3 point_a_local = Vec3::Zero();  ///< the same point in A's mesh frame
  Vec3 point_b_local = Vec3::Zero();  ///< the same point in B's mesh frame
  DistanceStats stats;  ///< The tests this query did.
  /// solid only: the distance is 0 because a piece of one surface lies inside the other solid.
  /// Then `pair` is not set, and point_a == point_b is that piece's vertex (a point of both
  /// solids; *_local in each mesh's frame).
  Inside inside = Inside::none;
};

/// The minimum distance between mesh A at pose `pa` and mesh B at pose `pb` (mesh frame to world),
/// with the closest triangles and points.
/// Tree `a` must have been built over mesh `ma` (and `b` over `mb`), as for collide(). Throws
/// InputError for mismatched trees and meshes, and for negative or NaN options.
[[nodiscard]] DistanceResult distance(const Tree& a, const Mesh& ma, const Pose& pa,  //
                                      const Tree& b, const Mesh& mb, const Pose& pb,  //
                                      const DistanceOptions& options = {});
/// The same answer (and stats), with caller-owned scratch.
[[nodiscard]] DistanceResult distance(const Tree& a, const Mesh& ma, const Pose& pa,  //
                                      const Tree& b, const Mesh& mb, const Pose& pb,  //
                                      const DistanceOptions& options, QueryWorkspace& workspace);

/// One query per pose of B (A at pa) on `threads` threads (0: hardware concurrency); results in
/// pose order and identical for any thread count (as collide_batch).
[[nodiscard]] std::vector<DistanceResult> distance_batch(const Tree& a, const Mesh& ma, const Pose& pa,  //
                                                         const Tree& b, const Mesh& mb,                  //
                                                         std::span<const Pose> poses_b,                  //
                                                         const DistanceOptions& options = {}, unsigned threads = 0);

/// Reference: every triangle pair, the same triangle distance and the same transform as
/// distance(); the first pair (in index order) at the minimum distance. Exact: of the options only
/// solid (and closed_a / closed_b) is used (containment by rays against every triangle).
[[nodiscard]] DistanceResult distance_brute_force(const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb,
                                                  const DistanceOptions& options = {});

}  // namespace tightbvh
