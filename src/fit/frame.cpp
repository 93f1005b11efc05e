#include "frame.hpp"

#include <cmath>
#include <limits>

#include "tightbvh/aabb.hpp"

namespace tightbvh::fit_detail {

Mat3 frame_from_axis(const Vec3& v) {
  const double n = v.norm();
  if (!(n > 0.0) || !std::isfinite(n)) return Mat3::Identity();
  const Vec3 a = v / n;
  // The coordinate axis least aligned with `a` gives a well-conditioned second direction.
  Vec3 helper = Vec3::UnitX();
  if (std::abs(a.y()) < std::abs(a.x()) && std::abs(a.y()) <= std::abs(a.z())) helper = Vec3::UnitY();
  else if (std::abs(a.z()) < std::abs(a.x()) && std::abs(a.z()) < std::abs(a.y())) helper = Vec3::UnitZ();
  else if (std::abs(a.x()) <= std::abs(a.y()) && std::abs(a.x()) <= std::abs(a.z())) helper = Vec3::UnitX();
  const Vec3 b = a.cross(helper).normalized();
  Mat3 out;
  out.col(0) = a;
  out.col(1) = b;
  out.col(2) = a.cross(b);
  return out;
}

Mat3 orthonormalize(const Mat3& axes) {
  Vec3 a = axes.col(0);
  if (!(a.norm() > 0.0) || !a.allFinite()) return Mat3::Identity();
  a.normalize();
  Vec3 b = axes.col(1) - a.dot(axes.col(1)) * a;
  const double bn = b.norm();
  if (!(bn > 1e-12 * axes.col(1).norm()) || !b.allFinite()) return frame_from_axis(a);
  b /= bn;
  // One more Gram-Schmidt pass for accuracy.
  b -= a.dot(b) * a;
  b.normalize();
  Mat3 out;
  out.col(0) = a;
  out.col(1) = b;
  out.col(2) = a.cross(b).normalized();
  return out;
}

bool smaller_box(const Obb& a, const Obb& b) {
  const double length = std::max(a.half_extents.sum(), b.half_extents.sum());
  return box_size_score(a.half_extents, length) < box_size_score(b.half_extents, length);
}

Vec3 local_origin(std::span<const Vec3> points) { return bounds_of(points).center(); }

Obb box_with_axes(std::span<const Vec3> points, const Mat3& axes, const Vec3& origin) {
  bool finite = true;
  return box_with_axes(points, axes, origin, finite);
}

Obb box_with_axes(std::span<const Vec3> points, const Mat3& axes, const Vec3& origin, bool& finite) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  Vec3 sum = Vec3::Zero();  // NaN propagates through sums (min/max may silently drop it)
  const Mat3 rt = axes.transpose();
  for (const Vec3& p : points) {
    const Vec3 q = rt * (p - origin);
    sum += q;
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  finite = sum.allFinite();
  Obb box;
  box.axes = axes;
  box.half_extents = 0.5 * (hi - lo);
  box.center = origin + axes * (0.5 * (hi + lo));
  return box;
}

}  // namespace tightbvh::fit_detail
