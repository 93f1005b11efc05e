#pragma once
// The distance between two convex sets given by their support functions: GJK (Gilbert, Johnson &
// Keerthi 1988, "A fast procedure for computing the distance between complex objects in
// three-dimensional space"; Ericson, Real-Time Collision Detection, §9.5). The simplex's closest
// point to the origin is found by trying its sub-simplices that hold the newest vertex (the
// support point that made progress must stay in the support set) and keeping the nearest whose
// barycentric coordinates are all >= 0 (Johnson's distance subalgorithm, solved directly on the
// Gram system of each sub-simplex, Cramer's rule; near-singular sub-simplices are skipped, a
// smaller one covers them, as in the signed-volumes approach of Montanari, Petrinic & Barbieri
// 2017). Every iteration also gives a lower bound v . w / |v| (w the support point of A - B
// against v), so the loop stops when |v| is within the requested error of that bound.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "tightbvh/math.hpp"

namespace tightbvh::gjk {

// The answer: `distance` = |point_a - point_b| (an upper bound of the true distance, within the
// error asked for of it when `converged`), `lower` a proven lower bound.
struct Result {
  double distance = 0.0;
  double lower = 0.0;
  Vec3 point_a = Vec3::Zero();  // in A
  Vec3 point_b = Vec3::Zero();  // in B
  bool overlapping = false;     // the origin is in the simplex: the sets share a point
  bool converged = false;
  int iterations = 0;
};

namespace detail {

struct Vertex {
  Vec3 w, a, b;  // w = a - b
};

// The closest point to the origin of the affine hull of the given vertices, as barycentric
// weights; false when the sub-simplex is (nearly) degenerate or the point is outside it.
inline bool solve(const std::array<Vertex, 4>& s, const int* idx, int k, double* lambda) {
  const Vec3& p0 = s[idx[0]].w;
  if (k == 1) {
    lambda[0] = 1.0;
    return true;
  }
  if (k == 2) {
    const Vec3 e = s[idx[1]].w - p0;
    const double ee = e.squaredNorm();
    if (!(ee > 0.0)) return false;
    const double t = -p0.dot(e) / ee;
    if (!(t >= 0.0 && t <= 1.0)) return false;
    lambda[0] = 1.0 - t;
    lambda[1] = t;
    return true;
  }
  if (k == 3) {
    const Vec3 e1 = s[idx[1]].w - p0, e2 = s[idx[2]].w - p0;
    const double g11 = e1.squaredNorm(), g12 = e1.dot(e2), g22 = e2.squaredNorm();
    const double det = g11 * g22 - g12 * g12;
    if (!(det > 1e-14 * g11 * g22)) return false;
    const double b1 = -p0.dot(e1), b2 = -p0.dot(e2);
    const double m1 = (b1 * g22 - b2 * g12) / det, m2 = (g11 * b2 - g12 * b1) / det;
    if (!(m1 >= 0.0 && m2 >= 0.0 && m1 + m2 <= 1.0)) return false;
    lambda[0] = 1.0 - m1 - m2;
    lambda[1] = m1;
    lambda[2] = m2;
    return true;
  }
  // k == 4: the origin as p0 + m1 e1 + m2 e2 + m3 e3.
  const Vec3 e1 = s[idx[1]].w - p0, e2 = s[idx[2]].w - p0, e3 = s[idx[3]].w - p0;
  const Vec3 c23 = e2.cross(e3);
  const double det = e1.dot(c23);
  if (!(std::abs(det) > 1e-14 * e1.norm() * e2.norm() * e3.norm())) return false;
  const Vec3 r = -p0;
  const double m1 = r.dot(c23) / det, m2 = e1.dot(r.cross(e3)) / det, m3 = e1.dot(e2.cross(r)) / det;
  if (!(m1 >= 0.0 && m2 >= 0.0 && m3 >= 0.0 && m1 + m2 + m3 <= 1.0)) return false;
  lambda[0] = 1.0 - m1 - m2 - m3;
  lambda[1] = m1;
  lambda[2] = m2;
  lambda[3] = m3;
  return true;
}

}  // namespace detail

// GJK between A (support_a(d): a point of A maximising d . x) and B, starting from the points
// a0 of A and b0 of B. Stops when |v| - lower <= absolute + relative * |v|, when |v| <= absolute
// (touching within the allowance: overlapping), or after max_iterations. With decide >= 0, also
// as soon as the question "distance <= decide?" is settled: lower > decide (no), or |v| <=
// decide (yes: |v| only decreases, so the converged distance would be <= decide too).
template <class SupportA, class SupportB>
[[nodiscard]] Result distance(const SupportA& support_a, const SupportB& support_b, const Vec3& a0, const Vec3& b0,
                              double absolute, double relative, int max_iterations = 128, double decide = -1.0) {
  std::array<detail::Vertex, 4> s;
  int n = 1;
  s[0] = {a0 - b0, a0, b0};
  Result r;
  Vec3 v = s[0].w;
  double lower = 0.0;
  for (int it = 0; it < max_iterations; ++it) {
    r.iterations = it + 1;
    const double vv = v.squaredNorm();
    const double vn = std::sqrt(vv);
    if (vn <= absolute) {
      r.overlapping = vn == 0.0;
      r.converged = true;
      break;
    }
    if (vn <= decide) break;
    const Vec3 a = support_a(-v), b = support_b(v);
    const Vec3 w = a - b;
    lower = std::max(lower, v.dot(w) / vn);
    if (decide >= 0.0 && lower > decide) break;
    if (vn - lower <= absolute + relative * vn) {
      r.converged = true;
      break;
    }
    bool repeated = false;
    for (int i = 0; i < n; ++i)
      if (s[i].w == w) repeated = true;
    if (repeated || n == 4) {  // no progress possible in double precision
      r.converged = vn - lower <= 1e3 * (absolute + relative * vn);
      break;
    }
    s[n++] = {w, a, b};
    // Sub-simplices holding the newest vertex (index n - 1), smallest first.
    double best = std::numeric_limits<double>::infinity();
    int best_idx[4] = {0, 0, 0, 0}, best_k = 0;
    double best_lambda[4] = {0.0, 0.0, 0.0, 0.0};
    const int others = n - 1;
    for (int mask = 0; mask < (1 << others); ++mask) {
      int idx[4], k = 0;
      idx[k++] = n - 1;
      for (int i = 0; i < others; ++i)
        if ((mask >> i) & 1) idx[k++] = i;
      double lambda[4];
      if (!detail::solve(s, idx, k, lambda)) continue;
      Vec3 p = Vec3::Zero();
      for (int i = 0; i < k; ++i) p += lambda[i] * s[idx[i]].w;
      const double d2 = k == 4 ? 0.0 : p.squaredNorm();
      if (d2 < best) {
        best = d2;
        best_k = k;
        std::copy(idx, idx + k, best_idx);
        std::copy(lambda, lambda + k, best_lambda);
      }
    }
    if (best_k == 0) {  // numerically stuck: keep the previous simplex and answer
      --n;
      r.converged = vn - lower <= 1e3 * (absolute + relative * vn);
      break;
    }
    std::array<detail::Vertex, 4> kept;
    v = Vec3::Zero();
    for (int i = 0; i < best_k; ++i) {
      kept[i] = s[best_idx[i]];
      v += best_lambda[i] * kept[i].w;
    }
    if (best_k == 4) {
      v = Vec3::Zero();
      r.overlapping = true;
    }
    s = kept;
    n = best_k;
    // Barycentric weights of the kept simplex, for the closest points.
    r.point_a = Vec3::Zero();
    r.point_b = Vec3::Zero();
    for (int i = 0; i < n; ++i) {
      r.point_a += best_lambda[i] * s[i].a;
      r.point_b += best_lambda[i] * s[i].b;
    }
    if (r.overlapping) {
      r.converged = true;
      break;
    }
  }
  if (n == 1) r.point_a = s[0].a, r.point_b = s[0].b;  // a single vertex (also before any solve)
  r.distance = r.overlapping ? 0.0 : (r.point_a - r.point_b).norm();
  r.lower = r.overlapping ? 0.0 : std::min(lower, r.distance);
  return r;
}

}  // namespace tightbvh::gjk
