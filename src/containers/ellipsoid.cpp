// The minimum-volume enclosing ellipsoid to within (1+epsilon) in volume: Khachiyan's algorithm
// (barycentric coordinate ascent on the lifted points q_i = (x_i, 1)) with the Todd-Yildirim
// away/drop steps (Todd & Yildirim 2007, Sec. 3, the WA-TY algorithm), on a small active set of
// the points (no convex hull: see mvee()). The start is uniform weights on extreme points along
// fixed directions, in the spirit of Kumar & Yildirim's (2005, Sec. 3) extreme-point start,
// which needs d passes over the points where this takes one.
//
// Stopping criterion (duality gap). For weights u (u >= 0, sum 1) let c = sum u_i x_i,
// S = sum u_i (x_i - c)(x_i - c)^T, M = sum u_i q_i q_i^T; then det M = det S and
// kappa_i = q_i^T M^-1 q_i = 1 + (x_i - c)^T S^-1 (x_i - c). The MVEE is
// { (x - c*)^T (d S*)^-1 (x - c*) <= 1 } with u* maximising log det M(u) (Khachiyan's dual), so
// every u gives the lower bound vol(MVEE) >= V_d d^(d/2) sqrt(det S(u)). The ellipsoid
// { (x - c)^T S^-1 (x - c) <= max_i kappa_i - 1 } holds every point and has volume
// V_d (max kappa - 1)^(d/2) sqrt(det S), hence a volume ratio of at most ((max kappa - 1) / d)^(d/2).
// We stop when max_i kappa_i <= 1 + d (1+epsilon)^(2/d), i.e. max kappa <= (1+eps')(d+1) with
// 1 + eps' = (1 + d (1+epsilon)^(2/d)) / (d+1): the volume is then within (1+epsilon).
#include "tightbvh/ellipsoid.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "tightbvh/error.hpp"

namespace tightbvh {
namespace {

void check_input(std::span<const Vec3> points, double epsilon) {
  if (points.empty()) throw InputError("ellipsoid: empty point set");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("ellipsoid: point " + std::to_string(i) + " has a non-finite coordinate (NaN or Inf)");
  if (!(epsilon > 0.0) || !std::isfinite(epsilon)) throw InputError("ellipsoid: epsilon must be a positive number");
}

// Safety cap on WA-TY iterations; the final scan keeps containment even if it is reached.
constexpr int kMaxIterations = 1'000'000;

template <int D>
struct Shape {
  Eigen::Matrix<double, D, 1> center;
  Eigen::Matrix<double, D, D> scatter;  // S of the header comment
  double scale2 = 0.0;                  // max_i (x_i - c)^T S^-1 (x_i - c)
};

template <int D>
using Points = std::vector<Eigen::Matrix<double, D, 1>>;

// WA-TY (Todd & Yildirim 2007) from the weights u: Khachiyan's step toward the point of largest
// kappa, or an away step from the weighted point of smallest kappa (dropping it at the cap),
// until max kappa <= kappa_stop (see the header comment for the (1 + epsilon) volume bound).
template <int D>
void wa_ty(const Points<D>& x, std::vector<double>& u, double epsilon) {
  using VecL = Eigen::Matrix<double, D + 1, 1>;
  using MatL = Eigen::Matrix<double, D + 1, D + 1>;
  const std::size_t n = x.size();
  const auto lift = [&](std::size_t i) { return (VecL() << x[i], 1.0).finished(); };
  const auto moment = [&] {
    MatL m = MatL::Zero();
    for (std::size_t i = 0; i < n; ++i)
      if (u[i] > 0.0) {
        const VecL q = lift(i);
        m.noalias() += u[i] * q * q.transpose();
      }
    return m;
  };
  const double dp1 = D + 1.0;
  const double kappa_stop = 1.0 + D * std::pow(1.0 + epsilon, 2.0 / D);
  // kappa_i = q_i^T M^-1 q_i, kept up to date by Sherman-Morrison: each step changes M to
  // a M + b q q^T, so M^-1 and every kappa_i change by a rank-one term in g = M^-1 q
  // (O(d) per point instead of a new inverse and O(d^2) per point); recomputed from the
  // weights every kRefresh steps, after a drop, and before stopping.
  constexpr int kRefresh = 32;
  MatL inv;
  std::vector<double> kappa(n);
  int since_refresh = 0;
  const auto refresh = [&] {
    inv = moment().inverse();
    for (std::size_t i = 0; i < n; ++i) {
      const VecL q = lift(i);
      kappa[i] = q.dot(inv * q);
    }
    since_refresh = 0;
  };
  // M' = a M + b q_l q_l^T: M'^-1 = (M^-1 - b / (a + b kappa_l) g g^T) / a with g = M^-1 q_l.
  const auto rank_one = [&](std::size_t l, double a, double b) {
    const VecL g = inv * lift(l);
    const double c = b / (a + b * kappa[l]);
    inv = (inv - c * g * g.transpose()) / a;
    for (std::size_t i = 0; i < n; ++i) {
      const double t = x[i].dot(g.template head<D>()) + g[D];
      kappa[i] = (kappa[i] - c * t * t) / a;
    }
    ++since_refresh;
  };
  refresh();
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    if (since_refresh >= kRefresh) refresh();
    std::size_t j = 0, k = n;
    double kj = -1.0, kk = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      if (kappa[i] > kj) kj = kappa[i], j = i;
      if (u[i] > 0.0 && kappa[i] < kk) kk = kappa[i], k = i;
    }
    if (kj <= kappa_stop) {
      if (since_refresh == 0) return;
      refresh();
      continue;
    }
    const double eps_plus = kj / dp1 - 1.0, eps_minus = k < n ? 1.0 - kk / dp1 : 0.0;
    if (eps_plus >= eps_minus) {
      // Khachiyan's (Frank-Wolfe) step toward x_j: the exact line search of Todd-Yildirim (2.7).
      const double alpha = (kj - dp1) / (dp1 * (kj - 1.0));
      for (double& w : u) w *= 1.0 - alpha;
      u[j] += alpha;
      rank_one(j, 1.0 - alpha, alpha);
    } else {
      // Away step from x_k (Todd-Yildirim Sec. 3): the line-search step, capped so that u_k
      // stays >= 0; at the cap x_k is dropped (its weight becomes exactly zero).
      const double cap = u[k] / (1.0 - u[k]);
      double beta = kk > 1.0 ? (dp1 - kk) / (dp1 * (kk - 1.0)) : cap;
      const bool drop = beta >= cap;
      if (drop) beta = cap;
      for (double& w : u) w *= 1.0 + beta;
      u[k] = drop ? 0.0 : u[k] - beta;
      if (drop) refresh();
      else rank_one(k, 1.0 + beta, -beta);
    }
  }
}

// The first active set: the simplex of affine_dimension() (so the moment matrix starts
// non-singular) and the extreme points along the axes and the diagonals, deduplicated.
template <int D>
std::vector<std::size_t> initial_active_set(const Points<D>& x, const std::array<std::uint32_t, 4>& simplex) {
  using VecD = Eigen::Matrix<double, D, 1>;
  constexpr int kDirections = D == 3 ? 7 : 4;
  std::array<VecD, kDirections> dirs;
  if constexpr (D == 3) {
    dirs = {VecD(1, 0, 0), VecD(0, 1, 0), VecD(0, 0, 1), VecD(1, 1, 1), VecD(1, 1, -1), VecD(1, -1, 1), VecD(-1, 1, 1)};
  } else {
    dirs = {VecD(1, 0), VecD(0, 1), VecD(1, 1), VecD(1, -1)};
  }
  std::array<std::size_t, kDirections> lo{}, hi{};
  std::array<double, kDirections> lo_t, hi_t;
  lo_t.fill(std::numeric_limits<double>::infinity());
  hi_t.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int k = 0; k < kDirections; ++k) {
      const double t = dirs[k].dot(x[i]);
      if (t < lo_t[k]) lo_t[k] = t, lo[k] = i;
      if (t > hi_t[k]) hi_t[k] = t, hi[k] = i;
    }
  std::vector<std::size_t> set(simplex.begin(), simplex.begin() + D + 1);
  for (int k = 0; k < kDirections; ++k) set.push_back(lo[k]), set.push_back(hi[k]);
  std::sort(set.begin(), set.end());
  set.erase(std::unique(set.begin(), set.end()), set.end());
  return set;
}

// WA-TY on full-dimensional points x (already local and normalised to size ~1) with an active
// set (the core-set strategy of Kumar & Yildirim 2005 and Sun & Freund 2004): WA-TY runs on a few
// points only; one pass over all points then adds the ones that violate the stopping criterion
// (the worst kMaxAdded of them) and the loop repeats. u is a valid weight vector on all points
// (zero outside the active set), so the stop test over all points certifies the (1 + epsilon)
// volume exactly as if WA-TY had run on every point, and no convex hull is needed.
// Returns the weighted center and scatter and the largest scaled distance of a point.
template <int D>
Shape<D> mvee(const Points<D>& x, const std::array<std::uint32_t, 4>& simplex, double epsilon) {
  using VecD = Eigen::Matrix<double, D, 1>;
  using MatD = Eigen::Matrix<double, D, D>;
  constexpr std::size_t kMaxAdded = 16;
  constexpr int kMaxRounds = 1000;
  constexpr std::size_t kAllActiveBelow = 32;
  const double kappa_stop = 1.0 + D * std::pow(1.0 + epsilon, 2.0 / D);
  // Small sets: uniform weights on every point instead, when that start has the larger
  // log det M (Khachiyan's dual objective, so it is the nearer to the optimum): it is the optimum
  // itself on symmetric sets (a cube's or an icosahedron's corners), where the extreme points
  // along fixed directions miss some of the support.
  std::vector<std::size_t> first = initial_active_set(x, simplex);
  if (x.size() <= kAllActiveBelow && first.size() < x.size()) {
    const auto log_det_uniform = [&](const auto& index, std::size_t count) {
      MatD scatter = MatD::Zero();
      VecD mean = VecD::Zero();
      for (std::size_t k = 0; k < count; ++k) mean += x[index(k)];
      mean /= static_cast<double>(count);
      for (std::size_t k = 0; k < count; ++k) {
        const VecD v = x[index(k)] - mean;
        scatter.noalias() += v * v.transpose();
      }
      return (scatter / static_cast<double>(count)).determinant();
    };
    if (log_det_uniform([](std::size_t k) { return k; }, x.size()) >
        log_det_uniform([&](std::size_t k) { return first[k]; }, first.size())) {
      first.resize(x.size());
      for (std::size_t i = 0; i < x.size(); ++i) first[i] = i;
    }
  }
  Points<D> active;
  active.reserve(first.size() + kMaxAdded);
  for (std::size_t i : first) active.push_back(x[i]);
  std::vector<double> u(active.size(), 1.0 / static_cast<double>(active.size()));
  std::vector<std::pair<double, std::size_t>> violators;
  Shape<D> s;
  for (int round = 0;; ++round) {
    wa_ty(active, u, epsilon);
    s.center = VecD::Zero();
    double total = 0.0;
    for (std::size_t i = 0; i < active.size(); ++i) s.center += u[i] * active[i], total += u[i];
    s.center /= total;
    s.scatter.setZero();
    for (std::size_t i = 0; i < active.size(); ++i)
      if (u[i] > 0.0) {
        const VecD v = active[i] - s.center;
        s.scatter.noalias() += (u[i] / total) * v * v.transpose();
      }
    // kappa_i - 1 = (x_i - c)^T S^-1 (x_i - c) (header comment).
    const MatD inv = s.scatter.inverse();
    violators.clear();
    s.scale2 = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const VecD v = x[i] - s.center;
      const double d2 = v.dot(inv * v);
      s.scale2 = std::max(s.scale2, d2);
      if (d2 + 1.0 > kappa_stop) violators.emplace_back(d2, i);
    }
    if (violators.empty() || round == kMaxRounds) return s;
    if (violators.size() > kMaxAdded) {
      std::nth_element(violators.begin(), violators.begin() + kMaxAdded, violators.end(),
                       [](const auto& a, const auto& b) { return a.first > b.first; });
      violators.resize(kMaxAdded);
    }
    for (const auto& [d2, i] : violators) active.push_back(x[i]), u.push_back(0.0);
  }
}

// Any unit vector orthogonal to the unit vector a.
Vec3 orthogonal(const Vec3& a) {
  const Vec3 e = std::abs(a.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY();
  return (e - e.dot(a) * a).normalized();
}

// The final containment scan: scales the radii by the largest scaled distance of any point, and
// gives zero radii a thickness in the rare case a point is off the flat set beyond the slack.
// Ends with contains(p) true (tolerance 0) for every point.
Ellipsoid contain_all(Ellipsoid e, std::span<const Vec3> points) {
  // Positive radii: exact scale by the maximum, as computed by contains().
  double m = 0.0;
  Vec3 thick = Vec3::Zero();
  for (const Vec3& p : points) {
    const Vec3 y = e.axes.transpose() * (p - e.center);
    double s = 0.0;
    for (int k = 0; k < 3; ++k)
      if (e.radii[k] > 0.0) s += (y[k] / e.radii[k]) * (y[k] / e.radii[k]);
      else thick[k] = std::max(thick[k], std::abs(y[k]));
    m = std::max(m, s);
  }
  if (m > 0.0) e.radii *= std::sqrt(m);
  const double slack = e.flat_slack();
  int thin = 0;
  for (int k = 0; k < 3; ++k) thin += e.radii[k] == 0.0 && thick[k] > slack;
  if (thin > 0) {
    // m/(1+delta) + sum (y_k/r_k)^2 <= 1/(1+delta) + thin * delta/(thin (1+delta)) = 1.
    constexpr double delta = 1e-6;
    for (int k = 0; k < 3; ++k)
      e.radii[k] = e.radii[k] > 0.0 ? e.radii[k] * std::sqrt(1.0 + delta)
                   : thick[k] > slack ? thick[k] * std::sqrt(thin * (1.0 + delta) / delta)
                                      : 0.0;
  }
  // Rounding: grow by a few ulps until the shared test accepts every point.
  for (double grow = 1.0 + 4e-16; grow < 2.0; grow = 1.0 + 4.0 * (grow - 1.0)) {
    double worst = 0.0;
    for (const Vec3& p : points) worst = std::max(worst, e.scaled_distance2(p));
    if (worst <= 1.0) break;
    e.radii *= grow * (std::isfinite(worst) ? std::sqrt(worst) : 1.0);
  }
  return e;
}

// Right-handed orthonormal columns.
Mat3 right_handed(Mat3 a) {
  if (a.determinant() < 0.0) a.col(2) = -a.col(2);
  return a;
}

}  // namespace

Ellipsoid bounding_ellipsoid(std::span<const Vec3> points, double epsilon) {
  check_input(points, epsilon);
  const AffineDimension dim = affine_dimension(points);
  const Vec3 box_center = 0.5 * (dim.bounds.min + dim.bounds.max);
  const double half = 0.5 * (dim.bounds.max - dim.bounds.min).maxCoeff();
  Ellipsoid e;
  e.center = box_center;
  if (dim.dimension == 0) return contain_all(e, points);  // the point: radii 0

  const Vec3 anchor = points[dim.simplex[0]];
  if (dim.dimension == 1) {
    // The segment: its midpoint, the half length along the line.
    const Vec3& a = dim.direction;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Vec3& p : points) {
      const double t = a.dot(p - anchor);
      lo = std::min(lo, t), hi = std::max(hi, t);
    }
    e.center = anchor + 0.5 * (lo + hi) * a;
    const Vec3 b = orthogonal(a);
    e.axes.col(0) = a, e.axes.col(1) = b, e.axes.col(2) = a.cross(b);
    e.radii = Vec3(0.5 * (hi - lo), 0.0, 0.0);
    return contain_all(e, points);
  }

    if (dim.dimension == 2) {
    // The minimum-area ellipse in the plane (the same algorithm with d = 2), radius 0 across.
    const Vec3 n = dim.normal, e1 = orthogonal(n), e2 = n.cross(e1);
    const Vec3 origin = box_center - n.dot(box_center - anchor) * n;  // in the plane
    std::vector<Vec2> x;
    x.reserve(points.size());
    for (const Vec3& p : points) x.emplace_back(e1.dot(p - origin) / half, e2.dot(p - origin) / half);
    const Shape<2> s = mvee<2>(x, dim.simplex, epsilon);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(s.scatter);
    e.center = origin + half * (s.center.x() * e1 + s.center.y() * e2);
    const Eigen::Matrix2d v = eig.eigenvectors();
    e.axes.col(0) = v(0, 0) * e1 + v(1, 0) * e2;
    e.axes.col(1) = v(0, 1) * e1 + v(1, 1) * e2;
    e.axes.col(2) = e.axes.col(0).cross(e.axes.col(1));
    const Eigen::Vector2d r = (eig.eigenvalues().cwiseMax(0.0) * s.scale2).cwiseSqrt() * half;
    e.radii = Vec3(r.x(), r.y(), 0.0);
    return contain_all(e, points);
  }

  // Solid: relative to the box center, normalised by the half extent (keeps 1e6 offsets exact
  // enough and the lifted moment matrix well scaled).
  std::vector<Vec3> x;
  x.reserve(points.size());
  for (const Vec3& p : points) x.push_back((p - box_center) / half);
  const Shape<3> s = mvee<3>(x, dim.simplex, epsilon);
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(s.scatter);
  e.center = box_center + half * s.center;
  e.axes = right_handed(eig.eigenvectors());
  e.radii = (eig.eigenvalues().cwiseMax(0.0) * s.scale2).cwiseSqrt() * half;
  return contain_all(e, points);
}

}  // namespace tightbvh
