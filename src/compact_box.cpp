#include "tightbvh/compact_box.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tightbvh/error.hpp"
#include "fit/projected_range.hpp"

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

CompactBox compact_box_with_axes(std::span<const Vec3> points, const Mat3& axes) {
  if (points.empty()) throw InputError("compact_box_with_axes: a box needs at least one point");
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "points are read as consecutive x, y, z");
  CompactBox box;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) box.axes(i, j) = to_float(axes(i, j));
  const Mat3 a = box.axes_d();
  double rows[3][4] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rows[i][j] = a(i, j);
  double lo_q[3], hi_q[3];
  fit_detail::projected_range(points.data()->data(), points.size(), rows, lo_q, hi_q);
  const Vec3 lo(lo_q[0], lo_q[1], lo_q[2]), hi(hi_q[0], hi_q[1], hi_q[2]);
  // The range is of q = A^T p, so the middle maps back by A (A^-T within 3e-7 of A: the center
  // only has to be near the middle, the extents are measured from wherever it is).
  const Vec3 center = a * (0.5 * (lo + hi));
  for (int i = 0; i < 3; ++i) box.center[i] = to_float(center[i]);
  // a_i . (p - c) = a_i . p - a_i . c: the range shifted to the stored center. Each of the two dot
  // products is off by at most about 6 units in the last place of max(|p|, |c|) (|a_i|_1 <=
  // sqrt(3)), the difference by a few more: well inside compact_box's pad of 64. |p|_inf <=
  // |p|_2 = |A^-T q|_2 <= 1.001 |q|_2 bounds the points' magnitude without reading them again.
  const Vec3 shift = a.transpose() * box.center_d();
  const double largest = 1.001 * lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).norm();
  const double magnitude = std::max(largest, box.center_d().cwiseAbs().maxCoeff());
  const double pad = 64.0 * std::numeric_limits<double>::epsilon() * magnitude;
  for (int i = 0; i < 3; ++i)
    box.half_extents[i] = round_up(std::max(hi[i] - shift[i], shift[i] - lo[i]) + pad);
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
