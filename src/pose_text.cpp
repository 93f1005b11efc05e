#include "tightbvh/pose_text.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace tightbvh {

Pose parse_pose(std::string_view text) {
  std::vector<double> numbers;
  std::istringstream in{std::string(text)};
  for (std::string token; in >> token;) {
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') throw InputError("not a number: '" + token + "'");
    if (!std::isfinite(value)) throw InputError("not finite: '" + token + "'");
    numbers.push_back(value);
  }
  if (numbers.size() != 12)
    throw InputError("expected 12 numbers (r00 r01 r02 r10 r11 r12 r20 r21 r22 tx ty tz), got " +
                     std::to_string(numbers.size()));
  Pose pose;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) pose.rotation(r, c) = numbers[3 * r + c];
  pose.translation = Vec3(numbers[9], numbers[10], numbers[11]);
  const double error = (pose.rotation.transpose() * pose.rotation - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (error > 1e-6) {
    std::ostringstream msg;
    msg << "rotation is not orthonormal (max |R^T R - I| = " << error << ")";
    throw InputError(msg.str());
  }
  if (pose.rotation.determinant() < 0) throw InputError("rotation has determinant -1 (a reflection)");
  return pose;
}

}  // namespace tightbvh
