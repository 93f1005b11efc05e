#pragma once
// The split strategies (split.hpp), internal to the builder.
//
// A node's triangles are a range of positions; position p has its triangle index in `order[p]`
// and its three corners in `corners[3p .. 3p+3)`. Splitting permutes both in lockstep, so a
// node's corners are always contiguous and go to the fitter without any gathering.
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "tightbvh/aabb.hpp"
#include "tightbvh/obb.hpp"
#include "tightbvh/split.hpp"

namespace tightbvh::detail {

struct SplitKey {
  double key;
  std::uint32_t triangle;  // ties broken by triangle index: independent of the current order
  std::uint32_t position;
};

// Buffers reused across nodes by one worker.
struct SplitScratch {
  std::vector<SplitKey> keys;               // count/median split
  std::vector<double> projections;          // rapid split
  std::vector<Aabb> bounds;                 // binned: triangle bounds in the node frame
  std::vector<Vec3> centers;                // binned: centroids in the node frame
  std::vector<std::uint32_t> order;         // reordering buffers
  std::vector<Vec3> corners;
};

// Reorders `order` (size n >= 2) and `corners` (3n) so that [0, mid) goes to the left child and
// returns mid, 0 < mid < n. Deterministic: depends on the inputs only.
[[nodiscard]] std::size_t split(SplitMethod method, std::span<std::uint32_t> order, std::span<Vec3> corners,
                                const Obb& box, SplitScratch& scratch);

}  // namespace tightbvh::detail
