#include "tightbvh/obb.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace tightbvh {
namespace {

TEST(Obb, CornersAreInsideAndVolumeMatches) {
  const Mat3 r = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Obb box{Vec3(1, -2, 5), r, Vec3(1, 2, 3)};
  EXPECT_DOUBLE_EQ(box.volume(), 48.0);
  for (const Vec3& c : box.corners()) EXPECT_TRUE(box.contains(c, 1e-12));
  EXPECT_FALSE(box.contains(box.center + r.col(2) * 3.01));
}

TEST(Obb, TransformMovesCornersRigidly) {
  const Obb box{Vec3(0, 0, 0), Mat3::Identity(), Vec3(1, 2, 3)};
  const Pose pose{Eigen::AngleAxisd(1.1, Vec3::UnitZ()).toRotationMatrix(), Vec3(4, 5, 6)};
  const Obb moved = box.transformed(pose);
  const auto before = box.corners();
  const auto after = moved.corners();
  for (int i = 0; i < 8; ++i) EXPECT_LT((pose.apply(before[i]) - after[i]).norm(), 1e-12);
}

TEST(Pose, InverseAndCompose) {
  const Pose a{Eigen::AngleAxisd(0.3, Vec3::UnitX()).toRotationMatrix(), Vec3(1, 2, 3)};
  const Pose b{Eigen::AngleAxisd(-1.3, Vec3::UnitY()).toRotationMatrix(), Vec3(-1, 0, 7)};
  const Vec3 p(0.5, -0.25, 2);
  EXPECT_LT(((a * b).apply(p) - a.apply(b.apply(p))).norm(), 1e-12);
  EXPECT_LT((a.inverse().apply(a.apply(p)) - p).norm(), 1e-12);
}

TEST(Aabb, TransformedContainsMovedCorners) {
  Aabb box;
  box.extend(Vec3(-1, 0, 2));
  box.extend(Vec3(3, 1, 5));
  const Pose pose{Eigen::AngleAxisd(0.9, Vec3(1, 1, 0).normalized()).toRotationMatrix(), Vec3(2, 2, 2)};
  const Aabb moved = box.transformed(pose);
  for (const Vec3& c : box.corners()) EXPECT_TRUE(moved.contains(pose.apply(c), 1e-12));
}

}  // namespace
}  // namespace tightbvh
