#pragma once
// Internal: all_pairs' triangle pairs queued for the four-lane test (tri_tri4.hpp), shared by
// collide() and the cost model's replay (bench/collide/collide_bench.cpp).
#include "../geometry/predicates.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/tri_tri.hpp"
#include "tri_tri4.hpp"

namespace tightbvh::query_detail {

// The lanes decide exactly where the scalar filter would: the same bound.
static_assert(kTriLanesFilterBound == detail::kOrient3dBound);

// The triangle pairs of an all_pairs query waiting for tri_tri_overlap4_avx2 (tri_tri4.hpp): an
// all_pairs walk tests every leaf pair and never stops, so its tests can wait and go four at a
// time. The filter decides most pairs in the lanes (lanes within rounding of touching go to the
// exact scalar test), without the scalar test's unpredictable branches on the corners' sides.
class TrianglePairBatch {
 public:
  // Queues a pair (q's corners already in A's frame); tests the four when full.
  void add(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& q0, const Vec3& q1, const Vec3& q2,
           TrianglePair ids, QueryResult& result) {
    const Vec3* corners[6] = {&p0, &p1, &p2, &q0, &q1, &q2};
    for (int k = 0; k < 6; ++k)
      for (int i = 0; i < 3; ++i) lanes_.c[3 * k + i][size_] = (*corners[k])[i];
    ids_[size_] = ids;
    if (++size_ == 4) flush(result);
  }
  // Tests the queued pairs, reporting those that touch.
  void flush(QueryResult& result) {
    if (size_ == 0) return;
    for (int lane = size_; lane < 4; ++lane)  // unused lanes repeat lane 0; their answers are dropped
      for (auto& value : lanes_.c) value[lane] = value[0];
#ifdef TIGHTBVH_AVX2_BOUNDS
    const int answer = tri_tri_overlap4_avx2(lanes_);
#else
    const int answer = 0;  // no lanes here (callers queue only where avx2_bounds_available()): all exact
#endif
    const unsigned used = (1u << size_) - 1u;
    const unsigned undecided = ~static_cast<unsigned>(answer) & used;
    unsigned touch = (static_cast<unsigned>(answer) >> 4) & used & ~undecided;  // the lanes' answers
    if (undecided != 0)  // within rounding of touching: the exact test
      for (int lane = 0; lane < size_; ++lane)
        if ((undecided >> lane & 1u) != 0 && exact(lane)) touch |= 1u << lane;
    // The touching pairs appended without a branch on each answer (which the predictor cannot
    // know): every pair is written, and the end moves past those that touch.
    result.hit = result.hit || touch != 0;
    const std::size_t reported = result.pairs.size();
    result.pairs.resize(reported + static_cast<std::size_t>(size_));
    TrianglePair* out = result.pairs.data() + reported;
    for (int lane = 0; lane < size_; ++lane) {
      *out = ids_[lane];
      out += (touch >> lane) & 1u;
    }
    result.pairs.resize(static_cast<std::size_t>(out - result.pairs.data()));
    size_ = 0;
  }

 private:
  [[nodiscard]] Vec3 corner(int lane, int k) const {
    return {lanes_.c[3 * k][lane], lanes_.c[3 * k + 1][lane], lanes_.c[3 * k + 2][lane]};
  }
  [[nodiscard]] bool exact(int lane) const {
    return tri_tri_overlap(corner(lane, 0), corner(lane, 1), corner(lane, 2), corner(lane, 3), corner(lane, 4),
                           corner(lane, 5));
  }

  TriPairs4 lanes_;
  TrianglePair ids_[4];
  int size_ = 0;
};

}  // namespace tightbvh::query_detail
