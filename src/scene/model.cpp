// Model: a mesh, its tree and the per-mesh data of repeated queries (model.hpp).
#include "tightbvh/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "../collide/contact_query.hpp"
#include "../collide/query_common.hpp"
#include "../collide/solid.hpp"
#include "../collide/wide_collide.hpp"
#include "../collide/wide_nodes.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/scene.hpp"
#include "tightbvh/validate_tree.hpp"

namespace tightbvh {

namespace {

// The root box's axes made exactly orthonormal (Gram-Schmidt in double; the float axes are
// orthonormal to about 2e-7, compact_box.hpp), the vertices' range measured along them, and the
// extents padded by a relative 1e-12 of the mesh's size for the rounding of that measurement and
// of the later transform (scene.cpp pads the posed box again).
Obb mesh_bounds(const Mesh& mesh, const Tree& tree) {
  Mat3 axes = tree.nodes.empty() ? Mat3::Identity() : tree.nodes[0].box.axes_d();
  Vec3 x = axes.col(0).normalized();
  Vec3 y = (axes.col(1) - x.dot(axes.col(1)) * x).normalized();
  if (!x.allFinite() || !y.allFinite()) x = Vec3::UnitX(), y = Vec3::UnitY();
  axes.col(0) = x;
  axes.col(1) = y;
  axes.col(2) = x.cross(y);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& v : mesh.vertices) {
    const Vec3 p = axes.transpose() * v;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  double scale = 0.0;
  for (const Vec3& v : mesh.vertices) scale = std::max(scale, v.cwiseAbs().maxCoeff());
  Obb box;
  box.axes = axes;
  box.center = axes * (0.5 * (lo + hi));
  box.half_extents = (0.5 * (hi - lo)).array() + 1e-12 * scale + std::numeric_limits<double>::min();
  return box;
}

// QueryOptions or DistanceOptions: solid queries take each model's closedness, computed once.
template <class Options>
Options with_closedness(const Model& a, const Model& b, const Options& options) {
  Options o = options;
  bool solid = o.solid;
  if constexpr (requires { o.signed_distance; }) solid = solid || o.signed_distance;
  if (solid) {
    if (!o.closed_a) o.closed_a = &a.closedness();
    if (!o.closed_b) o.closed_b = &b.closedness();
  }
  return o;
}

}  // namespace

Model::Model(Mesh mesh, const BuildOptions& options) : mesh_(std::move(mesh)) {
  check_mesh(mesh_, "model");
  tree_ = build(mesh_, options);
  finish();
}

Model::Model(Mesh mesh, Tree tree) : mesh_(std::move(mesh)), tree_(std::move(tree)) {
  check_mesh(mesh_, "model");
  const TreeCheck check = validate(tree_, mesh_);
  if (!check.ok()) throw InputError("model: the tree does not fit the mesh: " + check.summary());
  finish();
}

void Model::finish() {
  closedness_ = check_closed(mesh_);
  bounds_ = mesh_bounds(mesh_, tree_);
  wide_ = std::make_shared<const query_detail::WideTree>(query_detail::build_wide(tree_));
}

std::size_t Model::bytes() const {
  return mesh_.vertices.capacity() * sizeof(Vec3) + mesh_.triangles.capacity() * sizeof(Triangle) +
         tree_.nodes.capacity() * sizeof(Node) + tree_.triangle_order.capacity() * sizeof(std::uint32_t) +
         wide_->nodes.capacity() * sizeof(query_detail::WideNode) +
         closedness_.pieces.capacity() * sizeof(std::uint32_t) + closedness_.problem.capacity();
}

ModelPtr make_model(Mesh mesh, const BuildOptions& options) {
  return std::make_shared<const Model>(std::move(mesh), options);
}

ModelPtr make_model(Mesh mesh, Tree tree) { return std::make_shared<const Model>(std::move(mesh), std::move(tree)); }

QueryResult collide(const Model& a, const Pose& pa, const Model& b, const Pose& pb, const QueryOptions& options) {
  QueryWorkspace workspace;
  return collide(a, pa, b, pb, options, workspace);
}

QueryResult collide(const Model& a, const Pose& pa, const Model& b, const Pose& pb, const QueryOptions& options,
                    QueryWorkspace& workspace) {
  if (!is_valid_pose(pa)) require_valid_pose(pa, "collide", "the pose of model A");
  if (!is_valid_pose(pb)) require_valid_pose(pb, "collide", "the pose of model B");
  return scene_detail::collide_checked(a, pa, b, pb, options, workspace);
}

// The wide descent in every mode and margin with the default descend rule, where it was measured
// faster than the binary one in most scenarios (docs/design-notes/query-core.md, "collide() on
// models" and "first_hit and margins on the wide nodes"); solids and contacts are added after it
// as collide() adds them, after collide()'s own checks of the options.
QueryResult scene_detail::collide_checked(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                                          const QueryOptions& options, QueryWorkspace& workspace) {
  if (options.descend != DescendRule::larger_volume)
    return collide(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb, with_closedness(a, b, options), workspace);
  query_detail::check_margin("collide", options.margin);
  query_detail::check_contacts("collide", options);
  const QueryOptions o = with_closedness(a, b, options);
  std::optional<query_detail::SolidMeshes> solid;  // before the descent: an open mesh always throws
  if (o.solid) solid.emplace("collide", a.mesh_, o.closed_a, b.mesh_, o.closed_b);
  const Pose rel = relative_pose(pa, pb);
  QueryResult result = query_detail::collide_wide(a.tree_, *a.wide_, a.mesh_, b.tree_, *b.wide_, b.mesh_, rel,
                                                  o.mode, o.margin);
  if (o.contacts) query_detail::add_contacts(result, a.mesh_, pa, b.mesh_, pb);
  if (solid && !result.hit) {  // no pair: is one solid inside the other?
    result.inside = solid->overlap(a.tree_, a.mesh_, b.tree_, b.mesh_, rel).inside;
    result.hit = result.inside != Inside::none;
  }
  return result;
}

DistanceResult distance(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                        const DistanceOptions& options) {
  return distance(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb, with_closedness(a, b, options));
}

DistanceResult distance(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                        const DistanceOptions& options, QueryWorkspace& workspace) {
  return distance(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb, with_closedness(a, b, options), workspace);
}

}  // namespace tightbvh
