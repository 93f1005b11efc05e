#include "tightbvh/compact_box.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "collide/query_common.hpp"
#include "fit/frame.hpp"
#include "fit/projected_range.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/obb_overlap.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh {
namespace {

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

// |A^T (p - c)| <= e with A, c, e the stored floats, evaluated in double with no tolerance: the
// slab box the queries and validate() see.
bool contains_as_stored(const CompactBox& box, const Vec3& p) {
  return ((box.axes_d().transpose() * (p - box.center_d())).cwiseAbs().array() <= box.half_extents_d().array()).all();
}

TEST(CompactBox, ContainsItsPointsWithNoToleranceAtEveryScale) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const double scale : {1e-3, 1.0, 1e4})
    for (const double offset : {0.0, 1.0, 1e6}) {
      for (int trial = 0; trial < 50; ++trial) {
        const Mat3 r = random_rotation(rng);
        std::vector<Vec3> points;
        for (int i = 0; i < 40; ++i)
          points.push_back(Vec3::Constant(offset) + scale * r * Vec3(u(rng), 0.3 * u(rng), 0.01 * u(rng)));
        // The double box: PCA-like axes r, extents measured exactly as a fitter would.
        Obb fitted{Vec3::Zero(), r, Vec3::Zero()};
        Vec3 lo = Vec3::Constant(1e300), hi = -lo;
        for (const Vec3& p : points) {
          lo = lo.cwiseMin(r.transpose() * p);
          hi = hi.cwiseMax(r.transpose() * p);
        }
        fitted.center = r * (0.5 * (lo + hi));
        fitted.half_extents = 0.5 * (hi - lo);
        const CompactBox box = compact_box(fitted, points);
        for (const Vec3& p : points) ASSERT_TRUE(contains_as_stored(box, p)) << "scale " << scale << " offset " << offset;
        // Rounded outward, not inflated: the float rounding of the frame tilts it by about 1e-7
        // of the box and shifts it by about 6e-8 of its distance from the origin.
        const double slack = 1e-6 * fitted.half_extents.maxCoeff() + 1e-7 * fitted.center.cwiseAbs().maxCoeff();
        EXPECT_LE((box.half_extents_d() - fitted.half_extents).cwiseAbs().maxCoeff(), slack);
      }
    }
}

// compact_box_with_axes (refit's one pass): contains its points as stored at every scale and
// offset, point count (the AVX path's four chains and its tail) and flatness, and is as tight
// as the two-pass compact_box up to the float rounding of the center.
TEST(CompactBox, WithAxesContainsItsPointsAndIsAsTightAsTwoPasses) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const double scale : {1e-3, 1.0, 1e4})
    for (const double offset : {0.0, 1.0, 1e6})
      for (const double flat : {1.0, 0.01, 0.0})
        for (int trial = 0; trial < 20; ++trial) {
          const Mat3 r = random_rotation(rng);
          std::vector<Vec3> points;
          const int n = 1 + trial % 11;
          for (int i = 0; i < n; ++i)
            points.push_back(Vec3::Constant(offset) + scale * r * Vec3(u(rng), 0.3 * u(rng), flat * u(rng)));
          const CompactBox box = compact_box_with_axes(points, r);
          for (const Vec3& p : points)
            ASSERT_TRUE(contains_as_stored(box, p)) << "scale " << scale << " offset " << offset << " n " << n;
          const Obb fitted = fit_detail::box_with_axes(points, r, points.front());
          const CompactBox two_passes = compact_box(fitted, points);
          const double slack = 1e-6 * fitted.half_extents.maxCoeff() + 2e-7 * fitted.center.cwiseAbs().maxCoeff();
          EXPECT_LE((box.half_extents_d() - two_passes.half_extents_d()).cwiseAbs().maxCoeff(), slack);
        }
  EXPECT_THROW((void)compact_box_with_axes({}, Mat3::Identity()), InputError);
}

// The AVX lanes and the scalar loop give the same range bit for bit (no FMA, exact min/max),
// for every count around the unrolling by four, with NaN-free inputs of mixed magnitudes.
TEST(CompactBox, ProjectedRangeAvxEqualsScalarBitForBit) {
#ifdef TIGHTBVH_AVX_RANGE
  if (!__builtin_cpu_supports("avx")) GTEST_SKIP() << "no AVX on this CPU";
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 1; n <= 41; ++n)
    for (int trial = 0; trial < 20; ++trial) {
      const Mat3 r = random_rotation(rng);
      double a[3][4] = {};
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) a[i][j] = static_cast<double>(static_cast<float>(r(i, j)));
      std::vector<double> xyz(3 * n);
      for (double& x : xyz) x = u(rng) * std::pow(10.0, 6.0 * u(rng));
      double lo_s[3], hi_s[3], lo_v[3], hi_v[3];
      fit_detail::projected_range_scalar(xyz.data(), n, a, lo_s, hi_s);
      fit_detail::projected_range_avx(xyz.data(), n, a, lo_v, hi_v);
      for (int j = 0; j < 3; ++j) {
        ASSERT_EQ(std::bit_cast<std::uint64_t>(lo_s[j]), std::bit_cast<std::uint64_t>(lo_v[j])) << n << " " << j;
        ASSERT_EQ(std::bit_cast<std::uint64_t>(hi_s[j]), std::bit_cast<std::uint64_t>(hi_v[j])) << n << " " << j;
      }
      // and the range is the range: every projection inside, the extremes attained.
      for (int j = 0; j < 3; ++j) {
        bool lo_hit = false, hi_hit = false;
        for (int k = 0; k < n; ++k) {
          const double q = (xyz[3 * k] * a[0][j] + xyz[3 * k + 1] * a[1][j]) + xyz[3 * k + 2] * a[2][j];
          ASSERT_LE(lo_s[j], q);
          ASSERT_GE(hi_s[j], q);
          lo_hit |= q == lo_s[j], hi_hit |= q == hi_s[j];
        }
        EXPECT_TRUE(lo_hit && hi_hit);
      }
    }
#else
  GTEST_SKIP() << "no AVX path in this build";
#endif
}

// compact_aabb (refit's aabb path, bounds merged from the children) is compact_box of the
// points' axis-aligned box, bit for bit, at every scale and offset.
TEST(CompactBox, AabbFromBoundsEqualsCompactBoxOfThePoints) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const double scale : {1e-3, 1.0, 1e4})
    for (const double offset : {0.0, -3.0, 1e6})
      for (int trial = 0; trial < 30; ++trial) {
        std::vector<Vec3> points;
        for (int i = 0; i < 1 + trial % 9; ++i) points.push_back(Vec3::Constant(offset) + scale * Vec3(u(rng), u(rng), u(rng)));
        const Aabb bounds = bounds_of(points);
        const CompactBox want = compact_box(to_obb(bounds), points);
        const CompactBox got = compact_aabb(bounds);
        EXPECT_EQ(0, std::memcmp(&want, &got, sizeof(CompactBox))) << "scale " << scale << " offset " << offset;
        for (const Vec3& p : points) ASSERT_TRUE(contains_as_stored(got, p));
      }
  EXPECT_THROW((void)compact_aabb(Aabb{}), InputError);
}

TEST(CompactBox, AxisAlignedBoxesKeepExactAxes) {
  const std::vector<Vec3> points{{0.1, 0.2, 0.3}, {-0.7, 1.1, 2.9}};
  const CompactBox box = compact_box({Vec3(-0.3, 0.65, 1.6), Mat3::Identity(), Vec3(0.4, 0.45, 1.3)}, points);
  EXPECT_TRUE(box.axes.isIdentity());
  for (const Vec3& p : points) EXPECT_TRUE(contains_as_stored(box, p));
}

TEST(CompactBox, NoPointsIsAnError) {
  EXPECT_THROW((void)compact_box(Obb{}, {}), InputError);
}

// The claim of compact_box.hpp: with the queries' allowance, a box test on float boxes never
// culls two boxes that share a point. Each trial puts one point x on a corner of both boxes (the
// worst place for a tilted axis), B in its own frame and posed by a random rigid motion.
TEST(CompactBox, FloatBoxTestNeverCullsBoxesSharingAPoint) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> size(1e-3, 2.0);
  const auto corner_box = [&](const Vec3& x) {
    const Mat3 r = random_rotation(rng);
    const Vec3 h(size(rng), size(rng), 1e-6 * size(rng));  // flat ones too, as the leaves are
    const Vec3 s(u(rng) < 0 ? -1 : 1, u(rng) < 0 ? -1 : 1, u(rng) < 0 ? -1 : 1);
    const Obb fitted{x - r * s.cwiseProduct(h), r, h};
    const Vec3 opposite = x - 2.0 * r * s.cwiseProduct(h);
    Tree tree;
    tree.nodes.push_back({compact_box(fitted, std::vector<Vec3>{x, opposite}), 0, 1});
    tree.triangle_order = {0};
    return tree;
  };
  int culled_without_allowance = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec3 x = Vec3(u(rng), u(rng), u(rng)) * (trial % 2 ? 1.0 : 100.0);
    const Pose rel{random_rotation(rng), Vec3(u(rng), u(rng), u(rng))};  // B's frame to A's frame
    const Tree ta = corner_box(x);
    const Tree tb = corner_box(rel.inverse().apply(x));
    const CompactBox& a = ta.nodes[0].box;
    const CompactBox& b = tb.nodes[0].box;
    const auto [c, d] = query_detail::in_box_frame(a, rel.rotation * b.axes_d(), rel.apply(b.center_d()));
    ASSERT_TRUE(obb_overlap(c, d, a.half_extents_d(), b.half_extents_d(), query_detail::box_allowance(ta, tb, rel)))
        << "trial " << trial;
    culled_without_allowance += obb_overlap(c, d, a.half_extents_d(), b.half_extents_d(), 0.0) ? 0 : 1;
  }
  // Not asserted (it depends on the draw): how often the allowance was what kept the pair.
  RecordProperty("culled_without_allowance", culled_without_allowance);
}

}  // namespace
}  // namespace tightbvh
