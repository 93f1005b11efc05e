#include "pca.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "frame.hpp"

namespace tightbvh::fit_detail {
namespace {

// Iterative (QL) solver: slower, accurate for any spectrum. Fallback of principal_axes.
Mat3 principal_axes_iterative(const Mat3& covariance) {
  Eigen::SelfAdjointEigenSolver<Mat3> solver(covariance);
  if (solver.info() != Eigen::Success) return Mat3::Identity();
  const Mat3 v = solver.eigenvectors();  // increasing eigenvalues
  Mat3 axes;
  axes.col(0) = v.col(2);
  axes.col(1) = v.col(1);
  axes.col(2) = v.col(0);
  return orthonormalize(axes);
}

}  // namespace

Mat3 principal_axes(const Mat3& covariance) {
  if (!covariance.allFinite() || covariance.cwiseAbs().maxCoeff() == 0.0) return Mat3::Identity();
  // Closed form (trigonometric roots + kernels by cross products): several times cheaper than
  // QL iterations, and this runs once per tree node. Its eigenvector of the *most distinct*
  // eigenvalue is the accurate one (the other two are only determined up to a rotation when
  // their eigenvalues nearly tie), so the frame is rebuilt around that vector.
  Eigen::SelfAdjointEigenSolver<Mat3> solver;
  solver.computeDirect(covariance);
  const Vec3 lambda = solver.eigenvalues();  // increasing
  const Mat3 v = solver.eigenvectors();
  if (!v.allFinite() || !lambda.allFinite()) return principal_axes_iterative(covariance);
  // Sanity check of the closed form (it can lose accuracy when the spectrum spans many orders
  // of magnitude): every column must be a unit eigenvector to ~1e-7 relative; else iterate.
  const double scale = std::max(std::abs(lambda[0]), std::abs(lambda[2]));
  for (int i = 0; i < 3; ++i) {
    const Vec3 r = covariance * v.col(i) - lambda[i] * v.col(i);
    if (!(r.norm() <= 1e-7 * scale) || !(std::abs(v.col(i).squaredNorm() - 1.0) < 1e-9))
      return principal_axes_iterative(covariance);
  }
  Mat3 axes;  // decreasing eigenvalues, right-handed
  if (lambda[2] - lambda[1] >= lambda[1] - lambda[0]) {
    // Largest eigenvalue is the most distinct: keep its vector, orthogonalise the middle one.
    axes.col(0) = v.col(2);
    axes.col(1) = v.col(1);
    return orthonormalize(axes);
  }
  // Smallest eigenvalue is the most distinct (flat sets): keep the normal exactly.
  const Vec3 n = v.col(0).normalized();
  Vec3 a = v.col(2) - n.dot(v.col(2)) * n;
  if (!(a.norm() > 1e-6)) return principal_axes_iterative(covariance);  // not after the residual check
  a.normalize();
  axes.col(0) = a;
  axes.col(1) = n.cross(a);
  axes.col(2) = n;
  return axes;
}

Mat3 principal_axes_from(const Mat3& covariance, const Mat3& start) {
  if (!covariance.allFinite()) return Mat3::Identity();
  // One Gram-Schmidt pass: the start is a stored float frame, orthonormal to about 2e-7.
  const double n0 = start.col(0).norm();
  if (!(n0 > 0.0) || !std::isfinite(n0)) return principal_axes(covariance);
  Mat3 v;
  v.col(0) = start.col(0) / n0;
  v.col(1) = start.col(1) - v.col(0).dot(start.col(1)) * v.col(0);
  const double n1 = v.col(1).norm();
  if (!(n1 > 0.5 * start.col(1).norm()) || !std::isfinite(n1)) return principal_axes(covariance);  // not a frame
  v.col(1) /= n1;
  v.col(2) = v.col(0).cross(v.col(1));
  // The matrix in the current frame, d = v^T C v, symmetric: its six entries.
  const Mat3 cv = covariance * v;
  double d[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) d[i][j] = d[j][i] = v.col(i).dot(cv.col(j));
  double largest = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) largest = std::max(largest, std::abs(d[i][j]));
  if (largest == 0.0) return Mat3::Identity();
  // An off-diagonal entry this small moves an eigenvector by about its ratio to the eigenvalue
  // gap. 1e-7 of the largest entry is the accuracy principal_axes' closed form accepts (residuals
  // of 1e-7 of the scale); a box's volume moves by about the square of such a tilt, as its
  // extents are measured along whatever axes come out. Stopping there, not at 1e-12, saves most
  // of a sweep a node in refit, whose rotations are chains of divisions and square roots:
  // camel's refit 6.5-7.6 -> 5.8-6.9 ms, FCL's bottom-up refit / ours 1.96-2.21x -> 2.24-2.41x
  // (1e-8: 2.12-2.28x, 1e-9: no gain), the same volumes (docs/design-notes/refit.md,
  // "pca refit: moments from the children, axes by Jacobi sweeps").
  const double negligible = 1e-7 * largest;
  // The rotation in the plane (p, q) that zeroes d[p][q] (r the third index), in the symmetric
  // update form of Numerical Recipes (3rd ed., Section 11.1): compile-time indices keep d and v in
  // registers.
  const auto rotate = [&]<int p, int q, int r>() {
    const double apq = d[p][q];
    if (!(std::abs(apq) > negligible)) return false;
    // GVL Algorithm 8.5.1 (sym.schur2): t = tan of the smaller angle. For the small angles of a
    // good start (|tau| > 1e6) the series t = 1/(2 tau), c = 1 - t^2/2 is exact to double
    // rounding and saves the two square roots.
    const double tau = (d[q][q] - d[p][p]) / (2.0 * apq);
    double t, c;
    if (std::abs(tau) > 1e6) {
      t = 0.5 / tau;
      c = 1.0 - 0.5 * t * t;
    } else {
      t = (tau >= 0.0 ? 1.0 : -1.0) / (std::abs(tau) + std::sqrt(1.0 + tau * tau));
      c = 1.0 / std::sqrt(1.0 + t * t);
    }
    const double s = t * c;
    d[p][p] -= t * apq, d[q][q] += t * apq;
    d[p][q] = d[q][p] = 0.0;
    const double drp = d[r][p], drq = d[r][q];
    d[r][p] = d[p][r] = c * drp - s * drq;
    d[r][q] = d[q][r] = s * drp + c * drq;
    for (int k = 0; k < 3; ++k) {  // v J
      const double a = v(k, p), b = v(k, q);
      v(k, p) = c * a - s * b, v(k, q) = s * a + c * b;
    }
    return true;
  };
  constexpr int kMaxSweeps = 8;  // convergence is quadratic; from any start 4-5 sweeps suffice
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    bool rotated = rotate.template operator()<0, 1, 2>();
    rotated |= rotate.template operator()<0, 2, 1>();
    rotated |= rotate.template operator()<1, 2, 0>();
    if (!rotated) {
      // Columns by decreasing eigenvalue, right-handed.
      std::array<int, 3> order{0, 1, 2};  // three compare-exchanges, stable
      const auto exchange = [&](int i, int j) {
        if (d[order[j]][order[j]] > d[order[i]][order[i]]) std::swap(order[i], order[j]);
      };
      exchange(0, 1), exchange(1, 2), exchange(0, 1);
      Mat3 axes;
      axes.col(0) = v.col(order[0]);
      axes.col(1) = v.col(order[1]);
      axes.col(2) = axes.col(0).cross(axes.col(1));
      return axes;
    }
    if (!std::isfinite(d[0][0] + d[1][1] + d[2][2] + d[0][1] + d[0][2] + d[1][2])) break;
  }
  return principal_axes(covariance);
}

Mat3 pca_vertex_axes(std::span<const Vec3> points, const Vec3& origin) {
  // One pass: first and second moments relative to `origin` (a point near the set, so the
  // subtraction of the mean's outer product loses no more than centring first would).
  Vec3 sum = Vec3::Zero();
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  for (const Vec3& p : points) {
    const Vec3 d = p - origin;
    sum += d;
    xx += d.x() * d.x(), xy += d.x() * d.y(), xz += d.x() * d.z();
    yy += d.y() * d.y(), yz += d.y() * d.z(), zz += d.z() * d.z();
  }
  const double inv = 1.0 / static_cast<double>(points.size());
  const Vec3 mean = sum * inv;
  Mat3 c;
  c << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  return principal_axes(c * inv - mean * mean.transpose());
}

AreaMoments area_moments(std::span<const Vec3> corners, const Vec3& origin) {
  // For a triangle (p, q, r) of area A and centroid m, the integral over its area of x x^T is
  //   A/12 * (9 m m^T + p p^T + q q^T + r r^T)   (Gottschalk's thesis, eq. 3.5 ff.).
  // One pass, relative to `origin` (a point near the set, see pca_vertex_axes).
  AreaMoments m;
  m.origin = origin;
  const std::size_t n = corners.size() / 3;
  double total_area = 0.0;
  Vec3 moment = Vec3::Zero();
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  for (std::size_t t = 0; t < n; ++t) {
    const Vec3 p = corners[3 * t] - origin;
    const Vec3 q = corners[3 * t + 1] - origin;
    const Vec3 r = corners[3 * t + 2] - origin;
    const double area = 0.5 * (q - p).cross(r - p).norm();
    if (!(area > 0.0)) continue;
    const Vec3 s = p + q + r;  // 3 m
    total_area += area;
    moment += area * s;
    // 9 m m^T = s s^T
    const double w = area / 12.0;
    xx += w * (s.x() * s.x() + p.x() * p.x() + q.x() * q.x() + r.x() * r.x());
    xy += w * (s.x() * s.y() + p.x() * p.y() + q.x() * q.y() + r.x() * r.y());
    xz += w * (s.x() * s.z() + p.x() * p.z() + q.x() * q.z() + r.x() * r.z());
    yy += w * (s.y() * s.y() + p.y() * p.y() + q.y() * q.y() + r.y() * r.y());
    yz += w * (s.y() * s.z() + p.y() * p.z() + q.y() * q.z() + r.y() * r.z());
    zz += w * (s.z() * s.z() + p.z() * p.z() + q.z() * q.z() + r.z() * r.z());
  }
  m.area = total_area;
  m.first = moment;
  m.xx = xx, m.xy = xy, m.xz = xz, m.yy = yy, m.yz = yz, m.zz = zz;
  return m;
}

Mat3 AreaMoments::covariance() const {
  // Covariance = (sum of the triangles' integrals) / A_total - M M^T with M the area-weighted
  // centroid (relative to the origin).
  const Vec3 mean = first / (3.0 * area);
  Mat3 c;
  c << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  return c / area - mean * mean.transpose();
}

AreaMoments AreaMoments::moved_to(const Vec3& o) const {
  // Every point x becomes x + e: s -> s + 3e, p -> p + e, ..., so with w = A / 12 summed,
  // second += (e first^T + first e^T) / 3 + area e e^T and first += 3 area e.
  const Vec3 e = origin - o;
  AreaMoments m = *this;
  m.origin = o;
  m.first = first + 3.0 * area * e;
  const Vec3 f = first / 3.0;
  m.xx += 2 * e.x() * f.x() + area * e.x() * e.x();
  m.xy += e.x() * f.y() + f.x() * e.y() + area * e.x() * e.y();
  m.xz += e.x() * f.z() + f.x() * e.z() + area * e.x() * e.z();
  m.yy += 2 * e.y() * f.y() + area * e.y() * e.y();
  m.yz += e.y() * f.z() + f.y() * e.z() + area * e.y() * e.z();
  m.zz += 2 * e.z() * f.z() + area * e.z() * e.z();
  return m;
}

AreaMoments AreaMoments::without(const AreaMoments& part, const Vec3& o) const {
  AreaMoments m = moved_to(o);
  const AreaMoments p = part.moved_to(o);
  m.area -= p.area;
  m.first -= p.first;
  m.xx -= p.xx, m.xy -= p.xy, m.xz -= p.xz, m.yy -= p.yy, m.yz -= p.yz, m.zz -= p.zz;
  return m;
}

AreaMoments AreaMoments::plus(const AreaMoments& other) const {
  // other.moved_to(origin) added in place: refit does this at every node, so without the copy
  // and with a multiplication for the division by 3.
  const Vec3 e = other.origin - origin;
  const Vec3 f = other.first * (1.0 / 3.0);
  const double a = other.area;
  AreaMoments m = *this;
  m.area += a;
  m.first += other.first + 3.0 * a * e;
  m.xx += other.xx + 2 * e.x() * f.x() + a * e.x() * e.x();
  m.xy += other.xy + e.x() * f.y() + f.x() * e.y() + a * e.x() * e.y();
  m.xz += other.xz + e.x() * f.z() + f.x() * e.z() + a * e.x() * e.z();
  m.yy += other.yy + 2 * e.y() * f.y() + a * e.y() * e.y();
  m.yz += other.yz + e.y() * f.z() + f.y() * e.z() + a * e.y() * e.z();
  m.zz += other.zz + 2 * e.z() * f.z() + a * e.z() * e.z();
  return m;
}

Mat3 pca_triangle_axes(std::span<const Vec3> corners, const Vec3& origin) {
  // Covariance = (sum of those) / A_total - M M^T with M the area-weighted centroid.
  if (corners.size() / 3 == 0) return pca_vertex_axes(corners, origin);
  const AreaMoments m = area_moments(corners, origin);
  if (!(m.area > 0.0)) return pca_vertex_axes(corners, origin);
  return principal_axes(m.covariance());
}

}  // namespace tightbvh::fit_detail
