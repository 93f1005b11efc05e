#pragma once
// The split strategies (split.hpp), internal to the builder.
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "tightbvh/mesh.hpp"
#include "tightbvh/obb.hpp"
#include "tightbvh/split.hpp"

namespace tightbvh::detail {

// Buffers reused across nodes by one worker.
struct SplitScratch {
  std::vector<std::pair<double, std::uint32_t>> keys;  // count/median split
  std::vector<Aabb> bounds;                             // binned: triangle bounds in the node frame
  std::vector<Vec3> centers;                            // binned: centroids in the node frame
  std::vector<std::uint32_t> reordered;
};

// Reorders `range` (triangle indices, size >= 2) so that [0, mid) goes to the left child and
// returns mid, 0 < mid < range.size(). Deterministic: depends on the inputs only.
[[nodiscard]] std::size_t split(SplitMethod method, std::span<std::uint32_t> range, const Obb& box,
                                const Mesh& mesh, const std::vector<Vec3>& centroids,
                                SplitScratch& scratch);

}  // namespace tightbvh::detail
