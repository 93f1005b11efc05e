#pragma once
/// @file
/// The minimum-volume enclosing ellipsoid (Sunday, "Bounding Containers", The Bounding Ellipsoid),
/// to within (1+epsilon) in volume: Khachiyan's barycentric coordinate ascent with the
/// Todd-Yildirim away/drop steps (the WA-TY algorithm of Todd & Yildirim 2007, "On Khachiyan's
/// algorithm for the computation of minimum-volume enclosing ellipsoids", Discrete Appl. Math.
/// 155) on an active set grown from extreme points (core sets: Kumar & Yildirim 2005, JOTA 126;
/// Sun & Freund 2004, Oper. Res. 52).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>

#include "tightbvh/hull.hpp"
#include "tightbvh/pose.hpp"

namespace tightbvh {

/// The ellipsoid { center + axes * y : sum_k (y_k / radii_k)^2 <= 1 }. Flat sets have radius 0
/// along the missing directions (volume 0): along such an axis a point is inside when its offset
/// is within the flat slack of affine_dimension() (kFlatTolerance of the size, plus coordinate rounding).
struct Ellipsoid {
  Vec3 center = Vec3::Zero();    ///< The center.
  Mat3 axes = Mat3::Identity();  ///< orthonormal columns, right-handed
  Vec3 radii = Vec3::Zero();     ///< >= 0, along the columns of `axes`

  /// The offset allowed along a zero radius: 4 kFlatTolerance of the largest radius plus
  /// rounding of the coordinates (affine_dimension() calls sets this thin flat or a point).
  [[nodiscard]] double flat_slack() const {
    const double r = radii.maxCoeff();
    return 4.0 * kFlatTolerance * r + 4e-15 * (center.cwiseAbs().maxCoeff() + r);
  }
  /// sum_k (y_k / (radii_k + tolerance))^2 over the positive radii, or +inf when the offset
  /// along a zero radius exceeds flat_slack(). contains() and the final scan of
  /// bounding_ellipsoid() share this, so a point the scan accepts is contained.
  [[nodiscard]] double scaled_distance2(const Vec3& p, double tolerance = 0.0) const {
    const Vec3 y = axes.transpose() * (p - center);
    const double slack = flat_slack();
    double s = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double r = radii[k] + tolerance;
      if (r > 0.0) {
        const double t = y[k] / r;
        s += t * t;
      } else if (std::abs(y[k]) > slack) {
        return std::numeric_limits<double>::infinity();
      }
    }
    return s;
  }
  /// Closed containment; `tolerance` (absolute) is added to every radius.
  [[nodiscard]] bool contains(const Vec3& p, double tolerance = 0.0) const {
    return scaled_distance2(p, tolerance) <= 1.0;
  }
  /// 4/3 pi times the product of the radii (0 for a flat ellipsoid).
  [[nodiscard]] double volume() const { return 4.0 / 3.0 * std::numbers::pi * radii[0] * radii[1] * radii[2]; }
  /// The same ellipsoid after a rigid transform (radii unchanged).
  [[nodiscard]] Ellipsoid transformed(const Pose& pose) const {
    return {pose.apply(center), pose.rotation * axes, radii};
  }
};

/// An ellipsoid holding every point whose volume is at most (1 + epsilon) times the minimum
/// (up to a final relative growth of about 1e-15 for rounding). Solid sets: WA-TY on an active
/// set of the points (no convex hull), relative to a local origin and scale, stopped when the
/// duality gap over all points certifies the volume (see ellipsoid.cpp); then a final scan over
/// all points scales the radii by the largest scaled distance, so contains(p) holds for every input point with tolerance 0.
/// Flat sets (affine_dimension() < 3): the 2D minimum-area ellipse in the plane, the segment
/// (midpoint, half length) or the point, with zero radii elsewhere and volume 0.
/// Throws InputError for an empty set, a non-finite coordinate or epsilon not > 0 (or NaN).
[[nodiscard]] Ellipsoid bounding_ellipsoid(std::span<const Vec3> points, double epsilon = 0.01);

}  // namespace tightbvh
