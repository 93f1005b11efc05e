#pragma once
/// @file
/// A Model: one triangle mesh and its tree, built once, immutable, shared by any number of posed
/// objects (scene.hpp) as a std::shared_ptr<const Model>. It also keeps what repeated queries on
/// the mesh need, computed once: the mesh's closedness (for solid queries, closed.hpp), a
/// double-precision box around the mesh (for the scene's top-level tree), and the tree's boxes
/// again as wide single-precision nodes of four children, the layout collide() on two models
/// descends for all_pairs (docs/design-notes/query-core.md).
#include <cstddef>
#include <memory>

#include "tightbvh/build.hpp"
#include "tightbvh/closed.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/collide_trace.hpp"
#include "tightbvh/distance.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/obb.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/query_cache.hpp"
#include "tightbvh/query_workspace.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh {

class Model;
namespace query_detail {
struct WideTree;  // src/collide/wide_nodes.hpp: the query-time nodes, internal
/// Internal: the model's wide nodes, for the queries in src/collide/.
[[nodiscard]] const WideTree& wide_of(const Model& model);
}  // namespace query_detail
namespace scene_detail {
/// Internal: collide() of two models whose poses the caller has checked (the scenes, which check
/// them when they are set); collide() on models checks them, then calls this.
[[nodiscard]] QueryResult collide_checked(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                                          const QueryOptions& options, QueryWorkspace& workspace);
}  // namespace scene_detail

/// A mesh, its tree and the per-mesh data of repeated queries. Immutable after construction.
class Model {
 public:
  /// Checks `mesh` (check_mesh: InputError on NaN, out-of-range indices, no triangles) and builds
  /// its tree with `options`.
  explicit Model(Mesh mesh, const BuildOptions& options = {});
  /// Takes a tree built earlier over `mesh` (loaded from a file, say). InputError unless the mesh
  /// is valid and the tree passes validate(tree, mesh) (validate_tree.hpp).
  Model(Mesh mesh, Tree tree);

  /// The mesh, in the model's own frame.
  [[nodiscard]] const Mesh& mesh() const { return mesh_; }
  /// The tree over mesh().
  [[nodiscard]] const Tree& tree() const { return tree_; }
  /// check_closed(mesh()), computed once; the solid queries on models use it.
  [[nodiscard]] const Closedness& closedness() const { return closedness_; }
  /// A box around every vertex, in double precision with exactly orthonormal axes (the root
  /// node's axes, orthonormalised, the extents measured again and padded for rounding): what the
  /// scene's top-level tree bounds the model by under a pose.
  [[nodiscard]] const Obb& bounds() const { return bounds_; }
  /// The heap bytes this model holds (vertices, triangles, tree nodes and order, wide nodes,
  /// closedness).
  [[nodiscard]] std::size_t bytes() const;

 private:
  void finish();

  Mesh mesh_;
  Tree tree_;
  Closedness closedness_;
  Obb bounds_;
  // The tree's wide nodes (internal type, so held by pointer; shared so that Model stays copyable).
  std::shared_ptr<const query_detail::WideTree> wide_;

  friend QueryResult scene_detail::collide_checked(const Model&, const Pose&, const Model&, const Pose&,
                                                   const QueryOptions&, QueryWorkspace&);
  friend const query_detail::WideTree& query_detail::wide_of(const Model&);
};

/// How models are shared: by any number of scene objects and threads, never modified.
using ModelPtr = std::shared_ptr<const Model>;

/// A shared model built from `mesh` (see Model(Mesh, const BuildOptions&)).
[[nodiscard]] ModelPtr make_model(Mesh mesh, const BuildOptions& options = {});
/// A shared model from an existing tree over `mesh`, validated (see Model(Mesh, Tree)).
[[nodiscard]] ModelPtr make_model(Mesh mesh, Tree tree);

/// collide() (collide.hpp) of two posed models: the same answer. With options.solid, a null
/// closed_a / closed_b is taken from the models (computed once at construction). InputError for
/// a pose that is not finite or not a proper rotation (require_valid_pose, scene.hpp). Queries
/// with the default descend rule (every mode and margin, solid and contacts too) descend the
/// models' wide nodes, four children per node in single precision with a proven outward
/// allowance, rather than the binary trees (docs/design-notes/query-core.md, "collide() on
/// models"): all_pairs gives the same pairs and first_hit the same yes/no, though the one pair it
/// reports may be another touching pair than the trees' collide() finds first; their stats count
/// the box pairs that descent tests (one box of A against one child of B), so they differ from
/// the binary descent's.
[[nodiscard]] QueryResult collide(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                                  const QueryOptions& options = {});
/// The same answer, with caller-owned scratch (no allocation per query).
[[nodiscard]] QueryResult collide(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                                  const QueryOptions& options, QueryWorkspace& workspace);
/// collide() of two posed models along a coherent sequence of poses (a simulation loop), the same
/// answers as without the cache. first_hit tries the triangle pair that touched in the cache's last
/// first_hit on these models with one exact triangle test (within the margin, if any) and reports
/// it if it still touches (stats: 0 box tests, 1 triangle test); otherwise the wide descent answers
/// and its pair becomes the witness. all_pairs is the wide descent, as without the cache (no
/// front is kept on these nodes: docs/design-notes/collide.md, "QueryCache: front tracking, kept
/// but narrow", says why). With another descend rule than the default, the trees' collide() with
/// the cache answers (its front). Errors as collide() on models.
[[nodiscard]] QueryResult collide(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                                  const QueryOptions& options, QueryCache& cache);
/// collide() of two posed models with its descent recorded (collide_trace.hpp): the wide descent
/// that collide() on models makes, the same answer, stats and first hit. Each VisitedPair is one
/// box of A against one child box of B, named by the Tree nodes whose boxes the wide nodes hold
/// (a wide node's children are binary descendants one or more levels down, so levels can skip),
/// the level being the sum of their depths; the roots' pair comes first. `visited` equals
/// result.stats.box_tests. Errors as collide() on models.
[[nodiscard]] CollideTrace collide_trace(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                                         const QueryOptions& options = {}, const CollideTraceOptions& trace = {});
/// distance() (distance.hpp) of two posed models; closedness from the models as for collide().
[[nodiscard]] DistanceResult distance(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                                      const DistanceOptions& options = {});
/// The same answer, with caller-owned scratch.
[[nodiscard]] DistanceResult distance(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                                      const DistanceOptions& options, QueryWorkspace& workspace);

}  // namespace tightbvh
