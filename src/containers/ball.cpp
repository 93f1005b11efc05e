// Bounding balls: the exact minimum enclosing ball (Welzl 1991; Gaertner 1999, "Fast and robust
// smallest enclosing balls", Sec. 4 pivoting) and Ritter's 1990 approximation (Sunday's fastBall).
#include "tightbvh/ball.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "tightbvh/error.hpp"

namespace tightbvh {
namespace {

void check_points(std::span<const Vec3> points) {
  if (points.empty()) throw InputError("ball: empty point set");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("ball: point " + std::to_string(i) + " has a non-finite coordinate (NaN or Inf)");
}

struct Candidate {
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
  bool valid = false;
};

// The circumball of m affinely independent points inside their affine hull: center
// q0 + sum l_i v_i with v_i = q_i - q0 and G l = |v_i|^2 / 2 (G the Gram matrix of the v_i).
// Invalid when the points are (nearly) affinely dependent: duplicates, collinear, coplanar.
template <int M>
Candidate circumball(const std::array<Vec3, 5>& q, const std::array<int, 4>& idx) {
  const Vec3& q0 = q[idx[0]];
  if constexpr (M == 1) {
    return {q0, 0.0, true};
  } else {
    constexpr int D = M - 1;
    Eigen::Matrix<double, 3, D> v;
    for (int i = 0; i < D; ++i) v.col(i) = q[idx[i + 1]] - q0;
    const Eigen::Matrix<double, D, D> g = v.transpose() * v;
    Eigen::Matrix<double, D, 1> b;
    for (int i = 0; i < D; ++i) b(i) = 0.5 * g(i, i);
    // Normalised Gram determinant (squared sine-like volume ratio in [0, 1]).
    const double scale = g.diagonal().prod();
    const double det = g.determinant();
    if (!(scale > 0.0) || det <= 1e-26 * scale) return {};
    const Eigen::Matrix<double, D, 1> lambda = g.inverse() * b;  // closed form for D <= 3
    Candidate c{q0 + v * lambda, 0.0, true};
    for (int i = 0; i < M; ++i) c.radius = std::max(c.radius, (q[idx[i]] - c.center).norm());
    return c;
  }
}

// The exact smallest ball of n <= 5 points whose last point lies outside the smallest ball of the
// others: the smallest circumball, containing them all, of the last point and a subset of at
// most 3 of the others (Welzl 1991, Lemma 1: that point is on the boundary of the new ball; this
// halves the subsets a brute force over all of them tries). `support` receives the chosen subset.
Candidate small_ball(const std::array<Vec3, 5>& q, int n, std::array<Vec3, 5>& support, int& support_size) {
  Candidate best;
  int best_size = 0;
  std::array<int, 4> best_idx{};
  const int last = n - 1;
  for (int mask = 0; mask < (1 << last); ++mask) {
    std::array<int, 4> idx{};
    int m = 0;
    for (int i = 0; i < last && m < 4; ++i)
      if (mask & (1 << i)) idx[m++] = i;
    if (m > 3) continue;  // more than 3 of the others
    idx[m++] = last;
    Candidate c;
    switch (m) {
      case 1: c = circumball<1>(q, idx); break;
      case 2: c = circumball<2>(q, idx); break;
      case 3: c = circumball<3>(q, idx); break;
      default: c = circumball<4>(q, idx); break;
    }
    if (!c.valid || (best.valid && c.radius >= best.radius)) continue;
    const double limit = c.radius * (1.0 + 1e-13);
    bool all_in = true;
    for (int i = 0; i < n && all_in; ++i) all_in = (q[i] - c.center).norm() <= limit;
    if (!all_in) continue;
    best = c;
    best_size = m;
    best_idx = idx;
  }
  std::array<Vec3, 5> chosen;
  chosen.fill(Vec3::Zero());
  for (int i = 0; i < best_size; ++i) chosen[i] = q[best_idx[i]];
  support = chosen;
  support_size = best_size;
  return best;
}

// Grows the radius so that contains(p) holds exactly for every point (a final scan, not assumed).
Ball grown(const Vec3& center, double radius, std::span<const Vec3> points) {
  // The largest squared distance, then one square root: sqrt is monotone and correctly rounded,
  // so this is the largest norm() that contains() computes.
  double far2 = 0.0;
  for (const Vec3& p : points) far2 = std::max(far2, (p - center).squaredNorm());
  return {center, std::max(radius, std::sqrt(far2))};
}

}  // namespace

Ball bounding_ball(std::span<const Vec3> points) {
  check_points(points);
  const Vec3 origin = points[0];  // local origin: keeps precision under large offsets
  std::array<Vec3, 5> support;
  support[0] = Vec3::Zero();
  int size = 1;
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
  // Gaertner's pivoting: the farthest point enters, the new support is the small ball's
  // support of (old support + that point); the radius grows strictly, so this terminates.
  for (int iteration = 0; iteration < 10000; ++iteration) {
    double far2 = -1.0;
    Vec3 far = Vec3::Zero();
    for (const Vec3& p : points) {
      const Vec3 local = p - origin;
      const double d2 = (local - center).squaredNorm();
      if (d2 > far2) far2 = d2, far = local;
    }
    if (std::sqrt(far2) <= radius) break;
    std::array<Vec3, 5> q = support;
    q[size] = far;
    std::array<Vec3, 5> next;
    next.fill(Vec3::Zero());
    int next_size = 0;
    const Candidate c = small_ball(q, size + 1, next, next_size);
    if (!c.valid || !(c.radius > radius)) break;  // no progress left above rounding
    center = c.center;
    radius = c.radius;
    support = next;
    size = next_size;
  }
  return grown(origin + center, radius, points);
}

Ball fast_ball(std::span<const Vec3> points) {
  check_points(points);
  const Vec3 origin = points[0];
  // Pass 1 (Ritter): extreme points along x, y, z; the farthest pair is the initial diameter.
  std::array<std::size_t, 3> lo{}, hi{};
  for (std::size_t i = 1; i < points.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      if (points[i][k] < points[lo[k]][k]) lo[k] = i;
      if (points[i][k] > points[hi[k]][k]) hi[k] = i;
    }
  int axis = 0;
  double best = -1.0;
  for (int k = 0; k < 3; ++k) {
    const double d2 = (points[hi[k]] - points[lo[k]]).squaredNorm();
    if (d2 > best) best = d2, axis = k;
  }
  const Vec3 a = points[lo[axis]] - origin, b = points[hi[axis]] - origin;
  Vec3 center = 0.5 * (a + b);
  double radius = (b - center).norm();
  // Pass 2: an outside point p moves the far side of the ball to p (new diameter).
  for (const Vec3& p : points) {
    const Vec3 d = (p - origin) - center;
    const double d2 = d.squaredNorm();
    if (d2 <= radius * radius) continue;
    const double dist = std::sqrt(d2);
    const double r = 0.5 * (radius + dist);
    center += ((dist - r) / dist) * d;
    radius = r;
  }
  return grown(origin + center, radius, points);
}

}  // namespace tightbvh
