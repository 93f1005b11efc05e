// Model: a mesh, its tree and the per-mesh data of repeated queries (model.hpp).
#include "tightbvh/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "../collide/contact_query.hpp"
#include "../collide/query_cache.hpp"
#include "../collide/query_common.hpp"
#include "../collide/solid.hpp"
#include "../collide/wide_collide.hpp"
#include "../collide/wide_nodes.hpp"
#include "tightbvh/collide_trace.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/scene.hpp"
#include "tightbvh/tri_tri.hpp"
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

const query_detail::WideTree& query_detail::wide_of(const Model& model) { return *model.wide_; }

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

namespace {

// collide() on two models (poses checked) with the descent `descend(rel, options)` over their
// wide nodes: collide()'s checks of the options first, then solids and contacts added after the
// descent exactly as collide() adds them.
template <class Descend>
QueryResult on_models(const Model& a, const Pose& pa, const Model& b, const Pose& pb, const QueryOptions& options,
                      Descend&& descend) {
  query_detail::check_margin("collide", options.margin);
  query_detail::check_contacts("collide", options);
  const QueryOptions o = with_closedness(a, b, options);
  std::optional<query_detail::SolidMeshes> solid;  // before the descent: an open mesh always throws
  if (o.solid) solid.emplace("collide", a.mesh(), o.closed_a, b.mesh(), o.closed_b);
  const Pose rel = relative_pose(pa, pb);
  QueryResult result = descend(rel, o);
  if (o.contacts) query_detail::add_contacts(result, a.mesh(), pa, b.mesh(), pb);
  if (solid && !result.hit) {  // no pair: is one solid inside the other?
    result.inside = solid->overlap(a.tree(), a.mesh(), b.tree(), b.mesh(), rel).inside;
    result.hit = result.inside != Inside::none;
  }
  return result;
}

}  // namespace

// The wide descent in every mode and margin with the default descend rule, where it was measured
// faster than the binary one in most scenarios (docs/design-notes/query-core.md, "collide() on
// models" and "first_hit and margins on the wide nodes").
QueryResult scene_detail::collide_checked(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                                          const QueryOptions& options, QueryWorkspace& workspace) {
  if (options.descend != DescendRule::larger_volume)
    return collide(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb, with_closedness(a, b, options), workspace);
  return on_models(a, pa, b, pb, options, [&](const Pose& rel, const QueryOptions& o) {
    return query_detail::collide_wide(a.tree_, *a.wide_, a.mesh_, b.tree_, *b.wide_, b.mesh_, rel, o.mode, o.margin);
  });
}

// The witness first (query_cache.hpp): one exact triangle test, with the predicate the descent's
// leaves use, so a hit here is a hit there; indices are checked because the cache's key cannot
// tell a model rebuilt at the same address (a stale witness is then only a wasted test).
QueryResult collide(const Model& a, const Pose& pa, const Model& b, const Pose& pb, const QueryOptions& options,
                    QueryCache& cache) {
  if (!is_valid_pose(pa)) require_valid_pose(pa, "collide", "the pose of model A");
  if (!is_valid_pose(pb)) require_valid_pose(pb, "collide", "the pose of model B");
  if (options.descend != DescendRule::larger_volume)
    return collide(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb, with_closedness(a, b, options), cache);
  QueryCache::State& st = cache.state();
  st.bind_witness(a.tree(), b.tree());
  const bool first = options.mode == QueryMode::first_hit;
  return on_models(a, pa, b, pb, options, [&](const Pose& rel, const QueryOptions& o) {
    if (first && st.witness && st.witness->a < a.mesh().triangles.size() &&
        st.witness->b < b.mesh().triangles.size()) {
      const Triangle& ta = a.mesh().triangles[st.witness->a];
      const Triangle& tb = b.mesh().triangles[st.witness->b];
      const Vec3 q0 = query_detail::map_point(rel, b.mesh().vertices[tb[0]]);
      const Vec3 q1 = query_detail::map_point(rel, b.mesh().vertices[tb[1]]);
      const Vec3 q2 = query_detail::map_point(rel, b.mesh().vertices[tb[2]]);
      const Vec3& p0 = a.mesh().vertices[ta[0]];
      const Vec3& p1 = a.mesh().vertices[ta[1]];
      const Vec3& p2 = a.mesh().vertices[ta[2]];
      const bool touch = o.margin > 0.0 ? query_detail::within_margin(p0, p1, p2, q0, q1, q2, o.margin)
                                        : tri_tri_overlap(p0, p1, p2, q0, q1, q2);
      if (touch) {
        QueryResult result;
        result.hit = true;
        result.pairs.push_back(*st.witness);
        result.stats.triangle_tests = 1;
        return result;
      }
    }
    QueryResult result = query_detail::collide_wide(a.tree(), query_detail::wide_of(a), a.mesh(), b.tree(),
                                                    query_detail::wide_of(b), b.mesh(), rel, o.mode, o.margin);
    if (first) {
      if (result.hit && !result.pairs.empty())
        st.witness = result.pairs.front();
      else
        st.witness.reset();
    }
    return result;
  });
}

// The wide descent recorded: its wide trees built again with the Tree node of every lane (the
// same trees as the model's: build_wide is deterministic), each test named by those nodes.
CollideTrace collide_trace(const Model& a, const Pose& pa, const Model& b, const Pose& pb, const QueryOptions& options,
                           const CollideTraceOptions& trace_options) {
  if (!is_valid_pose(pa)) require_valid_pose(pa, "collide_trace", "the pose of model A");
  if (!is_valid_pose(pb)) require_valid_pose(pb, "collide_trace", "the pose of model B");
  if (options.descend != DescendRule::larger_volume)
    return collide_trace(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb, with_closedness(a, b, options),
                         trace_options);
  std::vector<std::uint32_t> sources_a, sources_b;
  const query_detail::WideTree wa = query_detail::build_wide(a.tree(), &sources_a);
  const query_detail::WideTree wb = query_detail::build_wide(b.tree(), &sources_b);
  query_detail::WideTraceSink sink;
  CollideTrace trace;
  trace.result = on_models(a, pa, b, pb, options, [&](const Pose& rel, const QueryOptions& o) {
    return query_detail::collide_wide_traced(a.tree(), wa, a.mesh(), b.tree(), wb, b.mesh(), rel, o.mode, o.margin,
                                             sink);
  });
  const std::vector<std::uint32_t> depth_a = query_detail::node_depths(a.tree());
  const std::vector<std::uint32_t> depth_b = query_detail::node_depths(b.tree());
  using Sink = query_detail::WideTraceSink;
  for (const Sink::Test& t : sink.tests) {
    const std::uint32_t ia = t.a_node == Sink::kRoot ? 0 : sources_a[t.a_node * query_detail::kWideLanes + t.a_lane];
    const std::uint32_t ib = t.b_node == Sink::kRoot ? 0 : sources_b[t.b_node * query_detail::kWideLanes + t.b_lane];
    const std::uint32_t level = depth_a[ia] + depth_b[ib];
    if (trace.per_level.size() <= level) trace.per_level.resize(level + 1, {});
    ++trace.per_level[level][static_cast<std::size_t>(t.outcome)];
    ++trace.visited;
    if (trace.pairs.size() < trace_options.max_pairs) trace.pairs.push_back({ia, ib, level, t.outcome});
  }
  return trace;
}

DistanceResult distance(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                        const DistanceOptions& options) {
  QueryWorkspace workspace;
  return distance(a, pa, b, pb, options, workspace);
}

// The binary trees' search; signed_distance's vertices classified through the wide nodes.
DistanceResult distance(const Model& a, const Pose& pa, const Model& b, const Pose& pb,
                        const DistanceOptions& options, QueryWorkspace& workspace) {
  return query_detail::distance_models(a.tree(), query_detail::wide_of(a), a.mesh(), pa, b.tree(),
                                       query_detail::wide_of(b), b.mesh(), pb, with_closedness(a, b, options), workspace);
}

}  // namespace tightbvh
