#pragma once
// The split strategies (split.hpp), internal to the builder.
//
// A node's triangles are a range of positions; position p has its triangle index in `order[p]`
// and its three corners in `corners[3p .. 3p+3)` (and, for fitters that use a node's distinct
// vertices, its mesh vertex indices in `ids[p]`). Splitting permutes them in lockstep, so a
// node's corners are always contiguous and go to the fitter without any gathering.
#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "tightbvh/aabb.hpp"
#include "tightbvh/obb.hpp"
#include "tightbvh/split.hpp"

namespace tightbvh::detail {

// A triangle's three mesh vertex indices.
using VertexIds = std::array<std::uint32_t, 3>;

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
  std::vector<VertexIds> ids;
};

// Reorders `order` (size n >= 2), `corners` (3n) and `ids` (n, or empty when the builder keeps
// none) so that [0, mid) goes to the left child and returns mid, 0 < mid < n. Deterministic:
// depends on the inputs only.
[[nodiscard]] std::size_t split(SplitMethod method, std::span<std::uint32_t> order, std::span<Vec3> corners,
                                std::span<VertexIds> ids, const Obb& box, SplitScratch& scratch);

}  // namespace tightbvh::detail
