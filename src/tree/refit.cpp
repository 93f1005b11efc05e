#include "tightbvh/refit.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <sstream>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "../fit/pca.hpp"
#include "parallel.hpp"
#include "node_fit.hpp"

namespace tightbvh {
namespace {

using Index = std::uint32_t;
constexpr Index kNoSlot = std::numeric_limits<Index>::max();

// The positions [begin, end) of triangle_order under a node.
struct Range {
  Index begin = 0;
  Index end = 0;
  [[nodiscard]] Index size() const { return end - begin; }
};

template <class... Parts>
[[noreturn]] void fail(const Parts&... parts) {
  std::ostringstream out;
  out << "refit: ";
  (out << ... << parts);
  throw InputError(out.str());
}

// ------------------------------------------------------------------ the tree's layout

// Every node's range, and the split of the work: subtrees of at most `grain` triangles are one task
// each; the nodes above them ("top" nodes) are fitted level by level, deepest first.
struct Layout {
  std::vector<Range> ranges;                   // per node
  std::vector<Index> tasks;                    // subtree roots, largest first
  std::vector<std::vector<Index>> top_levels;  // top nodes by depth, the root's level first
};

// Nodes in preorder from the root, each reached once; throws on a child out of range or a node
// reached twice (a cycle or a shared child).
std::vector<Index> preorder(const Tree& tree) {
  const auto& nodes = tree.nodes;
  if (nodes.empty()) fail("the tree has no nodes");
  if (nodes.size() > std::numeric_limits<Index>::max()) fail("the tree has too many nodes (", nodes.size(), ")");
  std::vector<char> seen(nodes.size(), 0);
  std::vector<Index> order, stack{0};
  order.reserve(nodes.size());
  seen[0] = 1;
  while (!stack.empty()) {
    const Index i = stack.back();
    stack.pop_back();
    order.push_back(i);
    const Node& node = nodes[i];
    if (node.is_leaf()) continue;
    if (std::uint64_t{node.first} + 1 >= nodes.size())
      fail("node ", i, ": children ", node.first, ", ", std::uint64_t{node.first} + 1, " out of range (", nodes.size(),
           " nodes)");
    for (const Index child : {node.first + 1, node.first}) {
      if (seen[child]++) fail("node ", child, " is reached twice (cycle or shared child), again from node ", i);
      stack.push_back(child);
    }
  }
  return order;
}

// Ranges bottom up (reverse preorder: children before parents); checks that leaves stay inside
// triangle_order, that siblings' ranges are adjacent and that the root covers all triangles.
std::vector<Range> node_ranges(const Tree& tree, const std::vector<Index>& order) {
  const auto& nodes = tree.nodes;
  const std::size_t n = tree.triangle_order.size();
  std::vector<Range> ranges(nodes.size());
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const Node& node = nodes[*it];
    if (node.is_leaf()) {
      if (std::uint64_t{node.first} + node.count > n)
        fail("node ", *it, ": leaf range [", node.first, ", ", std::uint64_t{node.first} + node.count,
             ") exceeds triangle_order (", n, " entries)");
      ranges[*it] = {node.first, node.first + node.count};
      continue;
    }
    const Range left = ranges[node.first], right = ranges[node.first + 1];
    if (left.end != right.begin)
      fail("node ", *it, ": the children's triangle ranges [", left.begin, ", ", left.end, ") and [", right.begin, ", ",
           right.end, ") are not adjacent");
    ranges[*it] = {left.begin, right.end};
  }
  return ranges;
}

// The fast case: trees from build() number children after their parent. Then one backward pass
// gives every range, and "every node but the root is the child of exactly one node" (checked) rules
// out cycles and orphans. nullopt when the tree is not of that kind or is broken: the general walk
// above then finds the error and names it.
std::optional<std::vector<Range>> ranges_if_children_follow_parents(const Tree& tree) {
  // One backward pass: the node array is large (128 bytes a node) and reading it is most of the
  // cost here.
  const auto& nodes = tree.nodes;
  const std::size_t n = tree.triangle_order.size();
  if (nodes.empty() || nodes.size() > std::numeric_limits<Index>::max()) return std::nullopt;
  std::vector<char> has_parent(nodes.size(), 0);
  std::vector<Range> ranges(nodes.size());
  for (std::size_t i = nodes.size(); i-- > 0;) {
    const Node& node = nodes[i];
    if (node.is_leaf()) {
      if (std::uint64_t{node.first} + node.count > n) return std::nullopt;
      ranges[i] = {node.first, node.first + node.count};
      continue;
    }
    if (node.first <= i || std::uint64_t{node.first} + 1 >= nodes.size()) return std::nullopt;
    if (has_parent[node.first]++ || has_parent[node.first + 1]++) return std::nullopt;
    const Range left = ranges[node.first], right = ranges[node.first + 1];
    if (left.end != right.begin) return std::nullopt;
    ranges[i] = {left.begin, right.end};
  }
  if (std::count(has_parent.begin() + 1, has_parent.end(), 1) != static_cast<std::ptrdiff_t>(nodes.size() - 1))
    return std::nullopt;
  return ranges;
}

// Subtrees at most this large are one task. It depends on the triangle count only, never on the
// thread count (as the builder's task grain), though here any split gives the same boxes.
[[nodiscard]] Index task_grain(std::size_t triangles) {
  return static_cast<Index>(std::max<std::size_t>(1024, triangles / 128));
}

Layout layout_of(const Tree& tree, const Mesh& mesh) {
  const std::size_t n = mesh.triangles.size();
  if (tree.triangle_order.size() != n)
    fail("the tree has ", tree.triangle_order.size(), " triangles, the mesh ", n,
         " (refit needs the mesh the tree was built on, with moved vertices)");
  std::vector<char> seen(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Index t = tree.triangle_order[i];
    if (t >= n) fail("triangle_order[", i, "] = ", t, " is out of range (", n, " triangles)");
    if (seen[t]++) fail("triangle ", t, " appears more than once in triangle_order (again at ", i, ")");
  }
  Layout layout;
  if (auto ranges = ranges_if_children_follow_parents(tree))
    layout.ranges = std::move(*ranges);
  else
    layout.ranges = node_ranges(tree, preorder(tree));
  if (const Range root = layout.ranges[0]; root.begin != 0 || root.end != n)
    fail("the root covers [", root.begin, ", ", root.end, ") of ", n, " triangles");
  const Index grain = task_grain(n);
  std::vector<Index> level{0};
  while (!level.empty()) {
    std::vector<Index> top, next;
    for (const Index i : level) {
      const Node& node = tree.nodes[i];
      if (node.is_leaf() || layout.ranges[i].size() <= grain) {
        layout.tasks.push_back(i);
        continue;
      }
      top.push_back(i);
      next.push_back(node.first);
      next.push_back(node.first + 1);
    }
    if (!top.empty()) layout.top_levels.push_back(std::move(top));
    level = std::move(next);
  }
  std::stable_sort(layout.tasks.begin(), layout.tasks.end(),
                   [&](Index a, Index b) { return layout.ranges[a].size() > layout.ranges[b].size(); });
  return layout;
}

// ------------------------------------------------------------------ the fast pca path

// The sums pca_triangle_axes and pca_vertex_axes (src/fit/pca.cpp) accumulate, relative to
// `origin`: for the triangles of positive area, A = sum(area), first = sum(area (p + q + r)),
// second = sum(area / 12 (s s^T + p p^T + q q^T + r r^T)) with s = p + q + r (Gottschalk's thesis,
// eq. 3.5 ff.); for pca-vertex, the corners' count, sum and sum of outer products. Sums are
// additive: a node's moments are its children's, shifted to its origin, which makes a node's axes
// O(1) instead of O(triangles). A symmetric 3x3 matrix by its six entries: the sums below are all
// symmetric.
struct Sym {
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  void add_outer(const Vec3& v, double w) {  // += w v v^T
    xx += w * v.x() * v.x(), xy += w * v.x() * v.y(), xz += w * v.x() * v.z();
    yy += w * v.y() * v.y(), yz += w * v.y() * v.z(), zz += w * v.z() * v.z();
  }
  void add_symmetric(const Vec3& a, const Vec3& b, double w) {  // += w (a b^T + b a^T)
    xx += 2 * w * a.x() * b.x(), yy += 2 * w * a.y() * b.y(), zz += 2 * w * a.z() * b.z();
    xy += w * (a.x() * b.y() + b.x() * a.y()), xz += w * (a.x() * b.z() + b.x() * a.z());
    yz += w * (a.y() * b.z() + b.y() * a.z());
  }
  void add(const Sym& o) { xx += o.xx, xy += o.xy, xz += o.xz, yy += o.yy, yz += o.yz, zz += o.zz; }
  [[nodiscard]] Mat3 matrix() const {
    Mat3 m;
    m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return m;
  }
};

// pca's sums (Gottschalk's continuous covariance): fit_detail::AreaMoments, the builder's.
struct AreaMoments {
  fit_detail::AreaMoments sums;

  [[nodiscard]] const Vec3& origin() const { return sums.origin; }
  static AreaMoments of(std::span<const Vec3> corners) { return {fit_detail::area_moments(corners, corners.front())}; }
  // The left child's origin is the parent's (both start at the range's first corner).
  void add(const AreaMoments& other) { sums = sums.plus(other.sums); }
  [[nodiscard]] Mat3 covariance() const { return sums.covariance(); }
  // Zero total area: pca_triangle_axes falls back to the corners' covariance.
  [[nodiscard]] bool degenerate() const { return !(sums.area > 0.0); }
};

// pca-vertex's sums: the corners' count, sum and sum of outer products, relative to `origin`.
struct CornerMoments {
  Vec3 origin_ = Vec3::Zero();
  double corners = 0.0;
  Vec3 sum = Vec3::Zero();
  Sym second;

  [[nodiscard]] const Vec3& origin() const { return origin_; }
  static CornerMoments of(std::span<const Vec3> points) {
    CornerMoments m;
    m.origin_ = points.front();
    for (const Vec3& x : points) {
      const Vec3 p = x - m.origin_;
      m.corners += 1.0;
      m.sum += p;
      m.second.add_outer(p, 1.0);
    }
    return m;
  }

  void add(const CornerMoments& other) {
    const Vec3 e = other.origin_ - origin_;
    second.add(other.second);
    second.add_symmetric(e, other.sum, 1.0);
    second.add_outer(e, other.corners);
    sum += other.sum + other.corners * e;
    corners += other.corners;
  }

  [[nodiscard]] Mat3 covariance() const {
    const Vec3 mean = sum / corners;
    return second.matrix() / corners - mean * mean.transpose();
  }
  [[nodiscard]] static bool degenerate() { return false; }
};

struct NoScratch {};  // the pca and aabb kernels need none

// pca (AreaMoments) / pca-vertex (CornerMoments): moments bottom up, extents from the node's own
// corners.
template <class Moments>
class PcaKernel {
 public:
  using Value = Moments;
  using Scratch = NoScratch;

  explicit PcaKernel(std::span<const Vec3> corners) : corners_(corners) {}

  Value leaf(Node& node, Range range, Scratch& /*scratch*/) const {
    const Moments m = Moments::of(node_corners(range));
    const std::optional<Obb> triangle = range.size() == 1 ? single(range.begin) : std::nullopt;
    node.box = triangle ? compact_box(*triangle, node_corners(range)) : box(m, range, node.box);
    return m;
  }

  // The left child's origin is the parent's (both start at range.begin): only the right one moves.
  Value internal(Node& node, Range range, Value left, const Value& right, Scratch& /*scratch*/) const {
    left.add(right);
    node.box = box(left, range, node.box);
    return left;
  }

 private:
  [[nodiscard]] std::optional<Obb> single(std::size_t p) const {
    return detail::triangle_box({corners_[3 * p], corners_[3 * p + 1], corners_[3 * p + 2]});
  }

  [[nodiscard]] std::span<const Vec3> node_corners(Range range) const {
    return corners_.subspan(3 * std::size_t{range.begin}, 3 * std::size_t{range.size()});
  }

  // The eigenvectors start from the node's box before the refit (`previous`): after a frame's
  // deformation they nearly diagonalise its new covariance (principal_axes_from). The extents are
  // measured once, in the stored float frame (compact_box_with_axes).
  [[nodiscard]] CompactBox box(const Moments& m, Range range, const CompactBox& previous) const {
    const auto corners = node_corners(range);
    // Zero total area (rare): computed from the node's corners rather than carried up the tree.
    const Mat3 axes = m.degenerate() ? fit_detail::pca_vertex_axes(corners, m.origin())
                                     : fit_detail::principal_axes_from(m.covariance(), previous.axes_d());
    return compact_box_with_axes(corners, axes);
  }

  std::span<const Vec3> corners_;
};

// ------------------------------------------------------------------ the fast aabb path

// aabb: the bounds of a node are the union of its children's, exactly, so a node costs O(1) and
// its box is the one build() gives, bit for bit (compact_aabb).
class AabbKernel {
 public:
  using Value = Aabb;
  using Scratch = NoScratch;

  explicit AabbKernel(std::span<const Vec3> corners) : corners_(corners) {}

  Value leaf(Node& node, Range range, Scratch& /*scratch*/) const {
    const Aabb bounds = bounds_of(corners_.subspan(3 * std::size_t{range.begin}, 3 * std::size_t{range.size()}));
    node.box = compact_aabb(bounds);
    return bounds;
  }
  Value internal(Node& node, Range /*range*/, Value left, const Value& right, Scratch& /*scratch*/) const {
    left.extend(right.min), left.extend(right.max);
    node.box = compact_aabb(left);
    return left;
  }

 private:
  std::span<const Vec3> corners_;
};

// ------------------------------------------------------------------ any other fitter

struct NoValue {};

// Each node fitted from its corners with the builder's rules (node_fit.hpp).
class FitKernel {
 public:
  using Value = NoValue;
  using Scratch = FitWorkspace;

  FitKernel(std::span<const Vec3> corners, const RefitOptions& options) : corners_(corners), options_(options) {}

  Value leaf(Node& node, Range range, Scratch& scratch) const {
    node.box = fit(range, scratch);
    return {};
  }
  Value internal(Node& node, Range range, Value /*left*/, const Value& /*right*/, Scratch& scratch) const {
    node.box = fit(range, scratch);
    return {};
  }

 private:
  [[nodiscard]] CompactBox fit(Range range, FitWorkspace& workspace) const {
    const auto corners = corners_.subspan(3 * std::size_t{range.begin}, 3 * std::size_t{range.size()});
    const Obb fitted =
        detail::fit_node(corners, corners_.size() / 3, options_.fitter, options_.fit, workspace,
                         [] { return std::span<const Vec3>{}; });
    return compact_box(fitted, corners);
  }

  std::span<const Vec3> corners_;
  const RefitOptions& options_;
};

// ------------------------------------------------------------------ the walk

template <class Kernel>
struct Worker {
  typename Kernel::Scratch scratch;
  std::vector<std::pair<Index, bool>> stack;  // (node, children done)
  std::vector<typename Kernel::Value> values;
};

// Fits the subtree under `root` children first (an explicit stack: RAPID trees can be deep);
// returns the root's value.
template <class Kernel>
typename Kernel::Value fit_subtree(const Kernel& kernel, Index root, const Layout& layout, Tree& tree,
                                   Worker<Kernel>& w) {
  w.stack.assign(1, {root, false});
  w.values.clear();
  while (!w.stack.empty()) {
    const auto [i, children_done] = w.stack.back();
    w.stack.pop_back();
    Node& node = tree.nodes[i];
    if (node.is_leaf()) {
      w.values.push_back(kernel.leaf(node, layout.ranges[i], w.scratch));
    } else if (!children_done) {
      w.stack.push_back({i, true});
      w.stack.push_back({node.first + 1, false});
      w.stack.push_back({node.first, false});
    } else {
      typename Kernel::Value right = std::move(w.values.back());
      w.values.pop_back();
      w.values.back() = kernel.internal(node, layout.ranges[i], std::move(w.values.back()), right, w.scratch);
    }
  }
  return std::move(w.values.back());
}

template <class Kernel>
void refit_with(const Kernel& kernel, const Layout& layout, unsigned threads, Tree& tree) {
  using Value = typename Kernel::Value;
  detail::WorkerPool<Worker<Kernel>> pool(threads);
  // The values of the task roots and the top nodes, by slot.
  std::vector<Index> slot(tree.nodes.size(), kNoSlot);
  Index slots = 0;
  for (const Index i : layout.tasks) slot[i] = slots++;
  for (const auto& level : layout.top_levels)
    for (const Index i : level) slot[i] = slots++;
  std::vector<Value> values(slots);
  pool.run(layout.tasks.size(), [&](std::size_t k, Worker<Kernel>& w) {
    const Index root = layout.tasks[k];
    values[slot[root]] = fit_subtree(kernel, root, layout, tree, w);
  });
  for (auto level = layout.top_levels.rbegin(); level != layout.top_levels.rend(); ++level) {
    pool.run(level->size(), [&](std::size_t k, Worker<Kernel>& w) {
      const Index i = (*level)[k];
      Node& node = tree.nodes[i];
      values[slot[i]] =
          kernel.internal(node, layout.ranges[i], values[slot[node.first]], values[slot[node.first + 1]], w.scratch);
    });
  }
}

// Corners in triangle_order's order: position p holds triangle triangle_order[p], so every node's
// corners are one contiguous span (as in the builder).
std::vector<Vec3> ordered_corners(const Tree& tree, const Mesh& mesh) {
  std::vector<Vec3> corners(3 * tree.triangle_order.size());
  for (std::size_t p = 0; p < tree.triangle_order.size(); ++p) {
    const Triangle& t = mesh.triangles[tree.triangle_order[p]];
    for (int k = 0; k < 3; ++k) corners[3 * p + k] = mesh.vertices[t[k]];
  }
  return corners;
}

}  // namespace

void refit(Tree& tree, const Mesh& mesh, const RefitOptions& options) {
  require_valid_mesh(mesh, "refit: mesh");
  const Layout layout = layout_of(tree, mesh);
  const std::vector<Vec3> corners = ordered_corners(tree, mesh);
  const unsigned threads = options.threads != 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  const auto* method = std::get_if<FitMethod>(&options.fitter);
  if (method && *method == FitMethod::pca)
    refit_with(PcaKernel<AreaMoments>(corners), layout, threads, tree);
  else if (method && *method == FitMethod::pca_vertex)
    refit_with(PcaKernel<CornerMoments>(corners), layout, threads, tree);
  else if (method && *method == FitMethod::aabb)
    refit_with(AabbKernel(corners), layout, threads, tree);
  else
    refit_with(FitKernel(corners, options), layout, threads, tree);
}

Tree refitted(const Tree& tree, const Mesh& mesh, const RefitOptions& options) {
  Tree out = tree;
  refit(out, mesh, options);
  return out;
}

}  // namespace tightbvh
