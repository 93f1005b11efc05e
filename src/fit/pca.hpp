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

}  // namespace tightbvh::fit_detail
