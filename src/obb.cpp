#include "tightbvh/obb.hpp"

#include <algorithm>

namespace tightbvh {

std::array<Vec3, 8> Obb::corners() const {
  std::array<Vec3, 8> c;
  for (int i = 0; i < 8; ++i) {
    const Vec3 sign((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0);
    c[i] = center + axes * sign.cwiseProduct(half_extents);
  }
  return c;
}

Obb to_obb(const Aabb& box) {
  if (box.empty()) return {};
  return {box.center(), Mat3::Identity(), 0.5 * box.extents()};
}

double containment_tolerance(const Obb& box, double relative) {
  // Scale by both the box size and its distance from the origin: far from the origin the
  // rounding of the coordinates themselves dominates.
  const double scale = std::max({box.half_extents.maxCoeff(), box.center.cwiseAbs().maxCoeff(), 1e-300});
  return relative * scale;
}

}  // namespace tightbvh
