#include "tightbvh/fcl/export.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>

#include <fcl/geometry/bvh/detail/BV_fitter.h>
#include <fcl/geometry/bvh/detail/BV_splitter.h>

#include "tightbvh/tree_walk.hpp"
#include "tightbvh/validate_tree.hpp"
#include "tree/splitter.hpp"

namespace tightbvh {
namespace {

// The FCL tree to produce, in the order FCL's builder visits it: preorder (node, left subtree,
// right subtree). Every subtree owns a contiguous range of `order`.
struct PlanNode {
  Obb box;
  std::uint32_t first = 0, count = 0;  // range of `order`
  std::uint32_t left_count = 0;        // internal nodes: triangles of the left child
};

struct Plan {
  std::vector<std::uint32_t> order;     // triangle indices
  std::vector<std::uint32_t> position;  // position[triangle] = its index in `order`
  std::vector<PlanNode> nodes;
};

class Planner {
 public:
  Planner(const Tree& tree, const Mesh& mesh, const FitOptions& fit) : tree_(tree), mesh_(mesh), fit_(fit) {}

  Plan run() {
    check();
    // A sound tree's leaves tile triangle_order in preorder: FCL's order is the tree's.
    plan_.order = tree_.triangle_order;
    plan_.nodes.reserve(2 * mesh_.triangles.size());
    const std::vector<TriangleRange> ranges = triangle_ranges(tree_);
    for_each_node(tree_, [&](const NodeVisit& v) {
      const TriangleRange& r = ranges[v.index];
      if (v.node.is_leaf()) return split_leaf(v.node.box.obb(), std::uint32_t(r.begin), std::uint32_t(r.size()));
      plan_.nodes.push_back({v.node.box.obb(), std::uint32_t(r.begin), std::uint32_t(r.size()),
                             std::uint32_t(ranges[v.node.first].size())});
    });
    plan_.position.assign(mesh_.triangles.size(), 0);
    for (std::uint32_t i = 0; i < plan_.order.size(); ++i) plan_.position[plan_.order[i]] = i;
    return std::move(plan_);
  }

 private:
  void fail(const std::string& what) const { throw InputError("to_fcl: tree does not fit the mesh: " + what); }

  // The library's structural check, plus one triangle_order entry per mesh triangle.
  void check() const {
    const TreeCheck structure = check_structure(tree_);
    if (!structure.ok()) fail(structure.errors[0]);
    if (mesh_.triangles.empty()) fail("mesh has no triangles");
    if (tree_.triangle_order.size() != mesh_.triangles.size())
      fail(std::to_string(tree_.triangle_order.size()) + " of " + std::to_string(mesh_.triangles.size()) +
           " triangles in leaves");
  }

  // Below one of our leaves: the library's median split (longest box axis, ties by triangle
  // index) down to single triangles, every new box fitted by our fitter.
  void split_leaf(const Obb& box, std::uint32_t first, std::uint32_t count) {
    triangle_corners(mesh_, std::span(plan_.order).subspan(first, count), corners_);
    leaf_first_ = first;
    split_node(box, first, count);
  }

  // corners_ holds the leaf's corners in lockstep with plan_.order (the splitter permutes both).
  void split_node(const Obb& box, std::uint32_t first, std::uint32_t count) {
    const std::size_t self = plan_.nodes.size();
    plan_.nodes.push_back({box, first, count, 0});
    if (count == 1) return;
    const auto order = std::span(plan_.order).subspan(first, count);
    const auto corners = std::span(corners_).subspan(3 * std::size_t{first - leaf_first_}, 3 * std::size_t{count});
    const auto half = std::uint32_t(detail::split(SplitMethod::median, order, corners, {}, box, scratch_));
    plan_.nodes[self].left_count = half;
    const Obb left = fit_triangles(corners.first(3 * std::size_t{half}), fit_);
    const Obb right = fit_triangles(corners.subspan(3 * std::size_t{half}), fit_);
    split_node(left, first, half);
    split_node(right, first + half, count - half);
  }

  const Tree& tree_;
  const Mesh& mesh_;
  FitOptions fit_;
  Plan plan_;
  std::vector<Vec3> corners_;  // of the leaf being split
  std::uint32_t leaf_first_ = 0;
  detail::SplitScratch scratch_;
};

// FCL's builder asks its fitter for each node's box, then its splitter for the partition, in
// preorder. These two replay the plan: the fitter hands out our boxes (checking that FCL's
// node holds exactly the plan node's triangles), the splitter sends each triangle to the
// side our tree puts it on. Errors are recorded, not thrown through FCL's builder.
struct Replay {
  const Plan* plan = nullptr;
  std::size_t next = 0, current = 0;
  std::string error;
};

template <class BV>
class ReplayFitter final : public fcl::detail::BVFitterBase<BV> {
 public:
  ReplayFitter(Replay& replay, const std::vector<BV>& bvs) : r_(replay), bvs_(bvs) {}
  void set(fcl::Vector3<double>*, fcl::Triangle*, fcl::BVHModelType) override {}
  void set(fcl::Vector3<double>*, fcl::Vector3<double>*, fcl::Triangle*, fcl::BVHModelType) override {}
  void clear() override {}
  BV fit(unsigned int* primitives, int count) override {
    if (r_.next >= r_.plan->nodes.size()) {
      if (r_.error.empty()) r_.error = "FCL asked for more nodes than planned";
      return BV();
    }
    r_.current = r_.next++;
    const PlanNode& node = r_.plan->nodes[r_.current];
    bool same = std::uint32_t(count) == node.count;
    for (int i = 0; same && i < count; ++i) {
      const std::uint32_t pos = r_.plan->position[primitives[i]];
      same = pos >= node.first && pos < node.first + node.count;
    }
    if (!same && r_.error.empty()) r_.error = "FCL node " + std::to_string(r_.current) + " differs from the plan";
    return bvs_[r_.current];
  }

 private:
  Replay& r_;
  const std::vector<BV>& bvs_;
};

template <class BV>
class ReplaySplitter final : public fcl::detail::BVSplitterBase<BV> {
 public:
  explicit ReplaySplitter(Replay& replay) : r_(replay) {}
  void set(fcl::Vector3<double>*, fcl::Triangle*, fcl::BVHModelType) override {}
  void clear() override {}
  // FCL then calls apply() once per primitive, in the order of `primitives` as given here
  // (its partition loop only swaps already-visited entries), with the primitive's centroid.
  void computeRule(const BV&, unsigned int* primitives, int count) override {
    pending_.assign(primitives, primitives + count);
    cursor_ = 0;
    const PlanNode& node = r_.plan->nodes[r_.current];
    boundary_ = node.first + node.left_count;
  }
  bool apply(const fcl::Vector3<double>&) const override {
    if (cursor_ >= pending_.size()) return false;
    return r_.plan->position[pending_[cursor_++]] >= boundary_;  // true = right child
  }

 private:
  Replay& r_;
  std::vector<unsigned int> pending_;
  mutable std::size_t cursor_ = 0;
  std::uint32_t boundary_ = 0;
};

// Walks FCL's finished tree against the plan: same shape, same leaves.
template <class BV>
void verify(const fcl::BVHModel<BV>& model, const Plan& plan) {
  const auto n = int(plan.order.size());
  if (model.getNumBVs() != 2 * n - 1)
    throw std::logic_error("to_fcl: FCL built " + std::to_string(model.getNumBVs()) + " nodes, expected " +
                           std::to_string(2 * n - 1));
  std::size_t k = 0;
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    const auto& bv = model.getBV(i);
    const PlanNode& p = plan.nodes[k++];
    if (bv.num_primitives != int(p.count) || bv.isLeaf() != (p.count == 1) ||
        (bv.isLeaf() && bv.primitiveId() != int(plan.order[p.first])))
      throw std::logic_error("to_fcl: FCL node " + std::to_string(i) + " differs from the plan");
    if (!bv.isLeaf()) {
      stack.push_back(bv.rightChild());
      stack.push_back(bv.leftChild());
    }
  }
}

template <class BV>
std::shared_ptr<fcl::BVHModel<BV>> export_model(const Mesh& mesh, const Plan& plan, const std::vector<BV>& bvs) {
  auto model = std::make_shared<fcl::BVHModel<BV>>();
  Replay replay;
  replay.plan = &plan;
  model->bv_fitter = std::make_shared<ReplayFitter<BV>>(replay, bvs);
  model->bv_splitter = std::make_shared<ReplaySplitter<BV>>(replay);
  std::vector<fcl::Vector3<double>> vertices(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  if (model->beginModel(int(triangles.size()), int(vertices.size())) != fcl::BVH_OK ||
      model->addSubModel(vertices, triangles) != fcl::BVH_OK || model->endModel() != fcl::BVH_OK)
    throw std::runtime_error("to_fcl: FCL refused the model");
  // Back to FCL's defaults: later refits by the user then behave as for any FCL model.
  model->bv_fitter = std::make_shared<fcl::detail::BVFitter<BV>>();
  model->bv_splitter = std::make_shared<fcl::detail::BVSplitter<BV>>(fcl::detail::SPLIT_METHOD_MEAN);
  if (!replay.error.empty()) throw std::logic_error("to_fcl: " + replay.error);
  if (replay.next != plan.nodes.size()) throw std::logic_error("to_fcl: FCL visited fewer nodes than planned");
  verify(*model, plan);
  model->computeLocalAABB();
  return model;
}

}  // namespace

fcl::OBB<double> to_fcl_obb(const Obb& box) {
  std::array<int, 3> perm{0, 1, 2};
  std::stable_sort(perm.begin(), perm.end(), [&](int l, int r) { return box.half_extents[l] > box.half_extents[r]; });
  fcl::OBB<double> out;
  for (int j = 0; j < 3; ++j) {
    out.axis.col(j) = box.axes.col(perm[j]);
    out.extent[j] = box.half_extents[perm[j]];
  }
  if (out.axis.determinant() < 0) out.axis.col(2) = -out.axis.col(2);  // keep it a rotation
  out.To = box.center;
  return out;
}

fcl::RSS<double> fit_rss(const Obb& box, std::span<const Vec3> points) {
  // FCL's RSS is a rectangle in a rotation frame: orthonormalise the box's axes (a tree's float
  // axes are orthonormal only to about 1e-7, compact_box.hpp) and measure the points in it.
  if (points.empty()) throw InputError("fit_rss: an RSS needs at least one point");
  const fcl::OBB<double> obb = to_fcl_obb(box);
  Mat3 axes;
  axes.col(0) = obb.axis.col(0).normalized();
  axes.col(1) = (obb.axis.col(1) - axes.col(0).dot(obb.axis.col(1)) * axes.col(0)).normalized();
  axes.col(2) = axes.col(0).cross(axes.col(1));
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : points) {
    const Vec3 q = axes.transpose() * (p - obb.To);
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  const Vec3 center = obb.To + axes * (0.5 * (lo + hi));
  std::vector<Vec3> local;
  local.reserve(points.size());
  for (const Vec3& p : points) local.push_back(axes.transpose() * (p - center));
  const double h0 = 0.5 * (hi[0] - lo[0]), h1 = 0.5 * (hi[1] - lo[1]), h2 = 0.5 * (hi[2] - lo[2]);
  const double pi = 3.14159265358979323846;
  fcl::RSS<double> best;
  double best_volume = std::numeric_limits<double>::infinity();
  // Shrinking the rectangle by d lets the corners be covered by the sphere sweep.
  for (double f : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double d = std::min(f * h2, std::min(h0, h1));
    const double a = h0 - d, b = h1 - d;  // rectangle half sizes
    double r2 = 0;
    for (const Vec3& q : local) {
      const double dx = std::max(std::abs(q.x()) - a, 0.0), dy = std::max(std::abs(q.y()) - b, 0.0);
      r2 = std::max(r2, dx * dx + dy * dy + q.z() * q.z());
    }
    const double r = std::sqrt(r2);
    // Steiner: volume of a flat rectangle swept by a ball.
    const double volume = 2 * r * (4 * a * b) + 0.5 * pi * (4 * (a + b)) * r * r + 4.0 / 3.0 * pi * r * r * r;
    if (volume < best_volume) {
      best_volume = volume;
      best.axis = axes;
      best.To = center + axes * Vec3(-a, -b, 0);
      best.l[0] = 2 * a;
      best.l[1] = 2 * b;
      best.r = r;
    }
  }
  return best;
}

std::shared_ptr<fcl::BVHModel<fcl::OBB<double>>> to_fcl(const Tree& tree, const Mesh& mesh,
                                                        const FclExportOptions& options) {
  const Plan plan = Planner(tree, mesh, options.fit).run();
  std::vector<fcl::OBB<double>> bvs;
  bvs.reserve(plan.nodes.size());
  for (const PlanNode& n : plan.nodes) bvs.push_back(to_fcl_obb(n.box));
  return export_model(mesh, plan, bvs);
}

namespace {

// Every plan node's RSS, fitted to its box and its triangles' corners.
std::vector<fcl::RSS<double>> plan_rss(const Plan& plan, const Mesh& mesh) {
  std::vector<fcl::RSS<double>> out;
  out.reserve(plan.nodes.size());
  std::vector<Vec3> corners;
  for (const PlanNode& n : plan.nodes) {
    triangle_corners(mesh, std::span(plan.order).subspan(n.first, n.count), corners);
    out.push_back(fit_rss(n.box, corners));
  }
  return out;
}

}  // namespace

std::shared_ptr<fcl::BVHModel<fcl::OBBRSS<double>>> to_fcl_obbrss(const Tree& tree, const Mesh& mesh,
                                                                  const FclExportOptions& options) {
  const Plan plan = Planner(tree, mesh, options.fit).run();
  const std::vector<fcl::RSS<double>> rss = plan_rss(plan, mesh);
  std::vector<fcl::OBBRSS<double>> bvs(plan.nodes.size());
  for (std::size_t i = 0; i < bvs.size(); ++i) {
    bvs[i].obb = to_fcl_obb(plan.nodes[i].box);
    bvs[i].rss = rss[i];
  }
  return export_model(mesh, plan, bvs);
}

std::shared_ptr<fcl::BVHModel<fcl::RSS<double>>> to_fcl_rss(const Tree& tree, const Mesh& mesh,
                                                            const FclExportOptions& options) {
  const Plan plan = Planner(tree, mesh, options.fit).run();
  return export_model(mesh, plan, plan_rss(plan, mesh));
}

}  // namespace tightbvh
