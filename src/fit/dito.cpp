// DiTO-14, the ditetrahedron OBB of Larsson & Källberg ("Fast Computation of Tight-Fitting
// Oriented Bounding Boxes", Game Engine Gems 2, 2011): O(n) and no hull. The extreme points along
// 7 fixed directions (the 3 coordinate axes and the 4 cube diagonals) give a large base triangle
// (the farthest pair of extremes, then the extreme farthest from their line); the points farthest
// above and below its plane make it a ditetrahedron. Each of its (up to 7) faces offers 3 frames:
// one axis along a face edge, one along the face normal. Every frame is scored on a small point
// set and the best one is kept; the extents are measured over all points.
//
// Two departures from the chapter, both for this library's objective: the score is the box
// volume (the chapter uses the surface area, a steadier measure on its few sample points) with
// the area breaking the ties between flat boxes, and sets of at most kDitoScoreAllMax points score
// every frame on all their points, not on the extremes only (the same cost on such sets).
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include "dito.hpp"
#include "frame.hpp"

namespace tightbvh::fit_detail {

namespace {

// The 7 directions of DiTO-14 (unnormalised: only the order of projections along each matters).
constexpr std::array<std::array<double, 3>, 7> kDirections = {{
    {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {1, -1, -1}}};

// The frame with its first axis along `edge` and its third along `normal` (made orthogonal to
// the edge), right-handed.
Mat3 frame_from_edge(const Vec3& edge, const Vec3& normal) {
  Mat3 frame;
  const Vec3 u = edge.normalized();
  const Vec3 w = (normal - normal.dot(u) * u).normalized();
  frame.col(0) = u;
  frame.col(1) = w.cross(u);
  frame.col(2) = w;
  return frame;
}

// The size of the box of `points` (relative to the origin) in `frame`, as smaller_box measures it
// (volume, and area between flat boxes), `length` the set's scale (the same for every frame).
double score(std::span<const Vec3> points, const Mat3& frame, double length) {
  const Mat3 rt = frame.transpose();
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : points) {
    const Vec3 q = rt * p;
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  return box_size_score(hi - lo, length);
}

}  // namespace

Obb dito_box(std::span<const Vec3> points) {
  // Relative to a point of the set, so that a set far from the origin keeps its precision.
  const Vec3 origin = points.front();
  std::array<double, 7> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  std::array<std::size_t, 7> at_lo{}, at_hi{};
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 p = points[i] - origin;
    for (std::size_t k = 0; k < kDirections.size(); ++k) {
      const double t = kDirections[k][0] * p.x() + kDirections[k][1] * p.y() + kDirections[k][2] * p.z();
      if (t < lo[k]) lo[k] = t, at_lo[k] = i;
      if (t > hi[k]) hi[k] = t, at_hi[k] = i;
    }
  }
  // The 14 extremes (min and max along each direction), then the two apexes.
  std::array<Vec3, 16> sample;
  for (std::size_t k = 0; k < kDirections.size(); ++k) {
    sample[2 * k] = points[at_lo[k]] - origin;
    sample[2 * k + 1] = points[at_hi[k]] - origin;
  }
  // Base triangle: the farthest pair of extremes, then the extreme farthest from their line.
  std::size_t far = 0;
  double far_d2 = -1.0;
  for (std::size_t k = 0; k < kDirections.size(); ++k) {
    const double d2 = (sample[2 * k + 1] - sample[2 * k]).squaredNorm();
    if (d2 > far_d2) far_d2 = d2, far = k;
  }
  const Vec3 p0 = sample[2 * far], p1 = sample[2 * far + 1];
  const Vec3 e0 = p1 - p0;
  if (!(far_d2 > 0.0)) return box_with_axes(points, Mat3::Identity(), origin);  // one point
  Vec3 p2 = p0;
  double off_d2 = 0.0;
  for (std::size_t s = 0; s < 14; ++s) {
    const double d2 = e0.cross(sample[s] - p0).squaredNorm();
    if (d2 > off_d2) off_d2 = d2, p2 = sample[s];
  }
  if (!(off_d2 > 0.0)) {
    // The extremes are collinear (a thin set, e.g. a sliver triangle whose middle vertex is
    // extreme along none of the 7 directions): the farthest of all points from their line.
    for (const Vec3& point : points) {
      const Vec3 p = point - origin;
      const double d2 = e0.cross(p - p0).squaredNorm();
      if (d2 > off_d2) off_d2 = d2, p2 = p;
    }
    if (!(off_d2 > 0.0)) return box_with_axes(points, frame_from_axis(e0), origin);  // collinear set
  }
  const Vec3 normal = e0.cross(p2 - p0);
  // The apexes: the points farthest above and below the base plane (over all points: one pass).
  double top = -std::numeric_limits<double>::infinity(), bottom = -top;
  Vec3 q_top = p0, q_bottom = p0;
  for (const Vec3& point : points) {
    const Vec3 p = point - origin;
    const double t = normal.dot(p);
    if (t > top) top = t, q_top = p;
    if (t < bottom) bottom = t, q_bottom = p;
  }
  sample[14] = q_top;
  sample[15] = q_bottom;

  // Candidate frames from the ditetrahedron's faces, scored on the sample (or on all points of a
  // small set, relative to the origin as well).
  std::array<Vec3, kDitoScoreAllMax> small;
  std::span<const Vec3> scored(sample.data(), sample.size());
  if (points.size() <= kDitoScoreAllMax) {
    for (std::size_t i = 0; i < points.size(); ++i) small[i] = points[i] - origin;
    scored = std::span<const Vec3>(small.data(), points.size());
  }
  const double length = std::sqrt(far_d2);
  double best = std::numeric_limits<double>::infinity();
  Mat3 best_frame = Mat3::Identity();
  const auto try_face = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = (b - a).cross(c - a);
    if (!(n.squaredNorm() > 0.0)) return;
    for (const Vec3& edge : {Vec3(b - a), Vec3(c - b), Vec3(a - c)}) {
      const Mat3 frame = frame_from_edge(edge, n);
      if (const double s = score(scored, frame, length); s < best) best = s, best_frame = frame;
    }
  };
  try_face(p0, p1, p2);
  const double base = normal.dot(p0);
  for (const auto& [apex, beyond] : {std::pair{q_top, top > base}, std::pair{q_bottom, bottom < base}}) {
    if (!beyond) continue;
    try_face(apex, p0, p1);
    try_face(apex, p1, p2);
    try_face(apex, p2, p0);
  }
  return box_with_axes(points, orthonormalize(best_frame), origin);
}

}  // namespace tightbvh::fit_detail
