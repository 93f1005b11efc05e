#pragma once
// Internal: principal-component frames (RAPID/OBBTree and FCL variants).
#include <span>

#include "tightbvh/pose.hpp"

namespace tightbvh::fit_detail {

// Eigenvectors of a symmetric 3x3 matrix as an orthonormal right-handed frame, columns sorted
// by decreasing eigenvalue (the identity for a zero or non-finite matrix). With repeated
// eigenvalues any orthonormal basis of the eigenspace is returned.
[[nodiscard]] Mat3 principal_axes(const Mat3& covariance);

// The same frame, found by cyclic Jacobi rotations (Golub & Van Loan, Matrix Computations,
// Section 8.5) started from `start` (any frame; orthonormalized first). When `start` nearly
// diagonalises the matrix, as a node's previous axes do for its covariance after a small
// deformation (refit), one or two sweeps of three rotations converge, several times cheaper than
// the closed form. Within a (nearly) repeated eigenvalue's eigenspace the rotated start is kept,
// so the frame does not jump from frame to frame. Falls back to principal_axes when the sweeps
// do not converge (e.g. entries near the overflow range).
[[nodiscard]] Mat3 principal_axes_from(const Mat3& covariance, const Mat3& start);

// FCL-style: eigenvectors of the unweighted covariance of the points (triangle corners).
[[nodiscard]] Mat3 pca_vertex_axes(std::span<const Vec3> points, const Vec3& origin);

// RAPID/OBBTree (Gottschalk et al. 1996, Gottschalk's thesis Section 3.2): eigenvectors of
// the covariance of the triangles as continuous surfaces, i.e. the second moments integrated
// over each triangle's area. Corners come three per triangle. When the total area is zero the
// vertex covariance is used instead.
[[nodiscard]] Mat3 pca_triangle_axes(std::span<const Vec3> corners, const Vec3& origin);

// The sums behind pca_triangle_axes, relative to `origin`, over the triangles of positive area:
// area = sum(A), first = sum(A s), second = sum(A / 12 (s s^T + p p^T + q q^T + r r^T)) with
// s = p + q + r (Gottschalk's thesis, eq. 3.5 ff.). They are additive, so a tree node's can be
// derived from its parent's and one child's instead of from its triangles (the builder, for the
// fitters whose first step is the PCA box), or summed from its children's (refit).
struct AreaMoments {
  Vec3 origin = Vec3::Zero();
  double area = 0.0;
  Vec3 first = Vec3::Zero();
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  // The area-weighted covariance (area > 0), as pca_triangle_axes computes it from these sums.
  [[nodiscard]] Mat3 covariance() const;
  // The same sums relative to another origin (x -> x + origin - o for every point x).
  [[nodiscard]] AreaMoments moved_to(const Vec3& o) const;
  // The sums of the triangles of `this` that are not in `part` (a subset), relative to `o`.
  [[nodiscard]] AreaMoments without(const AreaMoments& part, const Vec3& o) const;
  // The sums of the triangles of `this` and of `other` (disjoint sets), relative to this origin
  // (refit: a node's from its children's).
  [[nodiscard]] AreaMoments plus(const AreaMoments& other) const;
};

// The sums of the triangles given by their corners (three per triangle), relative to `origin`:
// exactly the ones pca_triangle_axes(corners, origin) accumulates, in the same order.
[[nodiscard]] AreaMoments area_moments(std::span<const Vec3> corners, const Vec3& origin);

}  // namespace tightbvh::fit_detail
