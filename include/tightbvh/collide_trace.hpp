#pragma once
/// @file
/// The descent of a collide() query, recorded: which node pairs it visited, in order, and what
/// happened to each. For pictures of the descent (`tightbvh collide --view`) and for debugging
/// trees; it is the real descent (the same traversal, box test and triangle test as collide(),
/// so the same first hit and the same stats), but slower: use collide() for answers.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "tightbvh/collide.hpp"

namespace tightbvh {

/// What happened to a node pair the descent visited.
enum class PairOutcome : std::uint8_t {
  culled,     ///< the boxes are disjoint (separating axis): the pair and all below it skipped
  descended,  ///< the boxes overlap and one node is internal: the larger one was split
  leaves,     ///< the boxes of two leaves overlap: their triangles were tested, none reported
  hit,        ///< two leaves whose triangle tests reported a pair
};
/// The number of PairOutcome values (the size of a CollideTrace::per_level row).
inline constexpr std::size_t kPairOutcomes = 4;

/// One node pair of the descent.
struct VisitedPair {
  /// @{
  /// Node indices into the trees' nodes: `a` into A's, `b` into B's.
  std::uint32_t a = 0, b = 0;
  /// @}
  /// Descent level: depth of a + depth of b (the root pair is 0; each split adds one).
  std::uint32_t level = 0;
  PairOutcome outcome = PairOutcome::culled;  ///< What the descent did with the pair.
};

/// A collide() answer with the descent that found it.
struct CollideTrace {
  QueryResult result;  ///< equal to collide()'s (pairs, hit and stats)
  /// The first `max_pairs` visited pairs (CollideTraceOptions), in visiting order.
  std::vector<VisitedPair> pairs;
  /// Every visited pair counted, recorded or not: per_level[level][outcome].
  std::vector<std::array<std::uint64_t, kPairOutcomes>> per_level;
  std::uint64_t visited = 0;  ///< == result.stats.box_tests
};

/// What collide_trace() records.
struct CollideTraceOptions {
  std::size_t max_pairs = 100'000;  ///< pairs recorded in CollideTrace::pairs (the rest only counted)
};

/// collide(a, ma, pa, b, mb, pb, options) with its descent recorded. Same errors as collide().
[[nodiscard]] CollideTrace collide_trace(const Tree& a, const Mesh& ma, const Pose& pa,  //
                                         const Tree& b, const Mesh& mb, const Pose& pb,  //
                                         const QueryOptions& options = {}, const CollideTraceOptions& trace = {});

}  // namespace tightbvh
