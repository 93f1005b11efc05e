#include "tightbvh/obb_overlap.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <Eigen/Geometry>

namespace tightbvh {
namespace {

// Reference: two convex polytopes intersect iff a corner of one lies in the other or an edge of
// one meets the other (every vertex of the intersection is one of these). Edge vs solid box by
// clipping the segment against the three slabs in the box frame (Liang-Barsky).
bool segment_meets_box(const Vec3& p0, const Vec3& p1, const Obb& box) {
  const Vec3 a = box.to_local(p0), b = box.to_local(p1);
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 3; ++i) {
    const double d = b[i] - a[i], e = box.half_extents[i];
    if (d == 0.0) {
      if (std::abs(a[i]) > e) return false;
      continue;
    }
    double s0 = (-e - a[i]) / d, s1 = (e - a[i]) / d;
    if (s0 > s1) std::swap(s0, s1);
    lo = std::max(lo, s0);
    hi = std::min(hi, s1);
    if (lo > hi) return false;
  }
  return true;
}

bool reference_overlap(const Obb& a, const Obb& b) {
  const auto ca = a.corners(), cb = b.corners();
  for (const Vec3& c : ca)
    if (b.contains(c)) return true;
  for (const Vec3& c : cb)
    if (a.contains(c)) return true;
  // Corner i and i ^ (1 << axis) span an edge.
  for (int i = 0; i < 8; ++i)
    for (int axis = 0; axis < 3; ++axis) {
      const int j = i ^ (1 << axis);
      if (j < i) continue;
      if (segment_meets_box(ca[i], ca[j], b) || segment_meets_box(cb[i], cb[j], a)) return true;
    }
  return false;
}

Obb inflated(Obb box, double delta) {
  box.half_extents.array() += delta;
  return box;
}

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
}

TEST(ObbOverlap, AgreesWithCornerEdgeReference) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.05, 2.0), c(-3.0, 3.0);
  int overlapping = 0, disjoint = 0;
  for (int iter = 0; iter < 50000; ++iter) {
    const Obb a{Vec3(c(rng), c(rng), c(rng)), random_rotation(rng), Vec3(u(rng), u(rng), u(rng))};
    Obb b{Vec3(c(rng), c(rng), c(rng)), random_rotation(rng), Vec3(u(rng), u(rng), u(rng))};
    if (iter % 5 == 0) b.axes = a.axes;  // parallel faces and edges
    if (iter % 5 == 1) b.axes = a.axes * Eigen::AngleAxisd(c(rng), Vec3::UnitZ()).toRotationMatrix();  // parallel edges
    const bool sat = obb_overlap(a, b);
    // SAT says disjoint => truly disjoint (checked on slightly shrunk boxes: the reference has
    // its own rounding); the reference says clearly disjoint => SAT finds a separating axis.
    if (!sat) {
      ASSERT_FALSE(reference_overlap(inflated(a, -1e-7), inflated(b, -1e-7))) << "iteration " << iter;
      ++disjoint;
    } else {
      ASSERT_TRUE(reference_overlap(inflated(a, 1e-7), inflated(b, 1e-7))) << "iteration " << iter;
      ++overlapping;
    }
    ASSERT_EQ(obb_overlap(b, a), sat);
  }
  EXPECT_GT(overlapping, 5000);
  EXPECT_GT(disjoint, 5000);
}

TEST(ObbOverlap, TouchingBoxesOverlap) {
  const Obb a{Vec3::Zero(), Mat3::Identity(), Vec3(1, 1, 1)};
  EXPECT_TRUE(obb_overlap(a, Obb{Vec3(2, 0, 0), Mat3::Identity(), Vec3(1, 1, 1)}));      // face to face
  EXPECT_TRUE(obb_overlap(a, Obb{Vec3(2, 2, 2), Mat3::Identity(), Vec3(1, 1, 1)}));      // corner to corner
  EXPECT_FALSE(obb_overlap(a, Obb{Vec3(2 + 1e-6, 0, 0), Mat3::Identity(), Vec3(1, 1, 1)}));
  // 90 degrees about z (exact), edge to edge along z.
  Mat3 rz;
  rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_TRUE(obb_overlap(a, Obb{Vec3(1.5, 1.5, 0), rz, Vec3(0.5, 0.5, 3)}));
  EXPECT_FALSE(obb_overlap(a, Obb{Vec3(1.5 + 1e-6, 1.5, 0), rz, Vec3(0.5, 0.5, 3)}));
  // 45 degrees about z: the corner edge of b just misses a's face along x.
  const Mat3 r45 = Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ()).toRotationMatrix();
  const double reach = 1.0 + std::sqrt(2.0);  // b's half diagonal (sqrt 2) plus a's half extent
  EXPECT_TRUE(obb_overlap(a, Obb{Vec3(reach - 1e-6, 0, 0), r45, Vec3(1, 1, 1)}));
  EXPECT_FALSE(obb_overlap(a, Obb{Vec3(reach + 1e-6, 0, 0), r45, Vec3(1, 1, 1)}));
}

TEST(ObbOverlap, EdgeEdgeAxisSeparates) {
  // Two long thin boxes crossing like an X (long axes x and y), each rolled 45 degrees about its
  // long axis, at different heights: no face normal separates them, only x cross y does (their
  // z-radii are 0.1 * sqrt 2 each). The whole configuration is tilted to avoid exact axes.
  const Mat3 tilt = Eigen::AngleAxisd(0.3, Vec3(1, 2, 0).normalized()).toRotationMatrix();
  const Mat3 ra = tilt * Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX()).toRotationMatrix();
  const Mat3 rb = tilt * Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY()).toRotationMatrix() *
                  Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
  const Obb a{Vec3::Zero(), ra, Vec3(5, 0.1, 0.1)};
  const Vec3 up = tilt.col(2);
  EXPECT_FALSE(obb_overlap(a, Obb{0.3 * up, rb, Vec3(5, 0.1, 0.1)}));
  EXPECT_TRUE(obb_overlap(a, Obb{0.27 * up, rb, Vec3(5, 0.1, 0.1)}));
  EXPECT_FALSE(reference_overlap(a, Obb{0.3 * up, rb, Vec3(5, 0.1, 0.1)}));
  EXPECT_TRUE(reference_overlap(a, Obb{0.27 * up, rb, Vec3(5, 0.1, 0.1)}));
}

TEST(ObbOverlap, MarginWidensTheTest) {
  const Obb a{Vec3::Zero(), Mat3::Identity(), Vec3(1, 1, 1)};
  const Obb b{Vec3(2.5, 0, 0), Mat3::Identity(), Vec3(1, 1, 1)};  // 0.5 apart
  EXPECT_FALSE(obb_overlap(a, b, 0.4));
  EXPECT_TRUE(obb_overlap(a, b, 0.6));
}

}  // namespace
}  // namespace tightbvh
