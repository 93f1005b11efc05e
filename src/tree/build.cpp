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

// Range of triangle_order owned by a node being built.
struct Pending {
  Index node;
  Index begin;
  Index end;
};

// Per-worker buffers, reused from node to node: no allocation per node once they have grown.
struct Scratch {
  std::vector<Pending> stack;
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
      : mesh_(mesh), options_(options), order_(order), corners_(triangle_corners(mesh)) {}

  // Fits the node's box; returns the split point (begin < mid < end), or `end` for a leaf.
  Index process(Node& node, Index begin, Index end, Scratch& scratch) {
    const Obb fitted = fit(begin, end, scratch);
    node.box = compact_box(fitted, node_corners(begin, end));
    if (end - begin <= options_.leaf_size) {
      node.first = begin;
      node.count = end - begin;
      return end;
    }
    const std::size_t n = end - begin;
    return begin + static_cast<Index>(detail::split(options_.split, std::span<Index>(order_).subspan(begin, n),
                                                    std::span<Vec3>(corners_).subspan(3 * std::size_t{begin}, 3 * n),
                                                    fitted, scratch.split));
  }

  // Builds the subtree of [begin, end) whose root is nodes[root] depth first, allocating child
  // pairs from nodes[next ...]; returns the end of what it used. An explicit stack: the RAPID
  // split can be very unbalanced (depth ~ n on some inputs).
  std::size_t build_subtree(Index root, Index begin, Index end, std::span<Node> nodes, std::size_t next,
                            Scratch& scratch) {
    auto& stack = scratch.stack;
    stack.assign(1, {root, begin, end});
    while (!stack.empty()) {
      const Pending p = stack.back();
      stack.pop_back();
      Node& node = nodes[p.node];
      const Index mid = process(node, p.begin, p.end, scratch);
      if (mid != p.end) {
        node.first = static_cast<Index>(next);
        node.count = 0;
        next += 2;
        stack.push_back({node.first + 1, mid, p.end});
        stack.push_back({node.first, p.begin, mid});
      }
    }
    return next;
  }

 private:
  // The distinct mesh vertices of the node's triangles (positions [begin, end) of order_).
  std::span<const Vec3> node_vertices(Index begin, Index end, Scratch& scratch) const {
    auto& stamp = scratch.vertex_stamp;
    if (stamp.size() != mesh_.vertices.size() || ++scratch.stamp_epoch == 0) {
      stamp.assign(mesh_.vertices.size(), 0);
      scratch.stamp_epoch = 1;
    }
    scratch.vertices.clear();
    for (Index p = begin; p < end; ++p)
      for (const std::uint32_t v : mesh_.triangles[order_[p]])
        if (stamp[v] != scratch.stamp_epoch) {
          stamp[v] = scratch.stamp_epoch;
          scratch.vertices.push_back(mesh_.vertices[v]);
        }
    return scratch.vertices;
  }

  [[nodiscard]] std::span<const Vec3> node_corners(Index begin, Index end) const {
    return std::span<const Vec3>(corners_).subspan(3 * std::size_t{begin}, 3 * std::size_t{end - begin});
  }

  [[nodiscard]] Obb fit(Index begin, Index end, Scratch& scratch) const {
    return detail::fit_node(node_corners(begin, end), options_.fitter, options_.fit, scratch.fit,
                            [&] { return node_vertices(begin, end, scratch); });
  }

  const Mesh& mesh_;
  const BuildOptions& options_;
  // Position-indexed, permuted in lockstep by the splits: position p holds triangle order_[p]
  // with corners corners_[3p..3p+3). Each node (and each task) touches only its own range.
  std::vector<Index>& order_;
  std::vector<Vec3> corners_;
};

// Subtrees at most this large are built by one task. It depends on the triangle count only,
// never on the thread count, so the node numbering (and thus the tree) is the same for any
// number of threads.
[[nodiscard]] Index task_grain(std::size_t triangles) {
  return static_cast<Index>(std::max<std::size_t>(1024, triangles / 128));
}

// Phase 1, the top levels, breadth first: the nodes of one level are independent, so their fits
// run in parallel; child slots are then allocated in level order, which fixes the numbering.
// Fills tree.nodes with those levels; returns the ranges below the grain, one task each.
std::vector<Pending> build_top_levels(Builder& builder, Index n, detail::WorkerPool<Scratch>& pool, Tree& tree) {
  const Index grain = task_grain(n);
  tree.nodes.emplace_back();
  std::vector<Pending> level{{0, 0, n}};
  std::vector<Pending> tasks;
  std::vector<Index> mids;
  while (!level.empty()) {
    std::vector<Pending> big;
    for (const Pending& p : level) (p.end - p.begin > grain ? big : tasks).push_back(p);
    mids.assign(big.size(), 0);
    pool.run(big.size(), [&](std::size_t i, Scratch& scratch) {
      mids[i] = builder.process(tree.nodes[big[i].node], big[i].begin, big[i].end, scratch);
    });
    level.clear();
    for (std::size_t i = 0; i < big.size(); ++i) {
      Node& node = tree.nodes[big[i].node];
      if (mids[i] == big[i].end) continue;  // a leaf (leaf_size > grain)
      node.first = static_cast<Index>(tree.nodes.size());
      node.count = 0;
      level.push_back({node.first, big[i].begin, mids[i]});
      level.push_back({node.first + 1, mids[i], big[i].end});
      tree.nodes.emplace_back();
      tree.nodes.emplace_back();
    }
  }
  return tasks;
}

// Where phase 2 put each task's subtree: nodes [offset[i], offset[i] + used[i]).
struct TaskSlices {
  std::vector<std::size_t> offset;  // tasks.size() + 1 entries
  std::vector<std::size_t> used;
};

// Phase 2, the subtrees below the grain: one task each, largest first for load balance. A
// subtree of m triangles has at most 2m - 1 nodes (exactly that for leaf_size 1): each task
// writes its nodes directly into its own slice of the final array, at an offset fixed by the
// task order.
TaskSlices build_subtrees(Builder& builder, const std::vector<Pending>& tasks, detail::WorkerPool<Scratch>& pool,
                          Tree& tree) {
  TaskSlices slices;
  std::vector<std::size_t>& offset = slices.offset;
  offset.assign(tasks.size() + 1, tree.nodes.size());
  for (std::size_t i = 0; i < tasks.size(); ++i)
    offset[i + 1] = offset[i] + 2 * std::size_t{tasks[i].end - tasks[i].begin} - 2;
  tree.nodes.resize(offset.back());
  slices.used.resize(tasks.size());
  std::vector<std::size_t> by_size(tasks.size());
  for (std::size_t i = 0; i < by_size.size(); ++i) by_size[i] = i;
  std::stable_sort(by_size.begin(), by_size.end(), [&](std::size_t a, std::size_t b) {
    return tasks[a].end - tasks[a].begin > tasks[b].end - tasks[b].begin;
  });
  pool.run(tasks.size(), [&](std::size_t k, Scratch& scratch) {
    const std::size_t i = by_size[k];
    const Pending& p = tasks[i];
    slices.used[i] = builder.build_subtree(p.node, p.begin, p.end, tree.nodes, offset[i], scratch) - offset[i];
  });
  return slices;
}

// Phase 3: with leaf_size > 1 the slices have unused tails: close the gaps, in task order.
void compact(const std::vector<Pending>& tasks, const TaskSlices& slices, Tree& tree) {
  std::size_t write = slices.offset[0];
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const std::size_t shift = slices.offset[i] - write;
    if (shift != 0) {
      Node& root = tree.nodes[tasks[i].node];
      if (!root.is_leaf()) root.first -= static_cast<Index>(shift);
      for (std::size_t k = slices.offset[i]; k < slices.offset[i] + slices.used[i]; ++k) {
        Node node = tree.nodes[k];
        if (!node.is_leaf()) node.first -= static_cast<Index>(shift);
        tree.nodes[k - shift] = node;
      }
    }
    write += slices.used[i];
  }
  tree.nodes.resize(write);
  if (tree.nodes.capacity() > write + write / 4) tree.nodes.shrink_to_fit();
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

  const std::vector<Pending> tasks = build_top_levels(builder, n, pool, tree);
  const TaskSlices slices = build_subtrees(builder, tasks, pool, tree);
  compact(tasks, slices, tree);
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
