#pragma once
// Internal: the state behind QueryCache and the front-tracking descent (include/tightbvh/query_cache.hpp).
//
// traverse_front(...) has the contract of traverse_pairs (traverse.hpp): the same test(a, b) and
// leaves(a, b) callables, the same split rule, so a query passes the lambdas it passes to
// traverse_pairs. It starts from the stored front instead of (0, 0).
//
// Invariant: the leaf-pair sets of the front's entries, leaves(a) x leaves(b), partition
// leaves(A) x leaves(B). Descending (replacing a pair by the two pairs of its split) and lifting
// (replacing two entries (a, b), (a, b') with b, b' siblings by (a, parent(b)), or the same on A's
// side) both keep it, whatever rule produced the front. Hence every touching leaf pair lies under
// exactly one entry, whose (conservative) box test passes, and the descent from it reaches it:
// the answers are those of the cold descent.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "query_workspace.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/query_cache.hpp"
#include "tightbvh/tree.hpp"
#include "traverse.hpp"

namespace tightbvh {
namespace query_detail {

inline constexpr std::uint32_t kNoNode = std::numeric_limits<std::uint32_t>::max();

struct FrontEntry {
  std::uint32_t a = 0, b = 0;
  std::uint16_t culled = 0;  // consecutive queries in which this pair's boxes were apart
  std::uint8_t level = 0;    // lift back-off: a lift is tried once both siblings were apart 1 << level times
};
inline constexpr std::uint8_t kMaxLiftLevel = 2;  // a failed lift is retried after at most 4 queries

// A growable array of entries whose push is inlined (std::vector's push_back is not always, and
// it sits on the per-pair path).
class EntryList {
 public:
  [[nodiscard]] std::size_t size() const { return n_; }
  [[nodiscard]] bool empty() const { return n_ == 0; }
  void clear() { n_ = 0; }
  void push_back(const FrontEntry& e) {
    if (n_ == data_.size()) [[unlikely]]
      data_.resize(std::max<std::size_t>(64, 2 * data_.size()));
    data_[n_++] = e;
  }
  void pop_back() { --n_; }
  [[nodiscard]] FrontEntry& back() { return data_[n_ - 1]; }
  [[nodiscard]] FrontEntry& operator[](std::size_t i) { return data_[i]; }
  void assign_one(const FrontEntry& e) {
    clear();
    push_back(e);
  }
  void swap(EntryList& other) noexcept {
    data_.swap(other.data_);
    std::swap(n_, other.n_);
  }

 private:
  std::vector<FrontEntry> data_;
  std::size_t n_ = 0;
};

// What identifies a tree for the cache (see query_cache.hpp).
struct TreeKey {
  const Tree* tree = nullptr;
  const Node* nodes = nullptr;
  std::size_t node_count = 0;
  std::size_t triangle_count = 0;

  friend bool operator==(const TreeKey&, const TreeKey&) = default;
};
[[nodiscard]] inline TreeKey key_of(const Tree& t) {
  return {&t, t.nodes.data(), t.nodes.size(), t.triangle_order.size()};
}

// parent[i]: the internal node whose children include i; kNoNode for the root.
inline void fill_parents(const Tree& t, std::vector<std::uint32_t>& parent) {
  parent.assign(t.nodes.size(), kNoNode);
  for (std::uint32_t i = 0; i < t.nodes.size(); ++i)
    if (!t.nodes[i].is_leaf()) parent[t.nodes[i].first] = parent[t.nodes[i].first + 1] = i;
}

}  // namespace query_detail

struct QueryCache::State {
  query_detail::TreeKey key_a, key_b;
  std::vector<std::uint32_t> parent_a, parent_b;
  query_detail::EntryList front, next;
  query_detail::EntryList stack;  // descent below one front entry
  std::optional<query_detail::NodePair> last_hit;  // the leaf pair of the last first_hit's hit
  // collide() on two Models (model.cpp): the triangle pair of the last first_hit's hit, and the
  // models' trees it was found on. Only a hint: the pair is tested exactly before it is reported.
  query_detail::TreeKey witness_a, witness_b;
  std::optional<TrianglePair> witness;
  std::uint64_t resets = 0;
  QueryWorkspace::Scratch scratch;

  void clear() {
    key_a = key_b = {};
    front.clear();
    last_hit.reset();
    witness_a = witness_b = {};
    witness.reset();
  }
  // Makes the state ready for a query on (a, b): keeps the front if it was built on them.
  void bind(const Tree& a, const Tree& b) {
    const query_detail::TreeKey ka = query_detail::key_of(a), kb = query_detail::key_of(b);
    if (ka == key_a && kb == key_b && !front.empty()) return;
    if (!front.empty()) ++resets;
    key_a = ka;
    key_b = kb;
    query_detail::fill_parents(a, parent_a);
    query_detail::fill_parents(b, parent_b);
    front.assign_one(query_detail::FrontEntry{});  // the root pair
    last_hit.reset();
  }
  // Makes the witness ready for a query on two models whose trees are a and b: kept if it was
  // found on them.
  void bind_witness(const Tree& a, const Tree& b) {
    const query_detail::TreeKey ka = query_detail::key_of(a), kb = query_detail::key_of(b);
    if (ka == witness_a && kb == witness_b) return;
    if (witness) ++resets;
    witness_a = ka;
    witness_b = kb;
    witness.reset();
  }
};

namespace query_detail {

// Where the node pair being tested came from (traverse_front has one call site of `test`, so
// that the query's box test inlines there).
enum class Source : std::uint8_t {
  root,   // the root pair, tested first when the front is larger
  front,  // an entry of the previous front
  child,  // a child pair below an overlapping pair
  lift,   // the parent of two sibling entries found apart
};

// The descent of traverse_pairs, from the front of `st` (bound to ta, tb); rebuilds the front.
// Used by the queries that visit every touching pair (all_pairs, with or without a margin). A
// cached first_hit does not come here: it tries the last hit's leaf pair, then the cold descent
// (collide.cpp), which tests in SIMD batches and nearest first and is faster than this one
// (docs/design-notes/collide.md, "QueryCache: front tracking, kept but narrow").
// flatten (GCC, Clang; others ignore it): with the lifting paths the function exceeds GCC's
// inlining budget, and without flatten the box test's 3x3 products and the entry pushes become
// calls (all_pairs on the bench trajectory: 0.96x of cold queries' speed without it, 1.04x with).
template <class NodeTest, class LeafPair>
[[gnu::flatten]] void traverse_front(const Tree& ta, const Tree& tb, DescendRule rule, QueryCache::State& st,
                                    NodeTest&& test, LeafPair&& leaves) {
  EntryList& front = st.front;
  EntryList& next = st.next;
  EntryList& stack = st.stack;
  next.clear();
  stack.clear();

  std::size_t i = 0;             // next entry of the old front
  bool root_first = front.size() > 1;
  bool lifting = false;          // `lift` holds the parent of next's last two entries, to be tested
  FrontEntry lift{};

  // After an entry found apart was appended: may its last two entries be lifted into their parent
  // pair? Yes when they are siblings (the same node of one tree, siblings in the other) that have
  // both been apart 1 << level queries in a row (Ehmann & Lin's front propagation upwards, with a
  // back-off per entry, raised each time the parent is found to overlap).
  const auto want_lift = [&] {
    if (next.size() < 2) return false;
    const FrontEntry& y = next.back();
    const FrontEntry& x = next[next.size() - 2];
    if (x.culled < (1u << x.level) || y.culled < (1u << y.level)) return false;
    if (x.a == y.a && x.b != y.b) {
      const std::uint32_t p = st.parent_b[x.b];
      if (p == kNoNode || p != st.parent_b[y.b]) return false;
      lift = {x.a, p, std::min(x.culled, y.culled), 0};
      return true;
    }
    if (x.b == y.b && x.a != y.a) {
      const std::uint32_t p = st.parent_a[x.a];
      if (p == kNoNode || p != st.parent_a[y.a]) return false;
      lift = {p, x.b, std::min(x.culled, y.culled), 0};
      return true;
    }
    return false;
  };
  const auto bump = [](std::uint16_t c) { return static_cast<std::uint16_t>(c == 0xffff ? c : c + 1); };

  for (;;) {
    // Pick the next node pair to test.
    Source source;
    FrontEntry q;
    if (root_first) {
      root_first = false;
      source = Source::root;
      q = FrontEntry{};
    } else if (lifting) {
      lifting = false;
      source = Source::lift;
      q = lift;
    } else if (!stack.empty()) {
      source = Source::child;
      q = stack.back();
      stack.pop_back();
    } else if (i < front.size()) {
      source = Source::front;
      q = front[i++];
    } else {
      break;
    }

    const bool overlap = test(q.a, q.b);

    switch (source) {
      case Source::root:
        if (!overlap) {  // apart: one test answers, and the front collapses to the roots
          front.assign_one(FrontEntry{0, 0, 1, 0});
          return;
        }
        continue;
      case Source::lift:
        if (overlap) {  // keep both siblings; back off
          FrontEntry& y = next.back();
          FrontEntry& x = next[next.size() - 2];
          x.level = std::min<std::uint8_t>(x.level + 1, kMaxLiftLevel);
          y.level = std::min<std::uint8_t>(y.level + 1, kMaxLiftLevel);
          x.culled = y.culled = 0;
        } else {
          next.pop_back();
          next.back() = q;
          lifting = want_lift();
        }
        continue;
      case Source::front:
      case Source::child:
        break;
    }

    if (!overlap) {
      if (source == Source::front) {
        q.culled = bump(q.culled);
      } else {
        q.culled = 1;
        q.level = 1;  // its parent overlapped just now: no lift before the next query
      }
      next.push_back(q);
      lifting = want_lift();
      continue;
    }
    q.culled = 0;
    const Node& na = ta.nodes[q.a];
    const Node& nb = tb.nodes[q.b];
    if (na.is_leaf() && nb.is_leaf()) {
      next.push_back(q);
      (void)leaves(q.a, q.b);  // visits every pair: never stops
      continue;
    }
    // Split the larger node, first child popped first. Never both nodes (as traverse_pairs does for
    // nodes of about one size): a lift merges two siblings back into their parent pair.
    if (splits_a(na, nb, rule)) {
      stack.push_back({na.first + 1, q.b, 0, 0});
      stack.push_back({na.first, q.b, 0, 0});
    } else {
      stack.push_back({q.a, nb.first + 1, 0, 0});
      stack.push_back({q.a, nb.first, 0, 0});
    }
  }
  front.swap(next);
}

}  // namespace query_detail
}  // namespace tightbvh
