// Bounding balls: the exact minimum enclosing ball (Welzl 1991; Gaertner 1999, "Fast and robust
// smallest enclosing balls", Sec. 4 pivoting) and Ritter's 1990 approximation (Sunday's fastBall).
#include "tightbvh/ball.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "tightbvh/error.hpp"

namespace tightbvh {
namespace {

void check_points(std::span<const Vec3> points) {
  if (points.empty()) throw InputError("ball: empty point set");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("ball: point " + std::to_string(i) + " has a non-finite coordinate (NaN or Inf)");
}

// Working-set growth per pass over all points, and a cap on the passes (the last pass grows the
// radius over every point whatever happens).
constexpr std::size_t kMaxAdded = 16;
constexpr int kMaxRounds = 100;

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

// Grows the radius so that contains(p) holds exactly for every point (a final scan, not assumed):
// the largest squared distance, then one square root (sqrt is monotone and correctly rounded, so
// this is the largest norm() that contains() computes).
Ball grown(const Vec3& center, double radius, std::span<const Vec3> points) {
  double far2 = 0.0;
  for (const Vec3& p : points) far2 = std::max(far2, (p - center).squaredNorm());
  return {center, std::max(radius, std::sqrt(far2))};
}

// Gaertner's pivoting state: the support (on the boundary) and its ball, in local coordinates.
struct Pivoting {
  std::array<Vec3, 5> support;
  int size = 0;
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
};

// Gaertner's pivoting on the points w: the farthest point enters, the new support is the small
// ball's support of (old support + that point); the radius grows strictly, so this terminates.
void pivot(const std::vector<Vec3>& w, Pivoting& st) {
  for (int iteration = 0; iteration < 10000; ++iteration) {
    double far2 = -1.0;
    Vec3 far = Vec3::Zero();
    for (const Vec3& p : w) {
      const double d2 = (p - st.center).squaredNorm();
      if (d2 > far2) far2 = d2, far = p;
    }
    if (std::sqrt(far2) <= st.radius) return;
    std::array<Vec3, 5> q = st.support;
    q[st.size] = far;
    std::array<Vec3, 5> next;
    next.fill(Vec3::Zero());
    int next_size = 0;
    const Candidate c = small_ball(q, st.size + 1, next, next_size);
    if (!c.valid || !(c.radius > st.radius)) return;  // no progress left above rounding
    st.center = c.center;
    st.radius = c.radius;
    st.support = next;
    st.size = next_size;
  }
}

}  // namespace

Ball bounding_ball(std::span<const Vec3> points) {
  if (points.empty()) check_points(points);
  const Vec3 origin = points[0];  // local origin: keeps precision under large offsets
  // Pass 1: finiteness, and the extreme points along the axes: a working set whose ball is
  // usually close to the answer (a core set, as in the ellipsoid's active set).
  std::array<std::size_t, 6> first{};
  Vec3 lo_t = points[0], hi_t = points[0];
  double nan_check = 0.0;  // NaN once any coordinate is NaN or infinite
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    nan_check += (p - p).sum();
    for (int k = 0; k < 3; ++k) {
      if (p[k] < lo_t[k]) lo_t[k] = p[k], first[2 * k] = i;
      if (p[k] > hi_t[k]) hi_t[k] = p[k], first[2 * k + 1] = i;
    }
  }
  if (!(nan_check == 0.0)) check_points(points);  // throws, naming the first non-finite point
  std::sort(first.begin(), first.end());
  std::vector<Vec3> w;
  w.reserve(first.size() + kMaxAdded);
  for (std::size_t k = 0; k < first.size(); ++k)
    if (k == 0 || first[k] != first[k - 1]) w.push_back(points[first[k]] - origin);
  Pivoting st;
  st.support[0] = w[0];
  st.size = 1;
  st.center = w[0];
  // The exact ball of the working set, then a pass over all points: the ones outside join the
  // working set (the farthest and up to kMaxAdded - 1 more), until none is outside. The last
  // pass is also the final containment scan (as grown()).
  for (int round = 0;; ++round) {
    pivot(w, st);
    const Vec3 center = origin + st.center;
    double far2 = 0.0;
    std::size_t far = 0;
    std::array<std::size_t, kMaxAdded> outside{};
    std::size_t count = 0;
    const double r2 = st.radius * st.radius;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double d2 = (points[i] - center).squaredNorm();
      if (d2 > far2) far2 = d2, far = i;
      if (d2 > r2 && count + 1 < kMaxAdded) outside[count++] = i;
    }
    if (std::sqrt(far2) <= st.radius || round == kMaxRounds) return {center, std::max(st.radius, std::sqrt(far2))};
    w.push_back(points[far] - origin);
    for (std::size_t k = 0; k < count; ++k)
      if (outside[k] != far) w.push_back(points[outside[k]] - origin);
  }
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
