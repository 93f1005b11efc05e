#pragma once
// Reusable scratch memory for the tree-vs-tree queries (collide.hpp): the traversal stack and
// B's boxes mapped into A's frame. Queries that share a workspace allocate only while its
// buffers grow; the answers do not depend on what the workspace was used for before.
// Not thread-safe: use one workspace per thread (collide_batch keeps one per worker).
#include <memory>

namespace tightbvh {

class QueryWorkspace {
 public:
  QueryWorkspace();
  ~QueryWorkspace();
  QueryWorkspace(QueryWorkspace&&) noexcept;
  QueryWorkspace& operator=(QueryWorkspace&&) noexcept;
  QueryWorkspace(const QueryWorkspace&) = delete;
  QueryWorkspace& operator=(const QueryWorkspace&) = delete;

  struct Scratch;  // internal (src/collide/query_workspace.hpp)
  [[nodiscard]] Scratch& scratch() { return *scratch_; }

 private:
  std::unique_ptr<Scratch> scratch_;
};

}  // namespace tightbvh
