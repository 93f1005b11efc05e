#include "tightbvh/build.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "../fit/pca.hpp"
#include "huge_pages.hpp"
#include "parallel.hpp"
#include "splitter.hpp"
#include "node_fit.hpp"

namespace tightbvh {

std::optional<Fitter> parse_fitter(std::string_view name) {
  if (name == "auto") return Fitter{AutoFit{}};
  if (const auto method = parse_fit_method(name)) return Fitter{*method};
  return std::nullopt;
}

std::string to_string(const Fitter& fitter) {
  if (const auto* method = std::get_if<FitMethod>(&fitter)) return std::string(to_string(*method));
  return "auto";
}

std::vector<std::string_view> fitter_names() {
  std::vector<std::string_view> names{"auto"};
  for (const std::string_view name : fit_method_names()) names.push_back(name);
  return names;
}

namespace {

using Index = std::uint32_t;

// Whether the fitter may run `method` on some node.
[[nodiscard]] bool uses(const Fitter& fitter, FitMethod method) {
  if (const auto* m = std::get_if<FitMethod>(&fitter)) return *m == method;
  const AutoFit& a = std::get<AutoFit>(fitter);
  return a.tight == method || a.medium == method || a.cheap == method;
}

// A node's area moments (the sums of pca_triangle_axes over its triangles), when its fitter starts
// from the PCA box (approx-kernel, normal-bopt: auto's tiers below the top). Summing them costs a
// pass over the node's corners with a square root per triangle, at every level of the tree (13.5%
// of auto's instructions on 1.2M triangles), while they are additive: the builder sums them for the
// smaller child only and derives the larger child's as the parent's minus the smaller's. The
// subtraction loses about eps * (anchor / node)^2 of the node's covariance, where anchor is the
// size of the node whose moments were last summed from its triangles, so a node more than
// kMaxDerivedShrink times smaller than its anchor sums its own again (error below ~3e-14; the
// moments only choose the PCA axes, the extents are always measured over the node's points).
struct Moments {
  fit_detail::AreaMoments sums;  // relative to the node's first corner once the node is fitted
  Index anchor = 0;              // triangles of the node they were last summed over
  bool valid = false;
};
constexpr Index kMaxDerivedShrink = 16;

// Whether some node may ask for its distinct vertices (every method but pca and pca-vertex).
[[nodiscard]] bool uses_distinct_vertices(const Fitter& fitter) {
  const auto* m = std::get_if<FitMethod>(&fitter);
  return m == nullptr || (*m != FitMethod::pca && *m != FitMethod::pca_vertex);
}

// Whether some node may be fitted from its PCA box by a method that takes derived moments.
[[nodiscard]] bool uses_moments(const Fitter& fitter) {
  if (const auto* m = std::get_if<FitMethod>(&fitter)) return fit_detail::uses_pca_axes(*m);
  const AutoFit& a = std::get<AutoFit>(fitter);
  return fit_detail::uses_pca_axes(a.tight) || fit_detail::uses_pca_axes(a.medium) || fit_detail::uses_pca_axes(a.cheap);
}

// Range of triangle_order owned by a node being built.
struct Pending {
  Index node;
  Index begin;
  Index end;
  Index parent;  // kNoParent for the root
};
constexpr Index kNoParent = std::numeric_limits<Index>::max();

// Per-worker buffers, reused from node to node: no allocation per node once they have grown.
struct Scratch {
  std::vector<Pending> stack;
  std::vector<Moments> moments;  // parallel to stack, for fitters that use moments (not pca)
  FitWorkspace fit;  // hulls, projections, ... of the fitters
  detail::SplitScratch split;
  // The node's distinct vertices, found with a stamp per mesh vertex (no sorting, no hashing).
  std::vector<std::uint32_t> vertex_stamp;
  std::uint32_t stamp_epoch = 0;
  std::vector<Vec3> vertices;
};

class Builder {
 public:
  Builder(const Mesh& mesh, const BuildOptions& options, std::vector<Index>& order)
      : mesh_(mesh), options_(options), order_(order) {
    detail::reserve_huge_pages(corners_, 3 * order.size());
    triangle_corners(mesh, order, corners_);  // order is still the identity
    uses_moments_ = uses_moments(options.fitter);
    if (uses_distinct_vertices(options.fitter)) {
      detail::reserve_huge_pages(ids_, order.size());
      ids_.assign(mesh.triangles.begin(), mesh.triangles.end());
    }
  }

  // Fits the node's box; returns the split point (begin < mid < end), or `end` for a leaf.
  // `moments`: the node's, when its parent derived them (else summed here when the fitter wants
  // them); on return, the moments of the children when they could be had cheaply.
  Index process(Node& node, Index begin, Index end, Scratch& scratch, Moments& moments, Moments& left,
                Moments& right, const CompactBox* parent_box) {
    left.valid = right.valid = false;
    const Index n = end - begin;
    if (!uses_moments_ || !wants_moments(n)) {
      moments.valid = false;
    } else if (!moments.valid || (moments.anchor != n && !takes_derived_moments(n))) {
      moments.sums = fit_detail::area_moments(node_corners(begin, end), corners_[3 * std::size_t{begin}]);
      moments.anchor = n;
      moments.valid = true;
    }
    Mat3 axes;
    const bool have_axes = moments.valid && moments.sums.area > 0.0;
    if (have_axes) axes = fit_detail::principal_axes(moments.sums.covariance());
    Obb fitted;
    if (const auto* m = std::get_if<FitMethod>(&options_.fitter);
        m && (*m == FitMethod::pca || *m == FitMethod::pca_vertex) && n >= 2) {
      // pca and pca-vertex: the axes, then the float box in one pass over the corners
      // (compact_box_with_axes), where fitting in double and rounding outward took two. The split
      // then uses the float box, whose axes are the fitted ones to float rounding. The mesh was
      // checked for NaN/Inf before the build.
      const auto corners = node_corners(begin, end);
      const Mat3 pca = *m == FitMethod::pca ? fit_detail::pca_triangle_axes(corners, corners.front())
                                            : fit_detail::pca_vertex_axes(corners, corners.front());
      node.box = compact_box_with_axes(corners, pca);
      fitted = node.box.obb();
    } else {
      std::span<const Vec3> points;
      Mat3 parent_axes;
      if (parent_box != nullptr) parent_axes = parent_box->axes_d();
      fitted = fit(begin, end, scratch, points, have_axes ? &axes : nullptr, parent_box != nullptr ? &parent_axes : nullptr);
      node.box = compact_box(fitted, points);
    }
    if (n <= options_.leaf_size) {
      node.first = begin;
      node.count = n;
      return end;
    }
    const Index mid = begin + static_cast<Index>(detail::split(options_.split, std::span<Index>(order_).subspan(begin, n),
                                                    std::span<Vec3>(corners_).subspan(3 * std::size_t{begin}, 3 * std::size_t{n}),
                                                    ids_.empty() ? std::span<detail::VertexIds>{}
                                                                 : std::span<detail::VertexIds>(ids_).subspan(begin, n),
                                                    fitted, scratch.split));
    if (moments.valid) derive_children(moments, begin, mid, end, left, right);
    return mid;
  }

  // Builds the subtree of [begin, end) whose root is nodes[root] depth first, allocating child
  // pairs from nodes[next ...]; returns the end of what it used. An explicit stack: the RAPID
  // split can be very unbalanced (depth ~ n on some inputs).
  std::size_t build_subtree(Index root, Index begin, Index end, Index parent, std::span<Node> nodes, std::size_t next,
                            Scratch& scratch) {
    auto& stack = scratch.stack;
    auto& stacked = scratch.moments;  // kept only when the fitter uses moments: pca's stack stays small
    stack.assign(1, {root, begin, end, parent});
    stacked.assign(uses_moments_ ? 1 : 0, Moments{});
    Moments moments, left, right;
    while (!stack.empty()) {
      const Pending p = stack.back();
      stack.pop_back();
      if (uses_moments_) {
        moments = stacked.back();
        stacked.pop_back();
      }
      Node& node = nodes[p.node];
      const Index mid = process(node, p.begin, p.end, scratch, moments, left, right,
                                p.parent == kNoParent ? nullptr : &nodes[p.parent].box);
      if (mid != p.end) {
        node.first = static_cast<Index>(next);
        node.count = 0;
        next += 2;
        stack.push_back({node.first + 1, mid, p.end, p.node});
        stack.push_back({node.first, p.begin, mid, p.node});
        if (uses_moments_) {
          stacked.push_back(right);
          stacked.push_back(left);
        }
      }
    }
    return next;
  }

 private:
  // Whether a node of n triangles is fitted from its PCA box (not a single triangle's box).
  [[nodiscard]] bool wants_moments(Index n) const {
    const FitMethod method = detail::method_for(options_.fitter, n, order_.size());
    // auto's normal-bopt nodes below the root fall back on the parent's axes, not on PCA's.
    if (const auto* a = std::get_if<AutoFit>(&options_.fitter); a && a->search_from_parent && method == a->cheap &&
                                                                  method == FitMethod::normal_bopt)
      return false;
    return n >= 2 && fit_detail::uses_pca_axes(method);
  }

  // Whether a node of n triangles fits from derived moments (normal-bopt: the PCA box is only its
  // fallback, and axes that differ in the last bits give about the same box) or only from sums
  // over its own triangles (approx-kernel: its 49 directions are taken in the PCA frame, so axes
  // rotated by rounding can pick other extreme points and another box, and the splits below
  // follow; elephant's gain share is 0.885 with sums over its own triangles, 0.874 with derived
  // moments there).
  [[nodiscard]] bool takes_derived_moments(Index n) const {
    return detail::method_for(options_.fitter, n, order_.size()) == FitMethod::normal_bopt && wants_moments(n);
  }

  // After the split of a node with moments: the smaller child's summed over its triangles, the
  // larger child's as the node's minus those (each relative to the child's first corner).
  void derive_children(const Moments& parent, Index begin, Index mid, Index end, Moments& left, Moments& right) const {
    const bool left_smaller = mid - begin <= end - mid;
    const Index small_begin = left_smaller ? begin : mid, small_end = left_smaller ? mid : end;
    const Index large_begin = left_smaller ? mid : begin, large_end = left_smaller ? end : mid;
    Moments& small = left_smaller ? left : right;
    Moments& large = left_smaller ? right : left;
    const Index large_n = large_end - large_begin;
    if (!takes_derived_moments(large_n) || parent.anchor > kMaxDerivedShrink * large_n) return;  // each sums its own
    small.sums = fit_detail::area_moments(node_corners(small_begin, small_end), corners_[3 * std::size_t{small_begin}]);
    small.anchor = small_end - small_begin;
    small.valid = wants_moments(small.anchor);
    large.sums = parent.sums.without(small.sums, corners_[3 * std::size_t{large_begin}]);
    large.anchor = parent.anchor;
    large.valid = true;
  }

  // The distinct mesh vertices of the node's triangles (positions [begin, end) of order_).
  std::span<const Vec3> node_vertices(Index begin, Index end, Scratch& scratch) const {
    auto& stamp = scratch.vertex_stamp;
    if (stamp.size() != mesh_.vertices.size() || ++scratch.stamp_epoch == 0) {
      stamp.assign(mesh_.vertices.size(), 0);
      scratch.stamp_epoch = 1;
    }
    // The vertex indices from the position-indexed copy (contiguous, where mesh_.triangles[order_[p]]
    // costs a cache miss per triangle on large meshes), the positions from the node's own corners
    // (just read by the fitter), and no branch: every corner is written and counted when new
    // (whether a vertex was seen is unpredictable, ~1 corner in 3 to 6 is new). The same vertices
    // in the same order as a push_back of the new ones.
    const std::uint32_t epoch = scratch.stamp_epoch;
    if (scratch.vertices.size() < 3 * std::size_t{end - begin}) scratch.vertices.resize(3 * std::size_t{end - begin});
    Vec3* out = scratch.vertices.data();
    std::size_t count = 0;
    for (Index p = begin; p < end; ++p) {
      const detail::VertexIds& t = ids_[p];
      for (int k = 0; k < 3; ++k) {
        const bool fresh = stamp[t[k]] != epoch;
        stamp[t[k]] = epoch;
        out[count] = corners_[3 * std::size_t{p} + k];
        count += fresh ? 1 : 0;
      }
    }
    return {out, count};
  }

  [[nodiscard]] std::span<const Vec3> node_corners(Index begin, Index end) const {
    return std::span<const Vec3>(corners_).subspan(3 * std::size_t{begin}, 3 * std::size_t{end - begin});
  }

  // The node's box; `points` gets what compact_box measures it on: the node's distinct vertices
  // when the fitter asked for them (the same maxima as over the corners, from ~6x fewer points),
  // else its corners.
  [[nodiscard]] Obb fit(Index begin, Index end, Scratch& scratch, std::span<const Vec3>& points,
                        const Mat3* pca_axes, const Mat3* parent_axes) const {
    points = node_corners(begin, end);
    return detail::fit_node(
        node_corners(begin, end), order_.size(), options_.fitter, options_.fit, scratch.fit,
        [&] {
          points = node_vertices(begin, end, scratch);
          return points;
        },
        pca_axes, parent_axes);
  }

  const Mesh& mesh_;
  const BuildOptions& options_;
  // Position-indexed, permuted in lockstep by the splits: position p holds triangle order_[p]
  // with corners corners_[3p..3p+3). Each node (and each task) touches only its own range.
  std::vector<Index>& order_;
  std::vector<Vec3> corners_;
  // Position-indexed like corners_: the mesh vertex indices of the triangle at each position, for
  // the fitters that find a node's distinct vertices (empty for pca and pca-vertex).
  std::vector<detail::VertexIds> ids_;
  bool uses_moments_ = false;
};

// Subtrees at most this large are built by one task, sequentially; above it every node is a task
// of its own. The grain only sets how the work is shared out: the layout below fixes every node's
// slot from its triangle range alone, so the tree is the same for any grain and thread count.
[[nodiscard]] Index task_grain(std::size_t triangles) {
  return static_cast<Index>(std::max<std::size_t>(1024, triangles / 128));
}

// A subtree still to build: its root goes to nodes[slot], its descendants to the slots from
// `next` on. A subtree of m triangles has at most 2m - 1 nodes (exactly that for leaf_size 1), so
// a node's child pair takes slots next, next + 1, the left child's descendants the 2m_left - 2
// slots after them and the right child's the rest: depth first, each child pair adjacent, as
// build_subtree lays out a subtree; no slot depends on the order in which the tasks ran.
struct Job {
  Index slot;
  std::size_t next;
  Index begin;
  Index end;
  Index parent;  // kNoParent for the root
};

// Largest subtree first (load balance: the big fits start early), then by position: a strict
// total order, as run_tasks needs.
[[nodiscard]] bool runs_before(const Job& a, const Job& b) {
  const Index size_a = a.end - a.begin;
  const Index size_b = b.end - b.begin;
  return size_a != size_b ? size_a > size_b : a.begin < b.begin;
}

// With leaf_size > 1 subtrees use fewer slots than reserved: drop the unused ones, keeping the
// order (children stay after their parent, sibling pairs adjacent).
void close_gaps(Tree& tree) {
  std::vector<Node>& nodes = tree.nodes;
  std::vector<Index> new_index(nodes.size(), 0);
  std::vector<char> used(nodes.size(), 0);
  used[0] = 1;
  Index count = 0;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (!used[k]) continue;
    new_index[k] = count++;
    if (!nodes[k].is_leaf()) used[nodes[k].first] = used[nodes[k].first + 1] = 1;
  }
  if (count == nodes.size()) return;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (!used[k]) continue;
    Node node = nodes[k];
    if (!node.is_leaf()) node.first = new_index[node.first];
    nodes[new_index[k]] = node;
  }
  nodes.resize(count);
  nodes.shrink_to_fit();
}

}  // namespace

Tree build(const Mesh& mesh, const BuildOptions& options) {
  (void)check_mesh(mesh, "mesh");
  if (mesh.triangles.size() >= std::numeric_limits<Index>::max())
    throw InputError("build: more than 2^32 - 2 triangles");
  if (options.leaf_size == 0) throw InputError("build: leaf_size must be at least 1");
  if (uses(options.fitter, FitMethod::approx_snap) && mesh.triangles.size() > kMaxApproxSnapTriangles)
    throw InputError("build: approx-snap is limited to " + std::to_string(kMaxApproxSnapTriangles) +
                     " triangles (an exact box per node: it would take hours on " +
                     std::to_string(mesh.triangles.size()) + "); use approx");
  const auto n = static_cast<Index>(mesh.triangles.size());

  Tree tree;
  tree.triangle_order.resize(n);
  for (Index i = 0; i < n; ++i) tree.triangle_order[i] = i;
  Builder builder(mesh, options, tree.triangle_order);
  const unsigned threads =
      options.threads != 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  detail::WorkerPool<Scratch> pool(threads);

  detail::reserve_huge_pages(tree.nodes, 2 * std::size_t{n} - 1);
  tree.nodes.resize(2 * std::size_t{n} - 1);
  const Index grain = task_grain(n);
  pool.run_tasks(Job{0, 1, 0, n, kNoParent}, runs_before, [&](const Job& job, Scratch& scratch, auto spawn) {
    if (job.end - job.begin <= grain) {
      (void)builder.build_subtree(job.slot, job.begin, job.end, job.parent, tree.nodes, job.next, scratch);
      return;
    }
    Node& node = tree.nodes[job.slot];
    // A task sums its own moments: which nodes are tasks depends on the mesh only (task_grain),
    // so the tree stays the same for any thread count.
    Moments moments, left, right;
    const Index mid = builder.process(node, job.begin, job.end, scratch, moments, left, right,
                                      job.parent == kNoParent ? nullptr : &tree.nodes[job.parent].box);
    if (mid == job.end) return;  // a leaf (leaf_size > grain)
    node.first = static_cast<Index>(job.next);
    node.count = 0;
    spawn(Job{node.first, job.next + 2, job.begin, mid, job.slot});
    spawn(Job{node.first + 1, job.next + 2 * std::size_t{mid - job.begin}, mid, job.end, job.slot});
  });
  if (options.leaf_size > 1) close_gaps(tree);
  return tree;
}

BuildResult build_with_stats(const Mesh& mesh, const BuildOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  BuildResult result;
  result.tree = build(mesh, options);
  result.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.stats.tree = tree_stats(result.tree);
  return result;
}

}  // namespace tightbvh
