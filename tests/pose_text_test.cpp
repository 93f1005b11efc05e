#include "tightbvh/pose_text.hpp"

#include <gtest/gtest.h>

#include <string>

namespace tightbvh {
namespace {

std::string error_of(const std::string& text) {
  try {
    (void)parse_pose(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ParsePose, ReadsRowMajorRotationThenTranslation) {
  const Pose p = parse_pose("0 -1 0  1 0 0  0 0 1   1.5 -2 3e-1");
  EXPECT_EQ(p.rotation(0, 1), -1.0);
  EXPECT_EQ(p.rotation(1, 0), 1.0);
  EXPECT_EQ(p.translation, Vec3(1.5, -2, 0.3));
  EXPECT_LT((p.apply(Vec3(1, 0, 0)) - Vec3(1.5, -1, 0.3)).norm(), 1e-15);
}

TEST(ParsePose, RejectsWhatIsNotAProperRigidTransform) {
  EXPECT_NE(error_of("1 0 0 0 1 0 0 0 1 0 0").find("expected 12 numbers"), std::string::npos);
  EXPECT_NE(error_of("1 0 0 0 1 0 0 0 1 0 0 0 0").find("got 13"), std::string::npos);
  EXPECT_NE(error_of("").find("got 0"), std::string::npos);
  EXPECT_NE(error_of("1 0 0 0 1 0 0 0 1 0x 0 0").find("not a number: '0x'"), std::string::npos);
  EXPECT_NE(error_of("1 0 0 0 1 0 0 0 1 nan 0 0").find("not finite: 'nan'"), std::string::npos);
  EXPECT_NE(error_of("1 0 0 0 1 0 0 0 1 -inf 0 0").find("not finite"), std::string::npos);
  EXPECT_NE(error_of("1 0 0 0 1 0 0 0 2 0 0 0").find("not orthonormal"), std::string::npos);
  EXPECT_NE(error_of("1 0 0 0 1 0 0 0 -1 0 0 0").find("determinant -1"), std::string::npos);
  EXPECT_EQ(error_of("1 0 0 0 1 0 0 0 1 0 0 0"), "");
}

}  // namespace
}  // namespace tightbvh
