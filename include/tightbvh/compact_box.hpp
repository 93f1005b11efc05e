#pragma once
/// @file
/// A tree node's box in single precision: 60 bytes instead of the 120 of a double Obb, so that a
/// leaf-size-1 tree takes 140 bytes per triangle instead of 260 and more of it stays in cache.
///
/// The fitters work in double precision; the builder then rounds each fitted box *outward*
/// (compact_box): center and axes are rounded to the nearest float, and the half extents are
/// measured again, in double, over the node's own points in that rounded frame, padded for the
/// rounding of that measurement and rounded up. So the box contains its points as a slab box
///   { x : |a_i . (x - c)| <= e_i, i = 0, 1, 2 }   (a_i the float axes, exactly as stored),
/// which is what Obb::contains and validate() check, without any tolerance.
///
/// The float axes are orthonormal only to about 2e-7 (|A^T A - I|). The box queries evaluate the
/// separating-axis test in double as if they were orthonormal; the error this makes in a projected
/// radius is at most about 8e-7 times the sum of the box's half extents (the slab box is the
/// parallelepiped spanned by the columns of A^-T, within 4e-7 of A). The queries add
/// kCompactBoxSlack times the sum of the two root boxes' largest half extents to their box margin,
/// which bounds that error with a safety factor of more than 2 (a node's half extents sum to at
/// most 3 sqrt(3) times the root's largest half extent), so a float box test never culls a pair
/// that the exact test keeps. The distance queries also shrink each node bound by that relative
/// amount: it combines gaps along the axes as if they were orthonormal.
#include <span>

#include <Eigen/Core>

#include "tightbvh/aabb.hpp"
#include "tightbvh/math.hpp"
#include "tightbvh/obb.hpp"

namespace tightbvh {

/// The queries' extra relative box margin for the float axes (see the file comment): times the sum
/// of the two root boxes' largest half extents.
inline constexpr double kCompactBoxSlack = 1e-5;

/// A tree node's box in single precision: the slab box { x : |a_i . (x - c)| <= e_i } of its float
/// axes a_i, center c and half extents e_i, in the mesh frame.
struct CompactBox {
  Eigen::Vector3f center = Eigen::Vector3f::Zero();        ///< The center c.
  Eigen::Matrix3f axes = Eigen::Matrix3f::Identity();  ///< the columns are the box axes
  Eigen::Vector3f half_extents = Eigen::Vector3f::Zero();  ///< e_i along axis i (>= 0).

  /// The center in double precision (exact).
  [[nodiscard]] Vec3 center_d() const { return center.cast<double>(); }
  /// The axes in double precision (exact).
  [[nodiscard]] Mat3 axes_d() const { return axes.cast<double>(); }
  /// The half extents in double precision (exact).
  [[nodiscard]] Vec3 half_extents_d() const { return half_extents.cast<double>(); }
  /// The same box in double precision (exact conversion; axes orthonormal to about 2e-7).
  [[nodiscard]] Obb obb() const { return {center_d(), axes_d(), half_extents_d()}; }
  /// 8 times the product of the half extents.
  [[nodiscard]] double volume() const { return 8.0 * half_extents_d().prod(); }
};

/// The fitted box rounded outward so that it contains every point of `points` (the node's
/// triangle corners or vertices), as described above. Throws InputError when `points` is empty.
[[nodiscard]] CompactBox compact_box(const Obb& fitted, std::span<const Vec3> points);

/// The box with (about) these axes around `points` in one pass, where fitting a box with
/// fit_detail::box_with_axes and then compact_box takes two: the axes are rounded to float first,
/// the points' range along them is measured once (in AVX lanes where the CPU has them), and the
/// center is the float nearest to the middle of that range. Contains every point as compact_box's
/// box does (same padding, see compact_box.cpp). `axes` orthonormal; throws InputError when
/// `points` is empty.
[[nodiscard]] CompactBox compact_box_with_axes(std::span<const Vec3> points, const Mat3& axes);

/// The float box of an axis-aligned range (identity axes, exact in float): bit for bit
/// compact_box(to_obb(bounds), points) for any finite points whose bounds are `bounds`, in O(1).
/// Lets refit merge a node's axis-aligned bounds from its children's. `bounds` not empty.
[[nodiscard]] CompactBox compact_aabb(const Aabb& bounds);

/// The nearest float box, with no containment guarantee: for boxes made by hand (tests, tools).
[[nodiscard]] CompactBox nearest_compact_box(const Obb& box);

}  // namespace tightbvh
