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
/// Signed distance of solids (DistanceOptions::signed_distance): when the solids overlap, the
/// answer is minus a penetration depth, the largest depth of a vertex of either mesh strictly
/// inside the other solid (its distance to the other surface). Overlap is decided by that vertex
/// test itself (exact: classify_point, inside.hpp): a vertex strictly inside the other solid
/// makes the interiors overlap. Surfaces apart: the solid test of QueryOptions::solid (one vertex
/// per piece) says whether one solid is nested in the other; if not, the answer is the unsigned
/// one, bit for bit. Surfaces touching or nested: every vertex is classified (those outside the
/// other root box skipped), and the closest point on the other surface measured for the vertices
/// strictly inside. The magnitude is a lower bound of the translational penetration depth
/// (docs/algorithms.md, "Penetration of closed meshes"); it is 0 when the surfaces cross with no
/// vertex inside (an edge–edge crossing), which DistanceResult::penetration_lower_bound_is_zero
/// flags, with the length of the surfaces' intersection curve (DistanceResult::curve_length).
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
  /// Signed distance of solids (see the file comment): negative when the solids overlap, minus
  /// the largest depth of a vertex of either mesh inside the other solid (DistanceResult::deepest
  /// says whose). Both meshes must be closed (InputError naming the open mesh; closed_a /
  /// closed_b as for `solid`). Implies `solid` (a nested solid gives a negative distance, not 0).
  bool signed_distance = false;
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
  /// signed_distance only, the solids overlap (distance < 0): whose vertex is deepest. a_in_b: a
  /// vertex of A inside B's solid; point_a is that vertex, point_b its closest point on B's
  /// surface. b_in_a: a vertex of B inside A's solid; point_b is that vertex, point_a its closest
  /// point on A's surface. The distance is minus the vertex's distance to that point (measured in
  /// the other mesh's frame: B's vertices mapped into A's frame as for every triangle test, A's
  /// by the inverse map); `pair` is not set. On a tie in depth, A's vertex before B's, the lower
  /// index first. none otherwise.
  Inside deepest = Inside::none;
  /// The deepest vertex's index (into ma.vertices for a_in_b, mb.vertices for b_in_a); 0 when
  /// `deepest` is none.
  std::uint32_t deepest_vertex = 0;
  /// signed_distance only: the surfaces touch (distance 0, `pair` and the points as without
  /// signed_distance) but no vertex of either mesh lies strictly inside the other solid. The
  /// solids touch or overlap through crossing edges only; the penetration depth's lower bound
  /// is then 0.
  bool penetration_lower_bound_is_zero = false;
  /// penetration_lower_bound_is_zero only: the length of the intersection curve of the two
  /// surfaces (QueryResult::curve_length of collide() in all_pairs mode with contacts), the
  /// measure of the crossing that the zero bound does not give. Coplanar overlaps add 0, so
  /// faces flush against each other give the length of their contact region's border segments
  /// that other triangles cross. 0 otherwise.
  double curve_length = 0.0;
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
/// solid, signed_distance (and closed_a / closed_b) are used (containment by rays against every
/// triangle; signed_distance: every vertex classified by classify_point_brute_force and measured
/// by closest_points_brute_force, in the same frames as distance(), so the same answer bit for
/// bit).
[[nodiscard]] DistanceResult distance_brute_force(const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb,
                                                  const DistanceOptions& options = {});

}  // namespace tightbvh
