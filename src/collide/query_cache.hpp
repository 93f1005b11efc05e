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
  std::uint8_t state = 0;    // kFresh; kTestedApart / kTestedOverlap: a first_hit leaf pair tested ahead;
                             // kUntested: a child on the descent stack
};
inline constexpr std::uint8_t kFresh = 0, kTestedApart = 1, kTestedOverlap = 2, kUntested = 3;
inline constexpr std::uint8_t kMaxLiftLevel = 8;  // at most one failed lift try per 256 queries

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
  std::vector<query_detail::FrontEntry> front, next;
  std::vector<query_detail::FrontEntry> stack;  // descent below one front entry
  std::uint32_t witness = query_detail::kNoNode;  // index into front of the last first_hit's leaf pair
  std::uint64_t resets = 0;
  QueryWorkspace::Scratch scratch;

  void clear() {
    key_a = key_b = {};
    front.clear();
    witness = query_detail::kNoNode;
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
    front.assign(1, query_detail::FrontEntry{});  // the root pair
    witness = query_detail::kNoNode;
  }
};

namespace query_detail {

// The descent of traverse_pairs, from the front of `st` (bound to ta, tb); rebuilds the front.
// try_witness (first_hit queries): the previous query's overlapping leaf pairs first, the last hit's first of all.
template <class NodeTest, class LeafPair>
Walk traverse_front(const Tree& ta, const Tree& tb, DescendRule rule, QueryCache::State& st, bool try_witness,
                    NodeTest&& test, LeafPair&& leaves) {
  std::vector<FrontEntry>& front = st.front;
  std::vector<FrontEntry>& next = st.next;
  std::vector<FrontEntry>& stack = st.stack;
  next.clear();

  // The root pair first: when the meshes have moved apart, one test answers and the front
  // collapses to the roots at once (lifting would take a pass over the whole front).
  if (front.size() > 1 && !test(0, 0)) {
    front.assign(1, FrontEntry{0, 0, 1, 0, kFresh});
    st.witness = kNoNode;
    return Walk::go_on;
  }

  // first_hit: the leaf pairs whose boxes overlapped in the previous query first (the witness,
  // the last hit's leaf pair, before them): contact persists between close poses, so the hit is
  // usually among them. Each is tested once; the main loop below reuses the outcome.
  if (try_witness) {
    const auto pretest = [&](std::size_t k) {
      FrontEntry& e = front[k];
      if (e.state != kFresh || e.culled != 0 || !ta.nodes[e.a].is_leaf() || !tb.nodes[e.b].is_leaf()) return false;
      if (!test(e.a, e.b)) {
        e.state = kTestedApart;
        return false;
      }
      e.state = kTestedOverlap;
      return leaves(e.a, e.b) == Walk::stop;
    };
    const auto stop_here = [&](std::size_t k, std::size_t tested) {  // the front stays as it is
      for (std::size_t j = 0; j < tested; ++j) front[j].state = kFresh;
      front[k].state = kFresh;
      if (st.witness < front.size()) front[st.witness].state = kFresh;
      st.witness = static_cast<std::uint32_t>(k);
      return Walk::stop;
    };
    if (st.witness < front.size() && pretest(st.witness)) return stop_here(st.witness, 0);
    for (std::size_t k = 0; k < front.size(); ++k)
      if (pretest(k)) return stop_here(k, k);
  }

  // Appends an entry found apart in this query, lifting while the last two entries are siblings
  // that have both been apart long enough and whose parent pair is apart too (Ehmann & Lin's
  // front propagation upwards). A parent that still overlaps raises both siblings' back-off.
  const auto push_apart = [&](FrontEntry e) {
    next.push_back(e);
    while (next.size() >= 2) {
      FrontEntry& y = next.back();
      FrontEntry& x = next[next.size() - 2];
      if (x.culled < (1u << x.level) || y.culled < (1u << y.level)) return;
      std::uint32_t pa = kNoNode, pb = kNoNode;
      if (x.a == y.a && x.b != y.b && st.parent_b[x.b] == st.parent_b[y.b] && st.parent_b[x.b] != kNoNode) {
        pa = x.a;
        pb = st.parent_b[x.b];
      } else if (x.b == y.b && x.a != y.a && st.parent_a[x.a] == st.parent_a[y.a] && st.parent_a[x.a] != kNoNode) {
        pa = st.parent_a[x.a];
        pb = x.b;
      } else {
        return;
      }
      if (test(pa, pb)) {
        x.level = std::min<std::uint8_t>(x.level + 1, kMaxLiftLevel);
        y.level = std::min<std::uint8_t>(y.level + 1, kMaxLiftLevel);
        x.culled = y.culled = 0;
        return;
      }
      const FrontEntry parent{pa, pb, std::min(x.culled, y.culled), 0, kFresh};
      next.pop_back();
      next.back() = parent;
    }
  };
  const auto bump = [](std::uint16_t c) { return static_cast<std::uint16_t>(c == 0xffff ? c : c + 1); };

  // On a stop, the rest of the descent stack and of the old front stay in the front untested.
  const auto keep_rest = [&](std::size_t from) {
    st.witness = static_cast<std::uint32_t>(next.size() - 1);
    for (std::size_t k = stack.size(); k-- > 0;) {
      next.push_back(stack[k]);
      next.back().state = kFresh;
    }
    for (std::size_t k = from; k < front.size(); ++k) {
      next.push_back(front[k]);
      next.back().state = kFresh;
    }
    front.swap(next);
    return Walk::stop;
  };

  for (std::size_t i = 0; i < front.size(); ++i) {
    FrontEntry e = front[i];
    bool overlap;
    if (e.state == kFresh) {
      overlap = test(e.a, e.b);
    } else {  // a leaf pair tested ahead (its triangles were tested too)
      overlap = e.state == kTestedOverlap;
      e.state = kFresh;
      if (overlap) {
        next.push_back(e);
        continue;
      }
    }
    if (!overlap) {
      e.culled = bump(e.culled);
      push_apart(e);
      continue;
    }
    e.culled = 0;
    stack.clear();
    stack.push_back(e);
    while (!stack.empty()) {
      FrontEntry q = stack.back();
      stack.pop_back();
      if (q.state == kUntested) {  // a child of an overlapping pair (the front entry itself was tested above)
        q.state = kFresh;
        if (!test(q.a, q.b)) {
          q.culled = 1;
          q.level = 1;  // its parent overlapped just now: no lift before the next query
          push_apart(q);
          continue;
        }
      }
      const Node& na = ta.nodes[q.a];
      const Node& nb = tb.nodes[q.b];
      if (na.is_leaf() && nb.is_leaf()) {
        q.culled = 0;
        next.push_back(q);
        if (leaves(q.a, q.b) == Walk::stop) return keep_rest(i + 1);
        continue;
      }
      // Split as traverse_pairs does (first child popped first: the same depth-first order).
      const bool split_a =
          nb.is_leaf() || (!na.is_leaf() && descend_size(na.box, rule) >= descend_size(nb.box, rule));
      if (split_a) {
        stack.push_back({na.first + 1, q.b, 0, 0, kUntested});
        stack.push_back({na.first, q.b, 0, 0, kUntested});
      } else {
        stack.push_back({q.a, nb.first + 1, 0, 0, kUntested});
        stack.push_back({q.a, nb.first, 0, 0, kUntested});
      }
    }
  }
  st.witness = kNoNode;
  front.swap(next);
  return Walk::go_on;
}

}  // namespace query_detail
}  // namespace tightbvh
