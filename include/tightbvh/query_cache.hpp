#pragma once
/// @file
/// Front tracking for coherent sequences of collide() queries on one pair of trees (a simulation
/// loop: consecutive poses are close). Generalized front tracking in the spirit of Ehmann & Lin
/// (2001, "Accurate and fast proximity queries between polyhedra using convex surface
/// decomposition", Sec. 5) and FCL's BVHFrontList.
///
/// The cache stores the *front* of the previous descent: the node pairs where it stopped (pairs
/// whose boxes were apart, and leaf pairs). Their leaf-pair sets always partition
/// leaves(A) x leaves(B), so starting the next descent from them instead of the roots reports the
/// same touching triangle pairs (box tests are conservative, triangle tests exact). Each query
/// descends where front pairs overlap at the new poses and lifts the front back up where two sibling pairs have
/// stayed apart for a while and their parent pair is apart too (with an exponential back-off when
/// the parent still overlaps), so the front follows the contact region instead of only growing.
///
/// first_hit: the leaf pair that touched last time is tried first (a "witness", as in
/// Lin-Canny's feature caching); if it does not touch at the new poses, the cold descent from the roots answers
/// (faster than a descent from the front since the cold one tests its pairs in SIMD batches and
/// nearest first). The hit flag equals the cold query's, but the pair reported may differ (any
/// touching pair is a valid answer). first_hit leaves the front as it is, so one cache may serve
/// both modes.
///
/// The front depends only on the two trees' topology. The cache records which trees (address,
/// node buffer, node and triangle counts) filled it; a query on other trees, or with A and B
/// swapped, starts over from the roots (resets() counts it). refit() keeps the topology, so a
/// cache stays valid across refits; a tree rebuilt in place inside the same node buffer with the
/// same counts cannot be told apart: call clear() after rebuilding a tree.
///
/// Not thread-safe: one cache per sequence (it also holds the query scratch, so no QueryWorkspace
/// is needed with it).
#include <cstddef>
#include <cstdint>
#include <memory>

namespace tightbvh {

/// The front of the previous collide() query on a pair of trees (see the file comment).
class QueryCache {
 public:
  QueryCache();
  ~QueryCache();
  QueryCache(QueryCache&&) noexcept;             ///< Takes over the other's front.
  QueryCache& operator=(QueryCache&&) noexcept;  ///< Takes over the other's front.
  QueryCache(const QueryCache&) = delete;
  QueryCache& operator=(const QueryCache&) = delete;

  /// Forget the front: the next query starts at the roots.
  void clear();
  /// Node pairs in the stored front (0 before the first query and after clear()).
  [[nodiscard]] std::size_t front_size() const;
  /// Queries that found other trees than the stored front's and started over from the roots.
  [[nodiscard]] std::uint64_t resets() const;

  struct State;  // internal (src/collide/query_cache.hpp)
  /// The front and scratch, for the queries (src/collide/); opaque to users.
  [[nodiscard]] State& state() { return *state_; }

 private:
  std::unique_ptr<State> state_;
};

}  // namespace tightbvh
