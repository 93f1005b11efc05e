#pragma once
/// @file
/// Reusable scratch memory for the tree-vs-tree queries (collide.hpp): the traversal stack and
/// B's boxes mapped into A's frame. Queries that share a workspace allocate only while its
/// buffers grow; the answers do not depend on the queries that used the workspace earlier.
/// Not thread-safe: use one workspace per thread (collide_batch keeps one per worker).
#include <memory>

namespace tightbvh {

/// Scratch memory of collide() and distance() queries (see the file comment).
class QueryWorkspace {
 public:
  QueryWorkspace();
  ~QueryWorkspace();
  QueryWorkspace(QueryWorkspace&&) noexcept;             ///< Takes over the other's buffers.
  QueryWorkspace& operator=(QueryWorkspace&&) noexcept;  ///< Takes over the other's buffers.
  QueryWorkspace(const QueryWorkspace&) = delete;
  QueryWorkspace& operator=(const QueryWorkspace&) = delete;

  struct Scratch;  // internal (src/collide/query_workspace.hpp)
  /// The buffers, for the queries (src/collide/); opaque to users.
  [[nodiscard]] Scratch& scratch() { return *scratch_; }

 private:
  std::unique_ptr<Scratch> scratch_;
};

}  // namespace tightbvh
