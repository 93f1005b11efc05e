// k-DOPs with fixed directions (Sunday, "Bounding Containers": the bounding box, the bounding
// diamond and their combination, the cuboctahedron; 18- and 26-DOPs add the edge directions).
#include "tightbvh/dop.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tightbvh/error.hpp"

namespace tightbvh {
namespace {

// All 13 directions: box (0-2), edges (3-8), diamond (9-12).
const std::array<Vec3, 13>& all_directions() {
  static const std::array<Vec3, 13> d{Vec3(1, 0, 0),  Vec3(0, 1, 0),  Vec3(0, 0, 1),  Vec3(1, 1, 0),  Vec3(1, 0, 1),
                                      Vec3(0, 1, 1),  Vec3(1, -1, 0), Vec3(1, 0, -1), Vec3(0, 1, -1), Vec3(1, 1, 1),
                                      Vec3(1, 1, -1), Vec3(1, -1, 1), Vec3(1, -1, -1)};
  return d;
}

int direction_index(DopKind kind, int i) {
  switch (kind) {
    case DopKind::diamond: return 9 + i;
    case DopKind::dop14: return i < 3 ? i : 6 + i;
    case DopKind::dop18: return i;
    case DopKind::dop26: return i;
  }
  return i;
}

// The one projection used for both fitting and containment, so fitted points test inside exactly.
double project(const Vec3& d, const Vec3& p) { return d.x() * p.x() + d.y() * p.y() + d.z() * p.z(); }

using Polygon = std::vector<Vec3>;

// Clips a convex polyhedron (faces as outward counter-clockwise polygons) by n.x <= h,
// Sutherland-Hodgman per face, closing the cut with a cap polygon ordered around n.
void clip(std::vector<Polygon>& faces, const Vec3& n, double h, double eps) {
  std::vector<Polygon> out;
  std::vector<Vec3> cap;
  for (const Polygon& f : faces) {
    Polygon g;
    for (std::size_t i = 0; i < f.size(); ++i) {
      const Vec3& a = f[i];
      const Vec3& b = f[(i + 1) % f.size()];
      const double sa = n.dot(a) - h, sb = n.dot(b) - h;
      const bool ina = sa <= eps, inb = sb <= eps;
      if (ina) {
        g.push_back(a);
        if (sa >= -eps) cap.push_back(a);
      }
      if (ina != inb) {
        const Vec3 x = a + (sa / (sa - sb)) * (b - a);
        g.push_back(x);
        cap.push_back(x);
      }
    }
    if (g.size() >= 3) out.push_back(std::move(g));
  }
  if (cap.size() >= 3) {
    Vec3 c = Vec3::Zero();
    for (const Vec3& p : cap) c += p;
    c /= static_cast<double>(cap.size());
    const Vec3 nn = n.normalized();
    const Vec3 u = (std::abs(nn.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(nn).normalized();
    const Vec3 w = nn.cross(u);
    std::sort(cap.begin(), cap.end(), [&](const Vec3& p, const Vec3& q) {
      return std::atan2((p - c).dot(w), (p - c).dot(u)) < std::atan2((q - c).dot(w), (q - c).dot(u));
    });
    out.push_back(std::move(cap));
  }
  faces = std::move(out);
}

void check_points(std::span<const Vec3> points) {
  if (points.empty()) throw InputError("dop: empty point set");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("dop: point " + std::to_string(i) + " has a non-finite coordinate (NaN or Inf)");
}

}  // namespace

int dop_axes(DopKind kind) {
  switch (kind) {
    case DopKind::diamond: return 4;
    case DopKind::dop14: return 7;
    case DopKind::dop18: return 9;
    case DopKind::dop26: return 13;
  }
  return 0;
}

Vec3 dop_direction(DopKind kind, int i) { return all_directions()[direction_index(kind, i)]; }

bool Dop::contains(const Vec3& p, double tolerance) const {
  for (int i = 0; i < axes(); ++i) {
    const Vec3 d = dop_direction(kind, i);
    const double s = project(d, p), t = tolerance * d.norm();
    if (s < min[i] - t || s > max[i] + t) return false;
  }
  return true;
}

double Dop::volume() const {
  const int k = axes();
  // Local origin: least-squares point of the slab mid-planes (precision under large offsets).
  Eigen::Matrix<double, Eigen::Dynamic, 3> a(k, 3);
  Eigen::VectorXd mid(k);
  for (int i = 0; i < k; ++i) {
    a.row(i) = dop_direction(kind, i).transpose();
    mid(i) = 0.5 * (min[i] + max[i]);
    if (!(min[i] <= max[i])) return 0.0;
  }
  const Vec3 o = (a.transpose() * a).partialPivLu().solve(a.transpose() * mid);
  std::vector<double> lo(k), hi(k);
  double m = 0.0;
  for (int i = 0; i < k; ++i) {
    const double s = dop_direction(kind, i).dot(o);
    lo[i] = min[i] - s, hi[i] = max[i] - s;
    m = std::max({m, std::abs(lo[i]), std::abs(hi[i])});
  }
  if (!(m > 0.0)) return 0.0;
  // Start from the cube [-m, m]^3 (every direction set spans R^3 with integer coefficients, so
  // the polytope lies inside), then clip by each half-space.
  const double e = 1.01 * m;
  std::vector<Polygon> faces;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {-1, 1}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Polygon f;
      for (auto [su, sv] : {std::pair{-1, -1}, std::pair{1, -1}, std::pair{1, 1}, std::pair{-1, 1}}) {
        Vec3 p;
        p[axis] = sign * e;
        p[u] = su * e;
        p[v] = sign * sv * e;  // counter-clockwise seen from outside
        f.push_back(p);
      }
      faces.push_back(f);
    }
  const double eps = 1e-13 * m;
  for (int i = 0; i < k && !faces.empty(); ++i) {
    const Vec3 d = dop_direction(kind, i);
    clip(faces, d, hi[i], eps * d.norm());
    clip(faces, -d, -lo[i], eps * d.norm());
  }
  double volume = 0.0;
  for (const Polygon& f : faces)
    for (std::size_t i = 1; i + 1 < f.size(); ++i) volume += f[0].dot(f[i].cross(f[i + 1]));
  return std::max(0.0, volume / 6.0);
}

Dop bounding_dop(std::span<const Vec3> points, DopKind kind) {
  check_points(points);
  Dop dop;
  dop.kind = kind;
  const int k = dop.axes();
  for (int i = 0; i < k; ++i) {
    const Vec3 d = dop_direction(kind, i);
    dop.min[i] = dop.max[i] = project(d, points[0]);
  }
  for (const Vec3& p : points)
    for (int i = 0; i < k; ++i) {
      const double s = project(dop_direction(kind, i), p);
      dop.min[i] = std::min(dop.min[i], s);
      dop.max[i] = std::max(dop.max[i], s);
    }
  return dop;
}

bool overlaps(const Dop& a, const Dop& b) {
  if (a.kind != b.kind) throw InputError("dop: overlaps needs two DOPs of the same kind");
  for (int i = 0; i < a.axes(); ++i)
    if (a.max[i] < b.min[i] || b.max[i] < a.min[i]) return false;
  return true;
}

}  // namespace tightbvh
