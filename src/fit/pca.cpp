#include "pca.hpp"

#include <Eigen/Eigenvalues>

#include "frame.hpp"

namespace tightbvh::fit_detail {
namespace {

// Eigenvectors of a symmetric 3x3 matrix, sorted by decreasing eigenvalue, right-handed.
Mat3 principal_axes(const Mat3& covariance) {
  if (!covariance.allFinite() || covariance.cwiseAbs().maxCoeff() == 0.0) return Mat3::Identity();
  Eigen::SelfAdjointEigenSolver<Mat3> solver(covariance);  // iterative (QL): accurate for close eigenvalues
  if (solver.info() != Eigen::Success) return Mat3::Identity();
  const Mat3 v = solver.eigenvectors();  // increasing eigenvalues
  Mat3 axes;
  axes.col(0) = v.col(2);
  axes.col(1) = v.col(1);
  axes.col(2) = v.col(0);
  return orthonormalize(axes);
}

}  // namespace

Mat3 pca_vertex_axes(std::span<const Vec3> points, const Vec3& origin) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : points) mean += p - origin;
  mean /= static_cast<double>(points.size());
  Mat3 c = Mat3::Zero();
  for (const Vec3& p : points) {
    const Vec3 d = p - origin - mean;
    c.noalias() += d * d.transpose();
  }
  return principal_axes(c / static_cast<double>(points.size()));
}

Mat3 pca_triangle_axes(std::span<const Vec3> corners, const Vec3& origin) {
  // For a triangle (p, q, r) of area A and centroid m, the integral over its area of x x^T is
  //   A/12 * (9 m m^T + p p^T + q q^T + r r^T)   (Gottschalk's thesis, eq. 3.5 ff.).
  // Covariance = (sum of those) / A_total - M M^T with M the area-weighted centroid.
  // Accumulated relative to the mean triangle centroid so the subtraction stays accurate.
  const std::size_t n = corners.size() / 3;
  if (n == 0) return pca_vertex_axes(corners, origin);
  Vec3 centroid_mean = Vec3::Zero();
  for (const Vec3& p : corners) centroid_mean += p - origin;
  centroid_mean /= static_cast<double>(corners.size());
  const Vec3 o = origin + centroid_mean;

  double total_area = 0.0;
  Vec3 moment = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  for (std::size_t t = 0; t < n; ++t) {
    const Vec3 p = corners[3 * t] - o;
    const Vec3 q = corners[3 * t + 1] - o;
    const Vec3 r = corners[3 * t + 2] - o;
    const double area = 0.5 * (q - p).cross(r - p).norm();
    if (!(area > 0.0)) continue;
    const Vec3 m = (p + q + r) / 3.0;
    total_area += area;
    moment += area * m;
    second.noalias() += (area / 12.0) * (9.0 * m * m.transpose() + p * p.transpose() + q * q.transpose() +
                                         r * r.transpose());
  }
  if (!(total_area > 0.0)) return pca_vertex_axes(corners, origin);
  const Vec3 mean = moment / total_area;
  const Mat3 c = second / total_area - mean * mean.transpose();
  return principal_axes(c);
}

}  // namespace tightbvh::fit_detail
