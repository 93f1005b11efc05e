#pragma once
// Internal: the scratch buffers behind QueryWorkspace (reused between queries).
#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "tightbvh/compact_box.hpp"
#include "tightbvh/math.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/query_workspace.hpp"
#include "traverse.hpp"

namespace tightbvh {
namespace query_detail {

// B's boxes mapped into A's frame, computed lazily once per query and node; an entry is valid
// when its stamp equals the query's epoch, so a new query needs no clearing.
struct MappedBox {
  // Left uninitialised on purpose (an entry is read only after `mapped` wrote it): a defaulted
  // constructor would make vector::resize zero the whole cache, 96 bytes per node of B, and page
  // faults on it cost more than a batch of cheap queries (a separated query touches a few
  // dozen entries, each worker's first resize all 1.2 MB of knot1's).
  MappedBox() {}  // NOLINT(modernize-use-equals-default)
  Mat3 axes;
  Vec3 center;
};
struct BoxCache {
  std::vector<MappedBox> boxes;
  std::vector<std::uint32_t> stamp;
  std::uint32_t epoch = 0;

  // Node `i`'s box `box` of B mapped by `rel` (B's frame to A's frame).
  const MappedBox& mapped(std::uint32_t i, const CompactBox& box, const Pose& rel) {
    MappedBox& m = boxes[i];
    if (stamp[i] != epoch) {
      stamp[i] = epoch;
      m.axes.noalias() = rel.rotation * box.axes_d();
      m.center.noalias() = rel.rotation * box.center_d() + rel.translation;
    }
    return m;
  }

  void begin(std::size_t nodes) {
    if (boxes.size() < nodes) {
      boxes.resize(nodes);
      stamp.resize(nodes, 0);
    }
    if (++epoch == 0) {  // wrapped: invalidate everything once
      std::fill(stamp.begin(), stamp.end(), 0);
      epoch = 1;
    }
  }
};

// A node pair of the distance descent with its lower bound (distance.cpp).
struct BoundedPair {
  std::uint32_t a, b;
  double bound;
};

// distance()'s search queue: a radix heap (Ahuja, Mehlhorn, Orlin & Tarjan 1990) of node pairs by
// bound. A monotone queue: every pair pushed has a bound at least the last one popped (the search
// raises a child's bound to its parent's, still a lower bound, since the child's triangles are
// among the parent's). Bounds are >= +0, whose bit patterns order as the values do; bucket k > 0
// holds the pairs whose key first differs from the last popped key at bit k - 1, bucket 0 those
// equal to it. A push is one bucket append with no data-dependent branch (a binary heap's sift
// compares at every level, each close to a coin toss); a pair is moved only when its bucket is
// the least non-empty one, and about half the pairs pushed are never popped (the search ends
// when the least bound is prunable), so most are never moved.
class RadixQueue {
 public:
  void clear() {
    for (std::uint64_t m = occupied_; m != 0; m &= m - 1) buckets_[std::countr_zero(m)].clear();
    occupied_ = 0;
    last_ = 0;
    size_ = 0;
  }
  [[nodiscard]] bool empty() const { return size_ == 0; }
  void push(const BoundedPair& x) {
    const int k = std::bit_width(key(x.bound) ^ last_);  // 0..63: bounds are >= +0
    buckets_[k].push_back(x);
    occupied_ |= std::uint64_t{1} << k;
    ++size_;
  }
  // Removes and returns the least pair (not empty()); its bound is then the least a push may
  // have.
  BoundedPair pop() {
    if (buckets_[0].empty()) settle();
    const BoundedPair x = buckets_[0].back();
    buckets_[0].pop_back();
    if (buckets_[0].empty()) occupied_ &= ~std::uint64_t{1};
    --size_;
    return x;
  }

 private:
  static std::uint64_t key(double bound) { return std::bit_cast<std::uint64_t>(bound); }
  // Bucket 0 is empty: the least pair is in the least non-empty bucket; it becomes the last key
  // and that bucket's pairs move to lower buckets (to bucket 0 those equal to it).
  void settle() {
    const int b = std::countr_zero(occupied_ & ~std::uint64_t{1});
    std::vector<BoundedPair>& from = buckets_[b];
    std::uint64_t least = key(from[0].bound);
    for (const BoundedPair& x : from) least = std::min(least, key(x.bound));
    last_ = least;
    for (const BoundedPair& x : from) {
      const int k = std::bit_width(key(x.bound) ^ last_);
      buckets_[k].push_back(x);
      occupied_ |= std::uint64_t{1} << k;
    }
    from.clear();
    occupied_ &= ~(std::uint64_t{1} << b);
  }

  std::vector<BoundedPair> buckets_[64];
  std::uint64_t occupied_ = 0;
  std::uint64_t last_ = 0;
  std::size_t size_ = 0;
};

}  // namespace query_detail

namespace query_detail {
// distance()'s search over wide nodes: a node of each tree (wide_nodes.hpp) with their reference
// points; the queue's entries name one of these and a lane of each node (distance.cpp).
struct WideSearchItem {
  Vec3 ref_a, ref_b;
  std::uint32_t a_node, b_node;
};
}  // namespace query_detail

struct QueryWorkspace::Scratch {
  query_detail::PairStack stack;
  query_detail::TestedPairStack tested_stack;
  query_detail::BoxCache mapped_b;
  std::vector<query_detail::BoundedPair> distance_stack;
  query_detail::RadixQueue distance_queue;
  std::vector<query_detail::WideSearchItem> wide_items;
};

}  // namespace tightbvh
