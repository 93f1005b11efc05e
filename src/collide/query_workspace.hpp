#pragma once
// Internal: the scratch buffers behind QueryWorkspace (reused between queries).
#include <algorithm>
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

}  // namespace query_detail

struct QueryWorkspace::Scratch {
  query_detail::PairStack stack;
  query_detail::TestedPairStack tested_stack;
  query_detail::BoxCache mapped_b;
  std::vector<query_detail::BoundedPair> distance_stack;
};

}  // namespace tightbvh
