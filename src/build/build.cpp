#include "tightbvh/build.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <limits>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "parallel.hpp"
#include "splitter.hpp"

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

namespace {

using Index = std::uint32_t;

// Range of triangle_order owned by a node being built.
struct Pending {
  Index node;
  Index begin;
  Index end;
};

// Per-worker buffers, reused from node to node: no allocation per node once they have grown.
struct Scratch {
  std::vector<Vec3> corners;
  detail::SplitScratch split;
};

class Builder {
 public:
  Builder(const Mesh& mesh, const BuildOptions& options, std::vector<Index>& order)
      : mesh_(mesh), options_(options), order_(order), centroids_(mesh.triangles.size()) {
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto c = mesh.corners(t);
      centroids_[t] = (c[0] + c[1] + c[2]) / 3.0;
    }
  }

  // Fits the node's box; returns the split point (begin < mid < end), or `end` for a leaf.
  Index process(Node& node, Index begin, Index end, Scratch& scratch) const {
    node.box = fit(begin, end, scratch);
    if (end - begin <= options_.leaf_size) {
      node.first = begin;
      node.count = end - begin;
      return end;
    }
    const auto range = std::span<Index>(order_).subspan(begin, end - begin);
    return begin + detail::split(options_.split, range, node.box, mesh_, centroids_, scratch.split);
  }

  // Builds the subtree of [begin, end) into `out` (local indices, root at 0), depth first.
  // An explicit stack: the RAPID split can be very unbalanced (depth ~ n on some inputs).
  void build_subtree(Index begin, Index end, std::vector<Node>& out, Scratch& scratch) const {
    out.clear();
    out.emplace_back();
    std::vector<Pending> stack{{0, begin, end}};
    while (!stack.empty()) {
      const Pending p = stack.back();
      stack.pop_back();
      Node node;
      const Index mid = process(node, p.begin, p.end, scratch);
      if (mid != p.end) {
        node.first = static_cast<Index>(out.size());
        node.count = 0;
        out.emplace_back();
        out.emplace_back();
        stack.push_back({node.first + 1, mid, p.end});
        stack.push_back({node.first, p.begin, mid});
      }
      out[p.node] = node;
    }
  }

 private:
  [[nodiscard]] FitMethod method_for(Index count) const {
    if (const auto* method = std::get_if<FitMethod>(&options_.fitter)) return *method;
    const AutoFit& a = std::get<AutoFit>(options_.fitter);
    return count >= a.tight_min_triangles ? a.tight : a.cheap;
  }

  [[nodiscard]] Obb fit(Index begin, Index end, Scratch& scratch) const {
    scratch.corners.clear();
    for (Index i = begin; i < end; ++i) {
      const Triangle& t = mesh_.triangles[order_[i]];
      scratch.corners.push_back(mesh_.vertices[t[0]]);
      scratch.corners.push_back(mesh_.vertices[t[1]]);
      scratch.corners.push_back(mesh_.vertices[t[2]]);
    }
    FitOptions fit = options_.fit;
    fit.method = method_for(end - begin);
    return fit_triangles(scratch.corners, fit);
  }

  const Mesh& mesh_;
  const BuildOptions& options_;
  std::vector<Index>& order_;  // each node (and each task) touches only its own range
  std::vector<Vec3> centroids_;
};

// Subtrees at most this large are built by one task. It depends on the triangle count only,
// never on the thread count, so the node numbering (and thus the tree) is the same for any
// number of threads.
[[nodiscard]] Index task_grain(std::size_t triangles) {
  return static_cast<Index>(std::max<std::size_t>(1024, triangles / 128));
}

}  // namespace

Tree build(const Mesh& mesh, const BuildOptions& options) {
  (void)validate(mesh, "mesh");
  if (mesh.triangles.size() >= std::numeric_limits<Index>::max())
    throw InputError("build: more than 2^32 - 2 triangles");
  if (options.leaf_size == 0) throw InputError("build: leaf_size must be at least 1");
  const auto n = static_cast<Index>(mesh.triangles.size());

  Tree tree;
  tree.triangle_order.resize(n);
  for (Index i = 0; i < n; ++i) tree.triangle_order[i] = i;
  const Builder builder(mesh, options, tree.triangle_order);
  const unsigned threads =
      options.threads != 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  detail::WorkerPool<Scratch> pool(threads);

  // Top levels, breadth first: the nodes of one level are independent, so their fits run in
  // parallel; child slots are then allocated in level order, which fixes the numbering.
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

  // Subtrees below the grain: one task each, largest first for load balance; each writes its
  // own local node array, appended afterwards in task order.
  std::vector<std::size_t> by_size(tasks.size());
  for (std::size_t i = 0; i < by_size.size(); ++i) by_size[i] = i;
  std::stable_sort(by_size.begin(), by_size.end(), [&](std::size_t a, std::size_t b) {
    return tasks[a].end - tasks[a].begin > tasks[b].end - tasks[b].begin;
  });
  std::vector<std::vector<Node>> local(tasks.size());
  pool.run(tasks.size(), [&](std::size_t i, Scratch& scratch) {
    const Pending& p = tasks[by_size[i]];
    builder.build_subtree(p.begin, p.end, local[by_size[i]], scratch);
  });
  std::size_t total = tree.nodes.size();
  for (const std::vector<Node>& sub : local) total += sub.size() - 1;
  tree.nodes.reserve(total);  // exact: no second copy of the largest array at peak
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const std::vector<Node>& sub = local[i];
    // Local node k >= 1 goes to offset + k - 1; local root 0 goes to the slot reserved above.
    const auto offset = static_cast<Index>(tree.nodes.size());
    const auto relocate = [offset](Node node) {
      if (!node.is_leaf()) node.first = node.first - 1 + offset;
      return node;
    };
    tree.nodes[tasks[i].node] = relocate(sub[0]);
    for (std::size_t k = 1; k < sub.size(); ++k) tree.nodes.push_back(relocate(sub[k]));
    local[i] = {};
  }
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
