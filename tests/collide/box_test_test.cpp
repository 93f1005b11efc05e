// collide()'s box tests (src/collide/box_test.hpp): the one-pair test, both lanes of the two-pair
// SIMD test and the four lanes of the four-pair test (AVX2 where the CPU has it) decide exactly
// as obb_overlap() on the same box frame, on random pairs and on pairs at the very boundary
// (adjacent doubles of a translation on either side of the flip), where any difference in the
// arithmetic would show. That collide() (batched tests) and
// collide_trace() (one-pair tests) make the same descent is tests/collide/trace_test.cpp.
#include "collide/box_test.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "tightbvh/compact_box.hpp"
#include "tightbvh/obb_distance.hpp"
#include "tightbvh/obb_overlap.hpp"
#include "tightbvh/pose.hpp"

namespace tightbvh {
namespace {

using query_detail::MappedBox;

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
}

// The reference: obb_overlap() on B's mapped box in A's box frame, the frame written out as the
// kernel documents it (r = Aa^T M, t = Aa^T (cm - ca), sums left to right).
bool reference(const CompactBox& a, const MappedBox& m, const Eigen::Vector3f& eb, double margin) {
  const Mat3 aa = a.axes_d();
  const Vec3 diff = m.center - a.center_d();
  Mat3 r;
  Vec3 t;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = aa(0, i) * m.axes(0, j) + aa(1, i) * m.axes(1, j) + aa(2, i) * m.axes(2, j);
    t[i] = aa(0, i) * diff[0] + aa(1, i) * diff[1] + aa(2, i) * diff[2];
  }
  return obb_overlap(r, t, a.half_extents_d(), eb.cast<double>(), margin);
}

struct Case {
  CompactBox a;
  MappedBox m;
  Eigen::Vector3f eb;
  double margin;
};

MappedBox mapped(const CompactBox& b, const Pose& rel) {
  MappedBox m;
  m.axes = rel.rotation * b.axes_d();
  m.center = rel.rotation * b.center_d() + rel.translation;
  return m;
}

// Random boxes; half of them then slid along a random direction to the last translation at which
// obb_overlap() still reports overlap, or the first at which it does not (bisection down to
// adjacent doubles), so the decisive axis is decided by the last bit.
std::vector<Case> cases(int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Case> out;
  while (static_cast<int>(out.size()) < count) {
    const auto extent = [&] {  // some flat boxes, as leaves of planar regions are
      return u(rng) < 0.1 ? 0.0 : 0.01 + u(rng);
    };
    const double scale = std::pow(10.0, 4.0 * u(rng) - 2.0);
    const Obb ba{Vec3(u(rng), u(rng), u(rng)) * scale, random_rotation(rng),
                 Vec3(extent(), extent(), extent()) * scale};
    const Obb bb{Vec3(u(rng), u(rng), u(rng)) * scale, u(rng) < 0.1 ? Mat3(Mat3::Identity()) : random_rotation(rng),
                 Vec3(extent(), extent(), extent()) * scale};
    // Sometimes B's axes equal A's (parallel edges, the kSatEpsilon case).
    const Pose rel{u(rng) < 0.1 ? Mat3(Mat3::Identity()) : random_rotation(rng), Vec3(u(rng), u(rng), u(rng)) * scale};
    Case c{nearest_compact_box(ba), {}, nearest_compact_box(bb).half_extents, u(rng) < 0.5 ? 0.0 : 1e-9 * scale};
    const CompactBox cb = nearest_compact_box(bb);
    c.m = mapped(cb, rel);
    if (out.size() % 2 == 0) {
      out.push_back(c);
      continue;
    }
    // Boundary: slide B from overlapping (s = 0, centers close) outwards until it flips.
    c.m.center = c.a.center_d();
    if (!reference(c.a, c.m, c.eb, c.margin)) continue;
    Vec3 dir(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    if (out.size() % 3 == 0) dir = c.a.axes_d().col(out.size() % 5 % 3);  // along one of A's faces
    dir.normalize();
    const Vec3 c0 = c.m.center;
    double lo = 0.0, hi = 10.0 * scale;  // overlapping at lo, apart at hi
    const auto at = [&](double s) {
      Case k = c;
      k.m.center = c0 + s * dir;
      return k;
    };
    if (reference(c.a, at(hi).m, c.eb, c.margin)) continue;
    while (std::nextafter(lo, hi) < hi) {
      const double mid = lo + (hi - lo) / 2;
      if (mid <= lo || mid >= hi) break;
      (reference(c.a, at(mid).m, c.eb, c.margin) ? lo : hi) = mid;
    }
    out.push_back(at(out.size() % 4 == 1 ? lo : hi));
  }
  return out;
}

TEST(BoxTest, OnePairAndBothLanesDecideAsObbOverlap) {
  const std::vector<Case> all = cases(20000, 7);
  int overlapping = 0, mismatches = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Case& c = all[i];
    const bool expected = reference(c.a, c.m, c.eb, c.margin);
    overlapping += expected;
    EXPECT_EQ(query_detail::box_overlap(c.a, c.m, c.eb, c.margin), expected) << "case " << i;
    EXPECT_EQ(query_detail::box_overlap_grouped(c.a, c.m, c.eb, c.margin), expected) << "case " << i;
    // This case in lane 0 and in lane 1, next to another case (a different margin is not a
    // lane's: the two lanes of a query share it, so the neighbour takes this margin too).
    const Case& o = all[(i * 7919 + 13) % all.size()];
    const bool other = reference(o.a, o.m, o.eb, c.margin);
    const auto l0 = query_detail::boxes_overlap2(c.a, c.m, c.eb, o.a, o.m, o.eb, c.margin);
    const auto l1 = query_detail::boxes_overlap2(o.a, o.m, o.eb, c.a, c.m, c.eb, c.margin);
    mismatches += (l0[0] != expected) + (l0[1] != other) + (l1[1] != expected) + (l1[0] != other);
    EXPECT_EQ(l0[0], expected) << "case " << i;
    EXPECT_EQ(l1[1], expected) << "case " << i;
    // One node against two of the other tree, as a split tests them: shared A, shared B.
    const auto shared_a = query_detail::boxes_overlap2(c.a, c.m, c.eb, c.a, o.m, o.eb, c.margin);
    const auto shared_b = query_detail::boxes_overlap2(c.a, c.m, c.eb, o.a, c.m, c.eb, c.margin);
    EXPECT_EQ(shared_a[0], expected);
    EXPECT_EQ(shared_a[1], reference(c.a, o.m, o.eb, c.margin));
    EXPECT_EQ(shared_b[0], expected);
    EXPECT_EQ(shared_b[1], reference(o.a, c.m, c.eb, c.margin));
    // Four lanes (a split of both nodes: A's two children against B's two, in either order), on
    // the AVX2 path where this CPU has it and on the two-lane fallback; this case's A box first
    // or second, against its own B box and another case's.
    const Case& p = all[(i * 104729 + 7) % all.size()];
    const bool c_first = i % 2 == 0;
    const query_detail::ChildBoxes boxes{{c_first ? &c.a : &p.a, c_first ? &p.a : &c.a}, {&c.m, &o.m}, {&c.eb, &o.eb}};
    for (const bool a_major : {true, false})
      for (const bool avx2 : {false, query_detail::avx2_bounds_available()}) {
        const auto l4 = query_detail::boxes_overlap_cross(boxes, a_major, c.margin, avx2);
        for (int k = 0; k < 4; ++k) {
          const int ia = a_major ? k / 2 : k % 2, ib = a_major ? k % 2 : k / 2;  // both_children's order
          EXPECT_EQ(l4[k], reference(*boxes.a[ia], *boxes.mb[ib], *boxes.eb[ib], c.margin))
              << "case " << i << ", lane " << k << (a_major ? ", A major" : ", B major") << (avx2 ? ", AVX2" : "");
        }
      }
  }
  EXPECT_EQ(mismatches, 0);
  // Both outcomes well represented (the boundary cases alternate sides).
  EXPECT_GT(overlapping, 4000);
  EXPECT_LT(overlapping, 16000);
}

// distance()'s bound in lanes (box_distance_bound, box_distance_bounds2, box_distance_bounds4,
// box_distance_bounds_cross):
// the scalar lane equals obb_distance_lower_bound() on the same box frame up to rounding (1e-12
// relative to the boxes' size; the query shrinks it by kCompactBoxSlack = 1e-5), and each SIMD
// lane (two SSE2, four AVX2) is the scalar lane bit for bit, next to any other pair. Cases: the
// boxes above, and the same pushed apart (B's center moved away from A's by 1x and 3x their
// offset), so most bounds are positive.
TEST(BoxTest, DistanceBoundLanesMatchObbDistanceLowerBound) {
  std::vector<Case> all;
  for (const Case& c : cases(6000, 9)) {
    all.push_back(c);
    for (const double push : {1.0, 3.0}) {
      Case far = c;
      far.m.center = c.m.center + push * (c.m.center - c.a.center_d());
      all.push_back(far);
    }
  }
  int positive = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Case& c = all[i];
    const Mat3 aa = c.a.axes_d();
    const Vec3 diff = c.m.center - c.a.center_d();
    Mat3 r;
    Vec3 t;
    for (int k = 0; k < 3; ++k) {
      for (int j = 0; j < 3; ++j) r(k, j) = aa(0, k) * c.m.axes(0, j) + aa(1, k) * c.m.axes(1, j) + aa(2, k) * c.m.axes(2, j);
      t[k] = aa(0, k) * diff[0] + aa(1, k) * diff[1] + aa(2, k) * diff[2];
    }
    const double expected = obb_distance_lower_bound(r, t, c.a.half_extents_d(), c.eb.cast<double>());
    const double size = diff.norm() + c.a.half_extents_d().sum() + c.eb.cast<double>().sum();
    const double one = query_detail::box_distance_bound(c.a, c.m, c.eb);
    positive += expected > 0.0;
    EXPECT_NEAR(one, expected, 1e-12 * size) << "case " << i;
    EXPECT_GE(one, 0.0);
    const Case& o = all[(i * 7919 + 13) % all.size()];
    const double other = query_detail::box_distance_bound(o.a, o.m, o.eb);
    const auto l0 = query_detail::box_distance_bounds2(c.a, c.m, c.eb, o.a, o.m, o.eb);
    const auto l1 = query_detail::box_distance_bounds2(o.a, o.m, o.eb, c.a, c.m, c.eb);
    EXPECT_EQ(l0[0], one) << "case " << i;
    EXPECT_EQ(l0[1], other) << "case " << i;
    EXPECT_EQ(l1[1], one) << "case " << i;
    // A split's shapes: one node against both children of the other.
    const auto shared_a = query_detail::box_distance_bounds2(c.a, c.m, c.eb, c.a, o.m, o.eb);
    EXPECT_EQ(shared_a[0], one);
    EXPECT_EQ(shared_a[1], query_detail::box_distance_bound(c.a, o.m, o.eb));
    // Four lanes (a split of both nodes: A's two children against B's two), on the AVX2 path
    // where this CPU has it and on the two-lane fallback.
    const Case& p = all[(i * 104729 + 7) % all.size()];
    // Any four pairs, each lane from its own pointers (distance()'s deeper single splits).
    const CompactBox* const a4[4] = {&c.a, &p.a, &o.a, &c.a};
    const query_detail::MappedBox* const m4[4] = {&c.m, &o.m, &p.m, &p.m};
    const Eigen::Vector3f* const e4[4] = {&c.eb, &o.eb, &p.eb, &p.eb};
    for (const bool avx2 : {false, query_detail::avx2_bounds_available()}) {
      const auto l4 = query_detail::box_distance_bounds4(a4, m4, e4, avx2);
      for (int k = 0; k < 4; ++k)
        EXPECT_EQ(l4[k], query_detail::box_distance_bound(*a4[k], *m4[k], *e4[k]))
            << "case " << i << ", lane " << k << (avx2 ? ", AVX2" : "");
    }
    // A split of both nodes: two boxes a side, in either order.
    const query_detail::ChildBoxes boxes{{&c.a, &p.a}, {&c.m, &o.m}, {&c.eb, &o.eb}};
    for (const bool a_major : {true, false})
      for (const bool avx2 : {false, query_detail::avx2_bounds_available()}) {
        const auto l4 = query_detail::box_distance_bounds_cross(boxes, a_major, avx2);
        for (int k = 0; k < 4; ++k) {
          const int ia = a_major ? k / 2 : k % 2, ib = a_major ? k % 2 : k / 2;  // both_children's order
          EXPECT_EQ(l4[k], query_detail::box_distance_bound(*boxes.a[ia], *boxes.mb[ib], *boxes.eb[ib]))
              << "case " << i << ", lane " << k << (a_major ? ", A major" : ", B major") << (avx2 ? ", AVX2" : "");
        }
      }
  }
  EXPECT_GT(positive, static_cast<int>(all.size()) / 3);
  RecordProperty("avx2_lanes_tested", query_detail::avx2_bounds_available() ? "yes" : "no (CPU or build without them)");
}

// The boundary cases really are at the boundary: moving B by one ulp of the slide flips them.
TEST(BoxTest, BoundaryCasesFlipWithinAnUlp) {
  const std::vector<Case> all = cases(200, 8);
  int flips = 0;
  for (std::size_t i = 1; i < all.size(); i += 2) {
    const Case& c = all[i];
    Case up = c, down = c;
    for (int k = 0; k < 3; ++k) {
      up.m.center[k] = std::nextafter(c.m.center[k], c.m.center[k] > c.a.center_d()[k] ? HUGE_VAL : -HUGE_VAL);
      down.m.center[k] = std::nextafter(c.m.center[k], c.m.center[k] > c.a.center_d()[k] ? -HUGE_VAL : HUGE_VAL);
    }
    flips += query_detail::box_overlap(up.a, up.m, up.eb, up.margin) !=
             query_detail::box_overlap(down.a, down.m, down.eb, down.margin);
  }
  EXPECT_GT(flips, 50);  // of 100; a few lose the flip to the rounding of the center coordinates
}

}  // namespace
}  // namespace tightbvh
