#pragma once
/// @file
/// Tree-vs-tree collision queries between two posed triangle meshes.
///
/// Touching: triangles are closed sets; two triangles touch iff they share at least one point
/// (shared vertices and edges, a vertex on a face, coplanar overlap all count). Degenerate
/// (zero-area) triangles are the segment or point they are. See tri_tri.hpp; the brute-force
/// reference below uses the same predicate.
///
/// Frames: B's vertices are mapped into A's mesh frame with the relative pose
/// relative_pose(pa, pb) = pa^-1 * pb, computed once per query; triangle pairs are tested there,
/// in both collide() and collide_brute_force(), with the same arithmetic, so both report exactly
/// the same pairs.
///
/// Traversal: Gottschalk et al. (1996) descent over node pairs with the 15-axis SAT
/// (obb_overlap.hpp), splitting the larger box (by volume) first, an explicit stack (inline
/// buffer, heap only for very deep trees), B's boxes mapped into A's frame lazily once per query
/// and node (both in a QueryWorkspace), B's triangles mapped at the leaves. Boxes are tested with a
/// small margin ((kBoxMargin + kCompactBoxSlack) times the meshes' scale) so that rounding and the
/// float boxes' slightly skew axes (compact_box.hpp) never cull a touching pair. No virtual calls.
///
/// Thread safety: the query functions only read their inputs; any number of queries may run
/// concurrently, each with its own QueryWorkspace (the overloads without one make their own).
#include <cstdint>
#include <span>
#include <vector>

#include "tightbvh/closed.hpp"
#include "tightbvh/contact.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/query_cache.hpp"
#include "tightbvh/query_workspace.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh {

/// What collide() reports.
enum class QueryMode {
  first_hit,  ///< stop at the first touching triangle pair
  all_pairs,  ///< every touching triangle pair
};

/// Which node of a pair of internal nodes is split during the descent: the larger by this
/// measure, or both when they are within a factor 8 of each other (their four child pairs are
/// box-tested at once).
enum class DescendRule {
  larger_volume,  ///< the box with the larger volume (default)
  larger_extent,  ///< the box with the larger maximal half extent
};

/// How collide() and collide_batch() query.
struct QueryOptions {
  QueryMode mode = QueryMode::first_hit;             ///< The first touching pair, or all of them.
  DescendRule descend = DescendRule::larger_volume;  ///< Which node of a pair is split.
  /// Safety margin (finite, >= 0): report the triangle pairs at distance <= margin
  /// (tri_tri_distance, tri_distance.hpp) instead of the touching ones; boxes are tested inflated
  /// by it. 0 (the default) is plain touching (tri_tri_overlap), with no margin arithmetic at all.
  double margin = 0.0;
  /// Solids: the meshes are the closed surfaces of solids (closed.hpp), and a hit is also
  /// reported when no triangle pair is reported but a piece of one surface lies inside the other
  /// solid (QueryResult::inside; decided exactly by ray parity, inside.hpp). Both meshes must be
  /// closed, else InputError naming the mesh and why. closed_a / closed_b: check_closed(ma) and
  /// check_closed(mb), computed once per mesh; when null, each query computes them (O(n log n)
  /// per query: loops should pass them; collide_batch computes them once). false: no change.
  bool solid = false;
  const Closedness* closed_a = nullptr;  ///< check_closed(ma) for `solid`, or null (computed per query).
  const Closedness* closed_b = nullptr;  ///< check_closed(mb) for `solid`, or null (computed per query).
  /// Contact geometry: QueryResult::contacts gets, for each reported pair, where the two triangles
  /// meet (contact.hpp), computed after the traversal. Only with mode all_pairs and margin 0 (pairs
  /// within a margin need not touch): otherwise InputError naming the option.
  bool contacts = false;
};

/// Why a solid query (QueryOptions::solid) hit without a reported triangle pair.
enum class Inside : std::uint8_t {
  none,    ///< no containment (touching or within-margin pairs, no hit, or solid not asked)
  b_in_a,  ///< a piece of B's surface lies inside A's solid
  a_in_b,  ///< a piece of A's surface lies inside B's solid
};
/// The enumerator's name: "none", "b_in_a" or "a_in_b".
[[nodiscard]] const char* to_string(Inside inside);

/// Relative margin of the box tests for rounding in the transform (times the sum of the two root
/// boxes' scales); the queries add kCompactBoxSlack for the float boxes.
inline constexpr double kBoxMargin = 1e-9;

/// The work a query did, in tests (the same for any thread count or workspace).
struct QueryStats {
  std::uint64_t box_tests = 0;       ///< SAT tests of node pairs
  std::uint64_t triangle_tests = 0;  ///< triangle-triangle tests

  /// Field-wise equality.
  friend bool operator==(const QueryStats&, const QueryStats&) = default;
};

/// Original triangle indices (into ma.triangles and mb.triangles).
struct TrianglePair {
  std::uint32_t a = 0;  ///< Index into ma.triangles (mesh A).
  std::uint32_t b = 0;  ///< Index into mb.triangles (mesh B).

  /// Ordered by a, then b.
  friend auto operator<=>(const TrianglePair&, const TrianglePair&) = default;
};

/// The answer of collide().
struct QueryResult {
  /// Some triangle pair touches (or is within the margin), or, with `solid`, a piece of one
  /// surface lies inside the other solid.
  bool hit = false;
  /// all_pairs: every touching pair, sorted by (a, b), unique. first_hit: the pair found, if any.
  std::vector<TrianglePair> pairs;
  QueryStats stats;  ///< The tests this query did.
  /// solid only: set when the hit is a containment (then `pairs` is empty). Containment is
  /// tested only when no pair was reported.
  Inside inside = Inside::none;
  /// contacts only: contacts[i] is where pairs[i]'s triangles meet, in the world frame (a segment,
  /// a point, or a coplanar polygon; contact.hpp). Empty otherwise.
  std::vector<Contact> contacts;
  /// contacts only: the length of the intersection curve, the sum of the segments' lengths
  /// (points add 0; coplanar polygons add 0, their perimeters are not part of the curve).
  double curve_length = 0.0;
};

/// pa^-1 * pb: maps B's mesh frame to A's mesh frame.
[[nodiscard]] Pose relative_pose(const Pose& pa, const Pose& pb);

/// Whether mesh A at pose `pa` and mesh B at pose `pb` (mesh frame to world) touch, and which
/// triangle pairs do (QueryOptions::mode).
/// Tree `a` must have been built over mesh `ma` (and `b` over `mb`); boxes in the mesh frames.
/// A tree whose triangle count differs from its mesh's throws InputError, as does a negative, NaN
/// or infinite margin, or solid with an open mesh; an empty tree never hits.
[[nodiscard]] QueryResult collide(const Tree& a, const Mesh& ma, const Pose& pa,  //
                                  const Tree& b, const Mesh& mb, const Pose& pb,  //
                                  const QueryOptions& options = {});
/// The same answer (and stats), with caller-owned scratch: the way to run many queries without
/// allocating per query.
[[nodiscard]] QueryResult collide(const Tree& a, const Mesh& ma, const Pose& pa,  //
                                  const Tree& b, const Mesh& mb, const Pose& pb,  //
                                  const QueryOptions& options, QueryWorkspace& workspace);
/// Coherent sequences (a simulation loop): the same answer, starting from the front the previous
/// query on the same trees left in `cache` (query_cache.hpp). all_pairs: the same pairs; first_hit:
/// the same hit flag, and the pair reported is the first found (the previous hit's leaf pair is
/// tried first), which may differ from the cold query's. stats count the tests this query did.
/// Any mode, margin and descend rule; trees other than the cache's restart from the roots.
[[nodiscard]] QueryResult collide(const Tree& a, const Mesh& ma, const Pose& pa,  //
                                  const Tree& b, const Mesh& mb, const Pose& pb,  //
                                  const QueryOptions& options, QueryCache& cache);

/// One query per pose of B (A at pa), spread over `threads` threads (0: hardware concurrency).
/// Results are in pose order and identical for any thread count. When queries throw, the
/// exception of the lowest pose index is rethrown (whatever the thread count).
[[nodiscard]] std::vector<QueryResult> collide_batch(const Tree& a, const Mesh& ma, const Pose& pa,  //
                                                     const Tree& b, const Mesh& mb,                 //
                                                     std::span<const Pose> poses_b,                 //
                                                     const QueryOptions& options = {}, unsigned threads = 0);

/// Reference: every triangle pair, same predicate (margin included) and same transform as collide(). In
/// first_hit mode it stops at the first touching pair (in index order). stats.box_tests == 0.
/// solid: containment by rays against every triangle (classify_point_brute_force).
[[nodiscard]] QueryResult collide_brute_force(const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb,
                                              const QueryOptions& options = {});

}  // namespace tightbvh
