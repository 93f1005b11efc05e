#pragma once
// Exact orientation predicates for double coordinates (internal to the library: used by the
// triangle-triangle test and by the 2D hull, whose monotone chain needs consistent signs).
//
// Each predicate first evaluates the determinant in double precision with a forward error bound
// (a static filter in the style of Shewchuk 1997, "Adaptive Precision Floating-Point Arithmetic
// and Fast Robust Geometric Predicates"); only when the result is within the bound is it
// recomputed exactly with floating-point expansions (error-free sums and products, Knuth /
// Dekker; expansion growth and scaling, Shewchuk Section 2). The returned sign is the sign of the
// exact determinant of the given doubles. Assumes no overflow (|coordinates| < ~1e100).
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "tightbvh/pose.hpp"

namespace tightbvh::detail {

inline constexpr double kUnitRoundoff = 1.1102230246251565e-16;  // 2^-53
// Forward error bounds (generous: Shewchuk's are (3 + 16u)u and (7 + 56u)u).
inline constexpr double kOrient2dBound = 8.0 * kUnitRoundoff;
inline constexpr double kOrient3dBound = 16.0 * kUnitRoundoff;

// ---------------------------------------------------------------- error-free transformations
inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  y = (a - av) + (b - bv);
}

// Requires |a| >= |b| (or a == 0).
inline void fast_two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  y = b - (x - a);
}

inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
#if defined(__FMA__) || defined(__FP_FAST_FMA)
  y = std::fma(a, b, -x);
#else
  // Dekker's split (no FMA instructions exist, so nothing can be contracted here).
  constexpr double kSplitter = 134217729.0;  // 2^27 + 1
  double c = kSplitter * a;
  const double ahi = c - (c - a), alo = a - ahi;
  c = kSplitter * b;
  const double bhi = c - (c - b), blo = b - bhi;
  y = alo * blo - (((x - ahi * bhi) - alo * bhi) - ahi * blo);
#endif
}

// ---------------------------------------------------------------- expansions
// A value represented as the exact sum of non-overlapping doubles in increasing magnitude, with
// zero components eliminated. Capacity N.
template <int N>
struct Expansion {
  double c[N];
  int n = 0;

  // this += b (GROW-EXPANSION, in place: component i is read before position <= i is written).
  void add(double b) {
    if (b == 0.0) return;
    double q = b;
    int m = 0;
    for (int i = 0; i < n; ++i) {
      double sum, err;
      two_sum(q, c[i], sum, err);
      q = sum;
      if (err != 0.0) c[m++] = err;
    }
    if (q != 0.0 || m == 0) c[m++] = q;
    n = m;
  }
  // this += f, f a non-overlapping expansion of fn components (FAST-EXPANSION-SUM, Shewchuk
  // Theorem 13: merge the components by magnitude, then an error-free running sum; the output is
  // non-overlapping under round-to-nearest-even).
  void add(const double* f, int fn) {
    double merged[N];
    const int total = static_cast<int>(
        std::merge(c, c + n, f, f + fn, merged, [](double x, double y) { return std::abs(x) < std::abs(y); }) - merged);
    if (total == 0) return;
    double q = merged[0];
    int m = 0;
    for (int i = 1; i < total; ++i) {
      double sum, err;
      two_sum(q, merged[i], sum, err);
      if (err != 0.0) c[m++] = err;
      q = sum;
    }
    if (q != 0.0 || m == 0) c[m++] = q;
    n = m;
  }
  [[nodiscard]] int sign() const { return n == 0 ? 0 : (c[n - 1] > 0.0) - (c[n - 1] < 0.0); }
};

// s * a * b * c added exactly to `out` (s = +1 or -1).
template <int N>
inline void add_triple_product(Expansion<N>& out, double s, double a, double b, double c) {
  double p, e;
  two_product(s * a, b, p, e);
  // (e, p) scaled by c: SCALE-EXPANSION (Shewchuk Theorem 19) on a two-component expansion.
  double h[4];
  int k = 0;
  double q, lo;
  two_product(e, c, q, lo);
  if (lo != 0.0) h[k++] = lo;
  double t_hi, t_lo;
  two_product(p, c, t_hi, t_lo);
  double sum;
  two_sum(q, t_lo, sum, lo);
  if (lo != 0.0) h[k++] = lo;
  fast_two_sum(t_hi, sum, q, lo);
  if (lo != 0.0) h[k++] = lo;
  if (q != 0.0) h[k++] = q;
  out.add(h, k);
}

// ---------------------------------------------------------------- orient2d
// (b - a) x (c - a) for 2D points given as (ax, ay), ..., exactly, as an expansion.
[[nodiscard]] inline Expansion<13> orient2d_expansion(double ax, double ay, double bx, double by, double cx,
                                                      double cy) {
  // (b - a) x (c - a) = a x b + b x c + c x a.
  Expansion<13> e;
  const auto add_product = [&e](double s, double u, double v) {
    double p, err;
    two_product(s * u, v, p, err);
    e.add(err);
    e.add(p);
  };
  add_product(1, ax, by), add_product(-1, ay, bx);
  add_product(1, bx, cy), add_product(-1, by, cx);
  add_product(1, cx, ay), add_product(-1, cy, ax);
  return e;
}

// Sign of (b - a) x (c - a).
[[nodiscard]] inline int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy) {
  return orient2d_expansion(ax, ay, bx, by, cx, cy).sign();
}

// The value of (b - a) x (c - a) with a small relative error (the rounded products when the
// filter bounds their error well below the result, else the exact expansion summed from its
// smallest component up): accurate even for nearly collinear points, whose rounded value can be
// pure noise or zero.
[[nodiscard]] inline double orient2d_value(double ax, double ay, double bx, double by, double cx, double cy) {
  const double l = (bx - ax) * (cy - ay), r = (by - ay) * (cx - ax);
  const double det = l - r;
  if (std::abs(det) > 1e10 * kOrient2dBound * (std::abs(l) + std::abs(r))) return det;  // relative error < 1e-10
  const Expansion<13> e = orient2d_expansion(ax, ay, bx, by, cx, cy);
  double sum = 0.0;
  for (int i = 0; i < e.n; ++i) sum += e.c[i];
  return sum;
}

// (b - a) x (c - a) with every component accurate (see orient2d_value): the normal of a sliver
// triangle, whose rounded cross product can be zero although the triangle is not degenerate.
[[nodiscard]] inline Vec3 accurate_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  return {orient2d_value(a.y(), a.z(), b.y(), b.z(), c.y(), c.z()),
          orient2d_value(a.z(), a.x(), b.z(), b.x(), c.z(), c.x()),
          orient2d_value(a.x(), a.y(), b.x(), b.y(), c.x(), c.y())};
}

[[nodiscard]] inline int orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  const double l = (bx - ax) * (cy - ay), r = (by - ay) * (cx - ax);
  const double det = l - r;
  const double bound = kOrient2dBound * (std::abs(l) + std::abs(r));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  if (bound == 0.0) return 0;  // an exactly zero difference in both products
  if ((ax == bx && ay == by) || (ax == cx && ay == cy) || (bx == cx && by == cy)) return 0;
  return orient2d_exact(ax, ay, bx, by, cx, cy);
}

// True iff a, b, c lie on one line (or coincide), exactly: (b - a) x (c - a) = 0, i.e. all three
// coordinate projections are degenerate (orient2d == 0 in the xy, yz and zx planes).
[[nodiscard]] inline bool collinear(const Vec3& a, const Vec3& b, const Vec3& c) {
  return orient2d(a.x(), a.y(), b.x(), b.y(), c.x(), c.y()) == 0 &&
         orient2d(a.y(), a.z(), b.y(), b.z(), c.y(), c.z()) == 0 &&
         orient2d(a.z(), a.x(), b.z(), b.x(), c.z(), c.x()) == 0;
}

// ---------------------------------------------------------------- orient3d
// Adds det[u, v, w] (columns) to `out` exactly: the six triple products of the Leibniz formula.
template <int N>
inline void add_determinant(Expansion<N>& out, const Vec3& u, const Vec3& v, const Vec3& w) {
  add_triple_product(out, 1, u.x(), v.y(), w.z());
  add_triple_product(out, -1, u.x(), v.z(), w.y());
  add_triple_product(out, -1, u.y(), v.x(), w.z());
  add_triple_product(out, 1, u.y(), v.z(), w.x());
  add_triple_product(out, 1, u.z(), v.x(), w.y());
  add_triple_product(out, -1, u.z(), v.y(), w.x());
}

// Sign of det[b - a, c - a, d - a] = ((b - a) x (c - a)) . (d - a): > 0 iff d is on the side of
// plane (a, b, c) that (b - a) x (c - a) points to.
[[nodiscard]] inline int orient3d_exact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // Fast exact case: when the differences b - a, c - a, d - a are exact doubles (Sterbenz:
  // close coordinates), det[u, v, w] is the sum of six products of three doubles.
  const Vec3 u = b - a, v = c - a, w = d - a;
  const auto exact_difference = [](double x, double y, double diff) {
    double s, e;
    two_sum(x, -y, s, e);
    return e == 0.0 && s == diff;
  };
  bool exact = true;
  for (int k = 0; k < 3 && exact; ++k)
    exact = exact_difference(b[k], a[k], u[k]) && exact_difference(c[k], a[k], v[k]) && exact_difference(d[k], a[k], w[k]);
  if (exact) {
    Expansion<6 * 4 + 1> e;
    add_determinant(e, u, v, w);
    return e.sign();
  }
  // General case: det[b - a, c - a, d - a] = [b, c, d] - [a, c, d] + [a, b, d] - [a, b, c], with
  // the triple product [x, y, z] = x . (y x z) expanded into six products of three coordinates.
  // Each triple product is summed on its own, then the four pairwise (shorter merges).
  const auto triple = [](Expansion<25>& e, double s, const Vec3& x, const Vec3& y, const Vec3& z) {
    add_triple_product(e, s, x.x(), y.y(), z.z());
    add_triple_product(e, -s, x.x(), y.z(), z.y());
    add_triple_product(e, -s, x.y(), y.x(), z.z());
    add_triple_product(e, s, x.y(), y.z(), z.x());
    add_triple_product(e, s, x.z(), y.x(), z.y());
    add_triple_product(e, -s, x.z(), y.y(), z.x());
  };
  Expansion<25> t[4];
  triple(t[0], 1, b, c, d);
  triple(t[1], -1, a, c, d);
  triple(t[2], 1, a, b, d);
  triple(t[3], -1, a, b, c);
  Expansion<97> total;
  Expansion<49> half;
  half.add(t[0].c, t[0].n);
  half.add(t[1].c, t[1].n);
  total.add(half.c, half.n);
  half.n = 0;
  half.add(t[2].c, t[2].n);
  half.add(t[3].c, t[3].n);
  total.add(half.c, half.n);
  return total.sign();
}

// Adaptive evaluation after the filter failed (Shewchuk's stages B and C): the determinant of the
// rounded differences exactly, then with the first-order terms of the differences' rounding
// errors; the full exact evaluation only when neither is decisive.
[[nodiscard]] inline int orient3d_adaptive(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  Vec3 u, v, w, ut, vt, wt;  // rounded differences and their exact rounding errors
  for (int k = 0; k < 3; ++k) {
    two_sum(b[k], -a[k], u[k], ut[k]);
    two_sum(c[k], -a[k], v[k], vt[k]);
    two_sum(d[k], -a[k], w[k], wt[k]);
  }
  Expansion<25> e;  // det[u, v, w] exactly
  add_determinant(e, u, v, w);
  if (ut == Vec3::Zero() && vt == Vec3::Zero() && wt == Vec3::Zero()) return e.sign();  // exact differences
  double estimate = 0.0;
  for (int i = 0; i < e.n; ++i) estimate += e.c[i];
  const Vec3 ua = u.cwiseAbs(), va = v.cwiseAbs(), wa = w.cwiseAbs();
  const double permanent = wa.x() * (ua.y() * va.z() + ua.z() * va.y()) + wa.y() * (ua.z() * va.x() + ua.x() * va.z()) +
                           wa.z() * (ua.x() * va.y() + ua.y() * va.x());
  // Stage B: |exact - det[u, v, w]| <= (3u + O(u^2)) permanent (Shewchuk: (3 + 28u)u).
  const double bound_b = 4.0 * kUnitRoundoff * permanent;
  if (estimate > bound_b) return 1;
  if (-estimate > bound_b) return -1;
  // Stage C: add the first-order error terms (Shewchuk: (26 + 288u)u^2 permanent + (3 + 8u)u |det|).
  const double det = estimate + (ut.dot(v.cross(w)) + vt.dot(w.cross(u)) + wt.dot(u.cross(v)));
  const double bound_c = 32.0 * kUnitRoundoff * kUnitRoundoff * permanent + 4.0 * kUnitRoundoff * std::abs(det);
  if (det > bound_c) return 1;
  if (-det > bound_c) return -1;
  return orient3d_exact(a, b, c, d);
}

// OrientPlane::filter()'s verdict when the rounded determinant does not decide the sign.
inline constexpr int kUndecided = 2;

// A plane through (a, b, c) prepared for many orient3d queries against it.
struct OrientPlane {
  const Vec3* a;
  const Vec3* b;
  const Vec3* c;
  Vec3 origin;     // *a, copied: the filter reads no other memory
  Vec3 normal;     // (b - a) x (c - a), rounded
  Vec3 permanent;  // the same with |.| on every product: bounds the rounding error
  bool repeated;   // two of a, b, c coincide: every orientation is zero

  OrientPlane(const Vec3& pa, const Vec3& pb, const Vec3& pc)
      : a(&pa), b(&pb), c(&pc), origin(pa), repeated(pa == pb || pa == pc || pb == pc) {
    const Vec3 u = pb - pa, v = pc - pa;
    normal = u.cross(v);
    permanent = Vec3(std::abs(u.y() * v.z()) + std::abs(u.z() * v.y()), std::abs(u.z() * v.x()) + std::abs(u.x() * v.z()),
                     std::abs(u.x() * v.y()) + std::abs(u.y() * v.x()));
  }

  [[nodiscard]] int sign(const Vec3& d) const {
    double det;
    const int s = filter(d, det);
    return s != kUndecided ? s : resolve(d);
  }
  // The static filter alone: +1 or -1 when decisive, 0 when the determinant is exactly zero
  // because every product in it has a zero factor (e.g. all four points on a plane z = const),
  // else kUndecided. `det` gets the rounded determinant normal . (d - a) (it ranks points by their
  // distance to the plane).
  [[nodiscard]] int filter(const Vec3& d, double& det) const {
    const Vec3 w = d - origin;
    det = normal.dot(w);
    const double bound = kOrient3dBound * permanent.dot(w.cwiseAbs());
    if (det > bound) return 1;
    if (-det > bound) return -1;
    return bound == 0.0 ? 0 : kUndecided;
  }
  // An upper bound on filter()'s error bound for every d whose rounded difference d - a is at
  // most `extent` in absolute value, componentwise (e.g. the extents of a box holding a and d).
  [[nodiscard]] double bound_within(const Vec3& extent) const {
    constexpr double kMargin = 1.0 + 8.0 * kUnitRoundoff;  // rounding of this bound itself
    return kOrient3dBound * kMargin * permanent.dot(extent * kMargin);
  }
  // The sign for such a d when the rounded determinant alone decides it (it exceeds
  // bound_within() in absolute value): `above` for +1, `below` for -1, neither when filter()
  // must decide. Branch-free, for loops over many points whose signs are unpredictable.
  void classify_within(const Vec3& d, double bound, double& det, bool& above, bool& below) const {
    det = normal.dot(d - origin);
    above = det > bound;
    below = -det > bound;
  }
  // The exact sign where filter() was undecided.
  [[nodiscard]] int resolve(const Vec3& d) const {
    if (repeated || d == *a || d == *b || d == *c) return 0;
    // The same sign with b or c as the base point (a cyclic rotation): when d lies on an
    // axis-parallel line through two of the vertices (extruded CAD shapes), one of the rotations
    // has a zero bound, so the costly exact stages are skipped.
    double det;
    if (const int s = OrientPlane(*b, *c, *a).filter(d, det); s != kUndecided) return s;
    if (const int s = OrientPlane(*c, *a, *b).filter(d, det); s != kUndecided) return s;
    // An edge parallel to a coordinate axis k (its other two coordinates equal): with u = b - a
    // = (0, u_k, 0), det[u, v, w] = u_k (v x w)_k, a 2D orientation in the other two coordinates,
    // whose exact stages cost a fraction of orient3d's.
    const Vec3* corner[3] = {a, b, c};
    for (int e = 0; e < 3; ++e) {
      const Vec3 &p = *corner[e], &q = *corner[(e + 1) % 3], &r = *corner[(e + 2) % 3];
      for (int k = 0; k < 3; ++k) {
        const int i = (k + 1) % 3, j = (k + 2) % 3;
        if (p[i] != q[i] || p[j] != q[j]) continue;
        const int along = (q[k] > p[k]) - (q[k] < p[k]);
        return along * orient2d(p[i], p[j], r[i], r[j], d[i], d[j]);
      }
    }
    return orient3d_adaptive(*a, *b, *c, d);
  }
};

[[nodiscard]] inline int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return OrientPlane(a, b, c).sign(d);
}

}  // namespace tightbvh::detail
