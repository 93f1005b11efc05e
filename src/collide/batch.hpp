#pragma once
// Internal: the batch queries (collide_batch, distance_batch): one query per pose of B on the
// builder's worker pool (dynamic scheduling over chunks of pose indices, one workspace per worker, each
// result in its own slot, so the output does not depend on the thread count or the
// interleaving; the error of the lowest failing pose is rethrown). With `solid`, the closedness
// of both meshes is checked once for all poses (an open mesh throws here).
#include <algorithm>
#include <optional>
#include <span>
#include <thread>
#include <vector>

#include "../tree/parallel.hpp"
#include "solid.hpp"
#include "tightbvh/query_workspace.hpp"

namespace tightbvh::query_detail {

// query(pose, options, workspace) -> Result, for every pose; Options has solid, closed_a, closed_b.
template <class Result, class Options, class Query>
std::vector<Result> run_batch(const char* name, const Mesh& ma, const Mesh& mb, std::span<const Pose> poses_b,
                              const Options& options, unsigned threads, Query&& query) {
  std::vector<Result> results(poses_b.size());
  std::optional<SolidMeshes> solid;
  Options per_pose = options;
  if (options.solid && !poses_b.empty()) {
    solid.emplace(name, ma, options.closed_a, mb, options.closed_b);
    per_pose.closed_a = &solid->a();
    per_pose.closed_b = &solid->b();
  }
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(poses_b.size(), 1)));
  detail::WorkerPool<QueryWorkspace> pool(threads);
  // Chunks of up to 64 poses: the queries take microseconds (see WorkerPool::run).
  const std::size_t chunk = std::clamp<std::size_t>(poses_b.size() / (16 * std::size_t{threads}), 1, 64);
  pool.run(
      poses_b.size(), [&](std::size_t i, QueryWorkspace& workspace) { results[i] = query(poses_b[i], per_pose, workspace); },
      chunk);
  return results;
}

}  // namespace tightbvh::query_detail
