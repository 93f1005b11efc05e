#pragma once
// Internal: the one descent over node pairs of two trees, shared by the tree-vs-tree queries
// (in the style of madmann91/bvh's traverse_top_down and Jolt's WalkTree + visitor). The
// query supplies what differs, as callables that inline (no std::function, no virtual):
//   test(a, b) -> bool        may the node pair (indices into ta.nodes, tb.nodes) hold an
//                             answer? false culls it (the query counts its own tests);
//   leaves(a, b) -> Walk      both nodes are leaves (ranges: ta.nodes[a].first/count into
//                             ta.triangle_order, same for b); Walk::stop ends the descent.
// Order: depth first from (0, 0); of an internal pair the larger node (DescendRule) is split,
// its first child visited first, or both nodes when they are of about one size (choose_split).
// A walk given a NearestFirst order (first hit) visits a split's overlapping child pairs nearest
// first, then its culled ones (sort_nearest_first). Queries rely on this order for their first hit and stats.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "tightbvh/collide.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh::query_detail {

enum class Walk : bool { go_on, stop };

struct NodePair {
  std::uint32_t a, b;
};

// A node pair whose box test passed when its split made it (traverse_pairs_tested), with the
// number of culled pairs that traverse_pairs would have popped, and counted, right before it
// (64 bits: the pair under a large subtree collects that subtree's trailing culled pairs).
struct TestedPair {
  std::uint32_t a, b;
  std::uint64_t culled_before;
};

// Explicit traversal stack: a fixed inline buffer, spilling to the heap only for very deep trees.
template <class Pair>
class BasicPairStack {
 public:
  void clear() {
    size_ = 0;
    spill_.clear();
  }
  void push(Pair p) {
    if (size_ < inline_.size()) {
      inline_[size_++] = p;
    } else {
      spill_.push_back(p);
      ++size_;
    }
  }
  [[nodiscard]] bool empty() const { return size_ == 0; }
  // The pair pop() would return (not empty()).
  [[nodiscard]] Pair& top() { return size_ > inline_.size() ? spill_.back() : inline_[size_ - 1]; }
  Pair pop() {
    --size_;
    if (size_ >= inline_.size()) {
      const Pair p = spill_.back();
      spill_.pop_back();
      return p;
    }
    return inline_[size_];
  }

 private:
  std::array<Pair, 256> inline_;
  std::vector<Pair> spill_;
  std::size_t size_ = 0;
};
using PairStack = BasicPairStack<NodePair>;
using TestedPairStack = BasicPairStack<TestedPair>;

// The size that DescendRule compares.
[[nodiscard]] inline double descend_size(const CompactBox& box, DescendRule rule) {
  const Vec3 e = box.half_extents_d();
  return rule == DescendRule::larger_volume ? e.prod() : e.maxCoeff();
}

// Whether a pair of nodes (not both leaves) descends into A's children: A is the larger by the
// rule, or B is a leaf.
[[nodiscard]] inline bool splits_a(const Node& na, const Node& nb, DescendRule rule) {
  return nb.is_leaf() || (!na.is_leaf() && descend_size(na.box, rule) >= descend_size(nb.box, rule));
}

// Of two nodes of about one size (within this ratio by the descend rule's measure) both are split
// at once: their four child pairs are tested together (boxes_overlap_cross: four AVX2 lanes for
// about the time of two SSE2 lanes), and where both children of the first split overlap the other
// node (most splits in deep overlap) the two tests of the intermediate pairs are saved. Of the
// ratios 2, 4, 8, 16 and any, measured on the shipped pair (docs/design-notes/collide.md,
// "Split both nodes when they are of about one size"), 8 is fastest or within noise of it in every
// scenario and mode. (distance()'s search has its own.)
inline constexpr double kSplitBothRatio = 8.0;

enum class Split {
  a,            // A's children against B
  b,            // A against B's children
  both_a_first, // the four child pairs, A's first child's two pairs first
  both_b_first, // the four child pairs, B's first child's two pairs first
};

// How a pair of nodes (not both leaves) is split: the larger node by the rule (A on a tie), or
// both when they are of about one size; the order of the four pairs is the one of splitting the
// larger node first, then the other. `ratio`: the sizes' limit for splitting both (distance()'s
// search uses its own).
[[nodiscard]] inline Split choose_split(const Node& na, const Node& nb, DescendRule rule,
                                        double ratio = kSplitBothRatio) {
  if (nb.is_leaf()) return Split::a;
  if (na.is_leaf()) return Split::b;
  const double sa = descend_size(na.box, rule), sb = descend_size(nb.box, rule);
  const bool a_larger = sa >= sb;
  if (sa <= ratio * sb && sb <= ratio * sa)
    return a_larger ? Split::both_a_first : Split::both_b_first;
  return a_larger ? Split::a : Split::b;
}

[[nodiscard]] inline bool splits_both(Split split) {
  return split == Split::both_a_first || split == Split::both_b_first;
}

// The four child pairs of a split of both nodes, in visiting order.
[[nodiscard]] inline std::array<NodePair, 4> both_children(const Node& na, const Node& nb, Split split) {
  const std::uint32_t a0 = na.first, a1 = na.first + 1, b0 = nb.first, b1 = nb.first + 1;
  if (split == Split::both_a_first) return {{{a0, b0}, {a0, b1}, {a1, b0}, {a1, b1}}};
  return {{{a0, b0}, {a1, b0}, {a0, b1}, {a1, b1}}};
}

// The order of a split's child pairs for a walk that stops at its first hit: those whose boxes
// overlap first, nearest first (gap(a, b): the squared distance of their box centers in A's
// frame; ties in both_children's order), then those culled. A first hit is found where the
// surfaces cross; of two overlapping child pairs, the one whose centers are closer is the more
// likely to hold a crossing, and the walk need not visit the other. On the bench's deep-overlap
// poses first_hit makes 45-72% fewer box tests (elephant/knot1 auto trees: 148 -> 62 a query)
// and takes 23-41% less time, near contact 3-24% fewer tests; separated poses make the same
// tests, 2-5% slower. Culled pairs go last so that a split with fewer than two overlapping pairs
// (most splits apart from contact) computes no gap, and the pairs are picked with branches that
// predict "culled" there: ordering every pair by gap cost separated first_hit 17-60% of its time,
// a branch-free pick of the overlapping pairs 10%. The depth of overlap (the least SAT slack of
// the 15 axes) orders about as well but is not free. docs/design-notes/collide.md,
// "Descent order: nearest first in first_hit".
struct NoGap {};
inline constexpr int kMaxChildPairs = 4;

// Orders pairs[0..m) (2 <= m <= 4) by gap, ascending, stable.
template <class Pair, class Gap>
inline void sort_nearest_first(Pair* pairs, int m, Gap&& gap) {
  if (m == 2) {  // most splits: a select, not a branch (the outcome is a coin toss)
    const bool swap = gap(pairs[1].a, pairs[1].b) < gap(pairs[0].a, pairs[0].b);
    const Pair p0 = pairs[0], p1 = pairs[1];
    pairs[0] = swap ? p1 : p0;
    pairs[1] = swap ? p0 : p1;
    return;
  }
  double key[kMaxChildPairs];
  for (int k = 0; k < m; ++k) key[k] = gap(pairs[k].a, pairs[k].b);
  for (int k = 1; k < m; ++k)
    for (int j = k; j > 0 && key[j] < key[j - 1]; --j) {
      std::swap(key[j], key[j - 1]);
      std::swap(pairs[j], pairs[j - 1]);
    }
}

// traverse_pairs' order for a walk that stops at its first hit: `gap` as above, and
// `overlaps(a, b)`, the node test without its bookkeeping (the order needs every outcome of a
// split before the walk visits, and counts, its pairs one by one).
template <class Gap, class Overlaps>
struct NearestFirst {
  Gap gap;
  Overlaps overlaps;
};

// Walks the node pairs of non-empty trees ta x tb. Returns Walk::stop when `leaves` stopped it.
// `stack` is scratch (cleared here, so a stack left over by a stopped walk is fine).
// With `order` a NearestFirst (not NoGap) a split's child pairs are visited in its order.
template <class NodeTest, class LeafPair, class Order = NoGap>
Walk traverse_pairs(const Tree& ta, const Tree& tb, DescendRule rule, PairStack& stack, NodeTest&& test,
                    LeafPair&& leaves, Order&& order = {}) {
  constexpr bool nearest = !std::is_same_v<std::remove_cvref_t<Order>, NoGap>;
  stack.clear();
  stack.push({0, 0});
  while (!stack.empty()) {
    const NodePair np = stack.pop();
    if (!test(np.a, np.b)) continue;
    const Node& na = ta.nodes[np.a];
    const Node& nb = tb.nodes[np.b];
    if (na.is_leaf() && nb.is_leaf()) {
      if (leaves(np.a, np.b) == Walk::stop) return Walk::stop;
      continue;
    }
    // Descend into the larger node (or the only internal one), or both.
    const Split split = choose_split(na, nb, rule);
    NodePair kids[kMaxChildPairs];
    int n = 2;
    if (split == Split::a) {
      kids[0] = {na.first, np.b};
      kids[1] = {na.first + 1, np.b};
    } else if (split == Split::b) {
      kids[0] = {np.a, nb.first};
      kids[1] = {np.a, nb.first + 1};
    } else {
      const std::array<NodePair, 4> four = both_children(na, nb, split);
      std::copy(four.begin(), four.end(), kids);
      n = 4;
    }
    if constexpr (nearest) {  // overlapping pairs nearest first, then the culled ones
      bool overlap[kMaxChildPairs];
      for (int k = 0; k < n; ++k) overlap[k] = order.overlaps(kids[k].a, kids[k].b);
      NodePair sorted[kMaxChildPairs];
      int m = 0;
      for (int k = 0; k < n; ++k)
        if (overlap[k]) sorted[m++] = kids[k];
      if (m >= 2) sort_nearest_first(sorted, m, order.gap);
      for (int k = 0, c = m; k < n; ++k)
        if (!overlap[k]) sorted[c++] = kids[k];
      std::copy(sorted, sorted + n, kids);
    }
    for (int k = n - 1; k >= 0; --k) stack.push(kids[k]);
  }
  return Walk::go_on;
}

// traverse_pairs with the box tests of a split made together: a split tests both child pairs at
// once (test_children_a(a_first, b) for A's children a_first, a_first + 1 against b, or
// test_children_b(a, b_first)), each returning {first pair overlaps, second pair overlaps}, or
// all four of a split of both nodes (test_children_both(na, nb, a_major) -> four overlaps in
// both_children's order);
// test(a, b) tests the root pair. The pairs are visited in traverse_pairs' order, and `box_tests`
// counts what traverse_pairs' test would have counted, also when `leaves` stops the walk (first
// hit, CanStop): only the pairs that overlap are pushed. A walk that cannot stop counts every test
// when it makes it; one that can stop counts a culled pair when the overlapping
// pair that traverse_pairs would pop next after it is popped (that pair's culled_before; a split's
// culled pairs after its last overlapping one go to the pair under them on the stack, or to the
// end of the walk). So a stopped walk counts no test that traverse_pairs would not have made, and
// first_hit does not push and pop its culled pairs (pushing them to count them at the pop costs
// 4-13% of its time, docs/design-notes/collide.md,
// "The descent's bookkeeping and the early exits"). Pushes branch on each outcome: a branch-free
// push (write the slot, advance by the outcome) is 4-10% faster in all_pairs near contact and in
// overlap but 5-10% slower in separated scenarios, where nearly every outcome is "culled" and
// predicted, so the next pop runs ahead of the box test; branch-free, its address waits for it. A
// walk that can stop, given a `gap`, pushes a split's overlapping child pairs nearest first and
// counts its culled ones after them (traverse_pairs' NearestFirst order).
template <bool CanStop, class NodeTest, class ChildrenA, class ChildrenB, class ChildrenBoth, class LeafPair,
          class Gap = NoGap>
Walk traverse_pairs_tested(const Tree& ta, const Tree& tb, DescendRule rule, TestedPairStack& stack,
                           std::uint64_t& box_tests, NodeTest&& test, ChildrenA&& test_children_a,
                           ChildrenB&& test_children_b, ChildrenBoth&& test_children_both, LeafPair&& leaves,
                           Gap&& gap = {}) {
  constexpr bool nearest = CanStop && !std::is_same_v<std::remove_cvref_t<Gap>, NoGap>;
  stack.clear();
  if (!test(0u, 0u)) {
    ++box_tests;
    return Walk::go_on;
  }
  if constexpr (!CanStop) ++box_tests;
  stack.push({0, 0, 0});  // first hit: counted when popped
  std::uint64_t after_last = 0;  // culled pairs after every pair on the stack
  // Pushes kids[0..n) in reverse (kids[0] is popped first), those that overlap only.
  const auto push_overlapping = [&](const TestedPair* kids, const bool* overlap, int n) {
    if constexpr (nearest) {  // overlapping pairs nearest first, then the culled ones (trailing)
      if (n == 2) {  // a split of one node: branches on the outcomes, as the pushes below (predicted
                     // "culled" apart from contact); the gaps only when both pairs overlap
        if (overlap[0] && overlap[1]) {
          const bool swap = gap(kids[1].a, kids[1].b) < gap(kids[0].a, kids[0].b);
          const TestedPair first = swap ? kids[1] : kids[0], second = swap ? kids[0] : kids[1];
          stack.push({second.a, second.b, 0});
          stack.push({first.a, first.b, 0});
          return;
        }
        const std::uint64_t trailing = overlap[0] || overlap[1] ? 1 : 2;
        if (stack.empty())
          after_last += trailing;
        else
          stack.top().culled_before += trailing;
        if (overlap[0]) stack.push({kids[0].a, kids[0].b, 0});
        if (overlap[1]) stack.push({kids[1].a, kids[1].b, 0});
        return;
      }
      TestedPair entry[kMaxChildPairs];
      int m = 0;
      for (int k = 0; k < n; ++k)
        if (overlap[k]) entry[m++] = {kids[k].a, kids[k].b, 0};
      if (m >= 2) sort_nearest_first(entry, m, gap);
      if (const int trailing = n - m; trailing != 0) {
        if (stack.empty())
          after_last += static_cast<std::uint64_t>(trailing);
        else
          stack.top().culled_before += static_cast<std::uint64_t>(trailing);
      }
      for (int k = m - 1; k >= 0; --k) stack.push(entry[k]);
      return;
    }
    if constexpr (!CanStop) {
      box_tests += static_cast<std::uint64_t>(n);  // every pushed pair is popped: count them now
      for (int k = n - 1; k >= 0; --k)
        if (overlap[k]) stack.push(kids[k]);
      return;
    }
    std::uint64_t trailing = 0;  // culled since the last overlapping kid
    TestedPair entry[4];
    for (int k = 0; k < n; ++k) {
      entry[k] = {kids[k].a, kids[k].b, trailing};
      trailing = overlap[k] ? 0 : trailing + 1;
    }
    if (trailing != 0) {
      if (stack.empty())
        after_last += trailing;
      else
        stack.top().culled_before += trailing;
    }
    for (int k = n - 1; k >= 0; --k)
      if (overlap[k]) stack.push(entry[k]);
  };
  while (!stack.empty()) {
    const TestedPair np = stack.pop();
    if constexpr (CanStop) box_tests += 1 + np.culled_before;
    const Node& na = ta.nodes[np.a];
    const Node& nb = tb.nodes[np.b];
    if (na.is_leaf() && nb.is_leaf()) {
      if (leaves(np.a, np.b) == Walk::stop) return Walk::stop;
      continue;
    }
    const Split split = choose_split(na, nb, rule);
    if (splits_both(split)) {
      const std::array<NodePair, 4> pairs = both_children(na, nb, split);
      const std::array<bool, 4> overlap = test_children_both(na, nb, split == Split::both_a_first);
      const TestedPair kids[4] = {{pairs[0].a, pairs[0].b, 0}, {pairs[1].a, pairs[1].b, 0},
                                  {pairs[2].a, pairs[2].b, 0}, {pairs[3].a, pairs[3].b, 0}};
      push_overlapping(kids, overlap.data(), 4);
      continue;
    }
    TestedPair kids[2];
    bool overlap[2];
    if (split == Split::a) {
      const auto [o0, o1] = test_children_a(na.first, np.b);
      kids[0] = {na.first, np.b, 0};
      kids[1] = {na.first + 1, np.b, 0};
      overlap[0] = o0;
      overlap[1] = o1;
    } else {
      const auto [o0, o1] = test_children_b(np.a, nb.first);
      kids[0] = {np.a, nb.first, 0};
      kids[1] = {np.a, nb.first + 1, 0};
      overlap[0] = o0;
      overlap[1] = o1;
    }
    push_overlapping(kids, overlap, 2);
  }
  box_tests += after_last;
  return Walk::go_on;
}

}  // namespace tightbvh::query_detail
