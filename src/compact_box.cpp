#include "tightbvh/compact_box.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "tightbvh/error.hpp"
#include "fit/projected_range.hpp"

namespace tightbvh {
namespace {

// The float nearest to x, really rounded. GCC 12's SLP vectorizer (-O2 and above) can
// fold a double -> float -> double round trip into the identity; the extents would then be
// measured in a frame other than the stored one (up to 8e-9 short on knot1). An empty asm that
// may change the float hides its value from the optimizer (a volatile elsewhere: a memory round
// trip, twelve of them a node).
[[nodiscard]] float to_float(double x) {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  float f = static_cast<float>(x);
  __asm__("" : "+x"(f));
  return f;
#else
  volatile float f = static_cast<float>(x);
  return f;
#endif
}

// The smallest float >= x (x finite, >= 0). The float after a non-negative f is the one whose
// bits are one more (also from +0 to the smallest subnormal, and from the largest float to +inf).
// Branch-free: whether f rounded down is a coin toss, and a mispredicted branch per extent costs
// about a tenth of a refit.
[[nodiscard]] float round_up(double x) {
  const float f = to_float(x);
  const std::uint32_t below = static_cast<double>(f) < x ? 1u : 0u;
  return std::bit_cast<float>(std::bit_cast<std::uint32_t>(f) + below);
}

// The range [lo, hi] of a_i . p over the points along the box's stored (float) axes, in AVX lanes
// where the CPU has them (fit/projected_range.hpp).
void range_along_axes(const CompactBox& box, std::span<const Vec3> points, Vec3& lo, Vec3& hi) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "points are read as consecutive x, y, z");
  double rows[3][4] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rows[i][j] = static_cast<double>(box.axes(i, j));
  double lo_q[3], hi_q[3];
  // A single triangle's three corners (half of all nodes) cost less in the scalar loop than the
  // call to the lanes; both give the same range.
  if (points.size() <= 4)
    fit_detail::projected_range_scalar(points.data()->data(), points.size(), rows, lo_q, hi_q);
  else
    fit_detail::projected_range(points.data()->data(), points.size(), rows, lo_q, hi_q);
  lo = Vec3(lo_q[0], lo_q[1], lo_q[2]), hi = Vec3(hi_q[0], hi_q[1], hi_q[2]);
}

// The half extents around the stored center from that range: a_i . (p - c) = a_i . p - a_i . c.
// Each of the two dot products is off by at most about 6 units in the last place of max(|p|,
// |c|) (|a_i|_1 <= sqrt(3), no FMA), their difference by a few more: the pad of 64 units covers it
// with a margin, and the result is rounded up. |p|_inf <= |p|_2 = |A^-T q|_2 <= 1.001 |q|_1 (the
// float axes are orthonormal to about 2e-7) bounds the points' magnitude without reading them
// again.
void set_half_extents(CompactBox& box, const Vec3& lo, const Vec3& hi) {
  const Vec3 c = box.center_d();
  const Vec3 shift = box.axes_d().transpose() * c;
  const double points_magnitude = 1.001 * lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).sum();  // >= the 2-norm
  const double magnitude = std::max(points_magnitude, c.cwiseAbs().maxCoeff());
  const double pad = 64.0 * std::numeric_limits<double>::epsilon() * magnitude;
  for (int i = 0; i < 3; ++i) box.half_extents[i] = round_up(std::max(hi[i] - shift[i], shift[i] - lo[i]) + pad);
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
  Vec3 lo, hi;
  range_along_axes(box, points, lo, hi);
  set_half_extents(box, lo, hi);
  return box;
}

CompactBox compact_box_with_axes(std::span<const Vec3> points, const Mat3& axes) {
  if (points.empty()) throw InputError("compact_box_with_axes: a box needs at least one point");
  CompactBox box;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) box.axes(i, j) = to_float(axes(i, j));
  Vec3 lo, hi;
  range_along_axes(box, points, lo, hi);
  // The range is of q = A^T p, so its middle maps back by A (A^-T is within 3e-7 of A: the center
  // only has to be near the middle, the extents are measured from wherever it is).
  const Vec3 center = box.axes_d() * (0.5 * (lo + hi));
  for (int i = 0; i < 3; ++i) box.center[i] = to_float(center[i]);
  set_half_extents(box, lo, hi);
  return box;
}

CompactBox compact_aabb(const Aabb& bounds) {
  if (bounds.empty()) throw InputError("compact_aabb: the bounds are empty");
  CompactBox box;  // identity axes: the range along them is the bounds themselves
  const Vec3 center = to_obb(bounds).center;
  for (int i = 0; i < 3; ++i) box.center[i] = to_float(center[i]);
  set_half_extents(box, bounds.min, bounds.max);
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
