#include "tightbvh/compact_box.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tightbvh/error.hpp"

namespace tightbvh {
namespace {

// The float nearest to x, really rounded. GCC 12's SLP vectorizer (-O2 and above) was seen to
// fold a double -> float -> double round trip into the identity; the extents would then be
// measured in a frame other than the stored one (up to 8e-9 short on knot1). A value read back
// from a volatile cannot be folded away.
[[nodiscard]] float to_float(double x) {
  volatile float f = static_cast<float>(x);
  return f;
}

// The smallest float >= x (x finite, >= 0).
[[nodiscard]] float round_up(double x) {
  float f = to_float(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

}  // namespace

CompactBox compact_box(const Obb& fitted, std::span<const Vec3> points) {
  if (points.empty()) throw InputError("compact_box: a box needs at least one point");
  CompactBox box;
  for (int i = 0; i < 3; ++i) {
    box.center[i] = to_float(fitted.center[i]);
    for (int j = 0; j < 3; ++j) box.axes(i, j) = to_float(fitted.axes(i, j));
  }
  // The extents in the stored (float) frame, so that the box contains what it bounds as stored.
  const Vec3 c = box.center_d();
  const Mat3 axes_t = box.axes_d().transpose();
  Vec3 extent = Vec3::Zero();
  double magnitude = c.cwiseAbs().maxCoeff();
  for (const Vec3& p : points) {
    extent = extent.cwiseMax((axes_t * (p - c)).cwiseAbs());
    magnitude = std::max(magnitude, p.cwiseAbs().maxCoeff());
  }
  // Each measured coordinate a_i . (p - c) is off by at most a few units in the last place of
  // |p| + |c| (one subtraction, a 3-term dot product with |a_i|_1 <= sqrt(3)): pad by far more.
  const double pad = 64.0 * std::numeric_limits<double>::epsilon() * magnitude;
  for (int i = 0; i < 3; ++i) box.half_extents[i] = round_up(extent[i] + pad);
  return box;
}

CompactBox nearest_compact_box(const Obb& box) {
  CompactBox out;
  for (int i = 0; i < 3; ++i) {
    out.center[i] = to_float(box.center[i]);
    out.half_extents[i] = to_float(box.half_extents[i]);
    for (int j = 0; j < 3; ++j) out.axes(i, j) = to_float(box.axes(i, j));
  }
  return out;
}

}  // namespace tightbvh
