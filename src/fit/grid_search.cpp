// GridSearchMinVolBbx, Barequet & Har-Peled Section 6.4 (Fig. 6.3), with the local
// improvement step of Section 6.5 (the "(Improved)" rows of Tables 6.1 and 6.2) and a final
// tilt search of the best box's orientation (refine_direction).
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>

#include "fitters.hpp"
#include "grid_order.hpp"

#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#define TIGHTBVH_GRID_SSE2 1
#endif
#include "tightbvh/mesh.hpp"

namespace tightbvh::fit_detail {

constexpr int kMaxGrid = 64;

const std::vector<std::array<int, 3>>& primitive_grid(int k) {
  if (k < 1 || k > kMaxGrid) throw InputError("fit: grid radius k must be in [1, 64]");
  static std::array<std::once_flag, kMaxGrid + 1> once;
  static std::array<std::vector<std::array<int, 3>>, kMaxGrid + 1> tables;
  std::call_once(once[k], [k] {
    auto& t = tables[k];
    for (int i = -k; i <= k; ++i)
      for (int j = -k; j <= k; ++j)
        for (int l = -k; l <= k; ++l) {
          // One of v, -v: the first non-zero coordinate is positive.
          const int first = i != 0 ? i : (j != 0 ? j : l);
          if (first <= 0) continue;
          if (std::gcd(std::gcd(std::abs(i), std::abs(j)), std::abs(l)) != 1) continue;
          t.push_back({i, j, l});
        }
  });
  return tables[k];
}

VolumeBound::VolumeBound(const HullGeometry& g, const AxisBox& bstar) : g_(g) {
  std::array<Vec3, 6> extreme;
  for (int axis = 0; axis < 3; ++axis) {
    const Vec3 a = bstar.axes.col(axis);
    // The extremes' projections kept, not taken again at every comparison: the same values (a
    // product is rounded the same way every time), so the same points. Strict comparisons (the
    // first point reaching an extreme) as selects: as branches they would be mispredicted at random.
    double lo = a.dot(g.local[0]), hi = lo;
    std::size_t at_lo = 0, at_hi = 0;
    for (std::size_t i = 0; i < g.local.size(); ++i) {
      const double t = a.dot(g.local[i]);
      const bool below = t < lo, above = t > hi;
      lo = below ? t : lo, at_lo = below ? i : at_lo;
      hi = above ? t : hi, at_hi = above ? i : at_hi;
    }
    extreme[2 * axis] = g.local[at_lo];
    extreme[2 * axis + 1] = g.local[at_hi];
  }
  // Small sets repeat extreme points (a point extreme along two axes): their triangles are
  // degenerate or repeated, so only the distinct points span triangles (same bound, fewer terms).
  int distinct = 0;
  for (int i = 0; i < 6; ++i)
    if (std::find(extreme.begin(), extreme.begin() + distinct, extreme[i]) == extreme.begin() + distinct)
      extreme[distinct++] = extreme[i];
  for (int i = 0; i < distinct; ++i)
    for (int j = i + 1; j < distinct; ++j)
      for (int l = j + 1; l < distinct; ++l) normals_[count_++] = (extreme[j] - extreme[i]).cross(extreme[l] - extreme[i]);
  if (g.hull == nullptr) return;
  // The projected area of the hull is 1/4 sum_f |C_f . v| / |v| over its faces, C_f the cross
  // product of two edges (twice the area vector; each point of the projection is covered twice).
  // Up to kAreaGroups faces are kept one by one; more are summed per cell of a cube map of their
  // normals (6 x 3 x 3 cells: normals within ~40 degrees), where the loss of |sum| against the
  // sum of |.| is confined to the cells the silhouette crosses.
  const auto& faces = g.hull->faces;
  const auto cross = [&](const std::array<std::uint32_t, 3>& f) -> Vec3 {
    return 0.25 * (g.local[f[1]] - g.local[f[0]]).cross(g.local[f[2]] - g.local[f[0]]);
  };
  if (faces.size() <= static_cast<std::size_t>(kAreaGroups)) {
    for (const auto& f : faces) areas_[area_count_++] = cross(f);
    return;
  }
  constexpr int kCells = 54;
  static_assert(kCells <= kAreaGroups);
  for (int c = 0; c < kCells; ++c) areas_[c] = Vec3::Zero();
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const Vec3& n = g.hull->face_normals[f];
    int major = 0;
    n.cwiseAbs().maxCoeff(&major);
    const double m = std::abs(n[major]);
    const int side = 2 * major + (n[major] < 0.0 ? 1 : 0);
    const auto cell = [&](double t) { return std::clamp(static_cast<int>((t / m + 1.0) * 1.5), 0, 2); };
    areas_[9 * side + 3 * cell(n[(major + 1) % 3]) + cell(n[(major + 2) % 3])] += cross(faces[f]);
  }
  area_count_ = kCells;
}

double VolumeBound::cheap(const Vec3& v) const {
  const Extent along = extent_along(g_, v);
  return cheap(v, along.hi - along.lo);
}

double VolumeBound::cheap(const Vec3& v, double width) const {
  double projected = 0.0;
  for (int i = 0; i < count_; ++i) projected = std::max(projected, std::abs(normals_[i].dot(v)));
  return width * projected / v.squaredNorm();
}

void VolumeBound::cheap_lanes(const double* dx, const double* dy, const double* dz, const double* lo, const double* hi,
                              double* out, std::size_t lanes) const {
#ifdef TIGHTBVH_AVX_GRID_ORDER
  static const bool avx = has_avx_grid_order();
  if (avx && lanes % 4 == 0) return cheap_bounds_avx(normals_.front().data(), count_, dx, dy, dz, lo, hi, out, lanes);
#endif
#ifdef TIGHTBVH_GRID_SSE2
  const __m128d sign = _mm_set1_pd(-0.0);
  for (std::size_t i = 0; i < lanes; i += 2) {
    const __m128d ax = _mm_load_pd(dx + i), ay = _mm_load_pd(dy + i), az = _mm_load_pd(dz + i);
    __m128d projected = _mm_setzero_pd();
    for (int t = 0; t < count_; ++t) {
      const Vec3& n = normals_[t];
      const __m128d d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(ax, _mm_set1_pd(n.x())), _mm_mul_pd(ay, _mm_set1_pd(n.y()))),
                                   _mm_mul_pd(az, _mm_set1_pd(n.z())));
      projected = _mm_max_pd(projected, _mm_andnot_pd(sign, d));
    }
    const __m128d norm2 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(ax, ax), _mm_mul_pd(ay, ay)), _mm_mul_pd(az, az));
    const __m128d width = _mm_sub_pd(_mm_load_pd(hi + i), _mm_load_pd(lo + i));
    _mm_store_pd(out + i, _mm_div_pd(_mm_mul_pd(width, projected), norm2));
  }
#else
  for (std::size_t i = 0; i < lanes; ++i) out[i] = cheap(Vec3(dx[i], dy[i], dz[i]), hi[i] - lo[i]);
#endif
}

double VolumeBound::operator()(const Vec3& v) const {
  const Extent along = extent_along(g_, v);
  double projected = 0.0;
  for (int i = 0; i < count_; ++i) projected = std::max(projected, std::abs(normals_[i].dot(v)));
  // Four partial sums: independent additions (the compiler may not reassociate them).
  double area[4] = {0.0, 0.0, 0.0, 0.0};
  int i = 0;
#ifdef TIGHTBVH_GRID_SSE2
  // Partial sums 0, 1 in one register and 2, 3 in another: the same products, sums and order as
  // the scalar loop below, two groups per instruction (the area vectors are consecutive x, y, z).
  {
    const __m128d vx = _mm_set1_pd(v.x()), vy = _mm_set1_pd(v.y()), vz = _mm_set1_pd(v.z());
    const __m128d sign = _mm_set1_pd(-0.0);
    const auto two = [&](const double* p) {  // |a . v| of the area vectors at p and p + 3
      const __m128d a = _mm_loadu_pd(p), b = _mm_loadu_pd(p + 2), c = _mm_loadu_pd(p + 4);
      const __m128d x = _mm_shuffle_pd(a, b, 2), y = _mm_shuffle_pd(a, c, 1), z = _mm_shuffle_pd(b, c, 2);
      return _mm_andnot_pd(sign, _mm_add_pd(_mm_add_pd(_mm_mul_pd(x, vx), _mm_mul_pd(y, vy)), _mm_mul_pd(z, vz)));
    };
    __m128d sum01 = _mm_setzero_pd(), sum23 = _mm_setzero_pd();
    for (; i + 4 <= area_count_; i += 4) {
      sum01 = _mm_add_pd(sum01, two(areas_[i].data()));
      sum23 = _mm_add_pd(sum23, two(areas_[i + 2].data()));
    }
    _mm_storeu_pd(area, sum01);
    _mm_storeu_pd(area + 2, sum23);
  }
#endif
  for (; i + 4 <= area_count_; i += 4)
    for (int j = 0; j < 4; ++j) area[j] += std::abs(areas_[i + j].dot(v));
  for (; i < area_count_; ++i) area[0] += std::abs(areas_[i].dot(v));
  projected = std::max(projected, (area[0] + area[1]) + (area[2] + area[3]));
  return (along.hi - along.lo) * projected / v.squaredNorm();
}

bool VolumeBound::excludes(const Vec3& v, double volume) const {
  // The margin keeps rounding in the bound or in Bopt from skipping a direction that would win.
  return volume < std::numeric_limits<double>::infinity() && (*this)(v) * (1.0 - 1e-9) >= volume;
}

namespace {

// Tilt steps of refine_direction, in radians: 0.05, 0.025, 0.0125. Measured on the 133 corpus
// meshes against min(CGAL, exact): ending at 1e-3 instead costs a third more Bopt calls and
// changes no worst case (approx <= 1.0021 x either way); ending at 0.02 leaves 3torus at 1.006.
constexpr double kFirstTilt = 0.05;
constexpr double kLastTilt = 0.01;

// Pattern search (Hooke & Jeeves style) over the box's orientation: tilt each axis by +-theta
// towards each other axis and re-solve Bopt along the tilted axis; take the first smaller box
// (re-running the axis improvement from it), otherwise halve theta. The axis improvement of
// Section 6.5 stops wherever no single axis re-solve helps; on symmetric shapes that is a ridge
// 2% above the optimum (bull and 3torus of the CGAL corpus with k = 2), which small tilts escape.
// Tilting only the Bopt axis is cheaper but gets stuck on 3torus for some B*(S).
AxisBox refine_direction(const HullGeometry& g, AxisBox box, const VolumeBound& bound, BoptScratch& scratch) {
  double volume = box.volume();
  for (double theta = kFirstTilt; theta >= kLastTilt;) {
    const double c = std::cos(theta), s = std::sin(theta);
    bool moved = false;
    for (int axis = 0; axis < 3 && !moved; ++axis)
      for (int towards = 0; towards < 3 && !moved; ++towards) {
        if (towards == axis) continue;
        for (const double sign : {1.0, -1.0}) {
          const Vec3 v = c * box.axes.col(axis) + sign * s * box.axes.col(towards);
          if (bound.excludes(v, volume)) continue;
          const AxisBox candidate = bopt(g, v, scratch);
          if (candidate.volume() < volume) {
            box = improve(g, candidate, scratch, 1e-6, 16, true);
            volume = box.volume();
            moved = true;
            break;
          }
        }
      }
    if (!moved) theta *= 0.5;
  }
  return box;
}

}  // namespace

void projection_ranges(std::span<const Vec3> points, const double* dx, const double* dy, const double* dz, double* lo,
                       double* hi, std::size_t lanes) {
#ifdef TIGHTBVH_AVX_GRID_ORDER
  static const bool avx = has_avx_grid_order();
  if (avx) return projection_ranges_avx(points.front().data(), points.size(), dx, dy, dz, lo, hi, lanes);
#endif
#ifdef TIGHTBVH_GRID_SSE2
  for (std::size_t i = 0; i < lanes; i += 2) {
    const __m128d ax = _mm_loadu_pd(dx + i), ay = _mm_loadu_pd(dy + i), az = _mm_loadu_pd(dz + i);
    __m128d l = _mm_set1_pd(std::numeric_limits<double>::infinity()), h = _mm_set1_pd(-std::numeric_limits<double>::infinity());
    for (const Vec3& p : points) {
      const __m128d d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(ax, _mm_set1_pd(p.x())), _mm_mul_pd(ay, _mm_set1_pd(p.y()))),
                                   _mm_mul_pd(az, _mm_set1_pd(p.z())));
      l = _mm_min_pd(l, d);
      h = _mm_max_pd(h, d);
    }
    _mm_storeu_pd(lo + i, l);
    _mm_storeu_pd(hi + i, h);
  }
#else
  for (std::size_t i = 0; i < lanes; ++i) {
    lo[i] = std::numeric_limits<double>::infinity(), hi[i] = -lo[i];
    for (const Vec3& p : points) {
      const double d = (dx[i] * p.x() + dy[i] * p.y()) + dz[i] * p.z();
      lo[i] = std::min(lo[i], d), hi[i] = std::max(hi[i], d);
    }
  }
#endif
}

namespace {

// The kStarts smallest boxes of the grid scan, smallest first (B*(S) itself when nothing beats it).
constexpr int kStarts = 4;
struct TopBoxes {
  std::array<AxisBox, kStarts> box;
  std::array<double, kStarts> volume;
  std::array<bool, kStarts> from_bopt{};  // false for B*(S) itself (not a Bopt box)
};

// B*(S) alone, where every search starts.
TopBoxes only_bstar(const AxisBox& bstar) {
  TopBoxes top;
  top.box.fill(bstar);
  top.volume.fill(std::numeric_limits<double>::infinity());
  top.volume[0] = bstar.volume();
  return top;
}

// Inserts a Bopt box into the sorted list of the `kept` smallest when it is smaller than the last.
void keep_if_smaller(TopBoxes& top, int kept, const AxisBox& box) {
  const double volume = box.volume();
  if (!(volume < top.volume[kept - 1])) return;
  int at = kept - 1;
  while (at > 0 && volume < top.volume[at - 1]) {
    top.volume[at] = top.volume[at - 1];
    top.box[at] = top.box[at - 1];
    top.from_bopt[at] = top.from_bopt[at - 1];
    --at;
  }
  top.volume[at] = volume;
  top.box[at] = box;
  top.from_bopt[at] = true;
}

// The k = 2 grid's 49 directions, padded to whole AVX lanes (zero directions, never read).
constexpr std::size_t kWidthLanes = 52;

// Bopt(S, {v}) for the primitive directions v of Grid(B*(S)) with L-inf norm <= k, in increasing
// order of their volume bound (the best boxes come early, and once a bound reaches the kept-th
// best volume so do all later ones); keeps the `kept` (<= kStarts) smallest boxes.
TopBoxes scan_grid(const HullGeometry& g, const AxisBox& bstar, const VolumeBound& bound, int k, int kept,
                   BoptScratch& scratch) {
  // Grid(B*(S)) is spanned by the box's edge vectors b_j = extent_j * axis_j.
  const Vec3 extent = bstar.hi - bstar.lo;
  Mat3 basis;
  for (int j = 0; j < 3; ++j) basis.col(j) = extent[j] * bstar.axes.col(j);
  TopBoxes top = only_bstar(bstar);
  const auto& grid = primitive_grid(k);
  auto& order = scratch.grid_order;
  order.clear();
  if (grid.size() <= kWidthLanes) {
    // The widths along all directions in one pass over the points, four directions per AVX
    // instruction (grid_order.hpp) or two per SSE2 one: the same rounded projections as a scalar
    // loop (no FMA), so the same order.
    alignas(32) double dx[kWidthLanes] = {}, dy[kWidthLanes] = {}, dz[kWidthLanes] = {};
    alignas(32) double lo[kWidthLanes], hi[kWidthLanes];
    for (std::size_t i = 0; i < grid.size(); ++i) {
      const Vec3 v = basis * Vec3(grid[i][0], grid[i][1], grid[i][2]);
      dx[i] = v.x(), dy[i] = v.y(), dz[i] = v.z();
    }
    projection_ranges(g.local, dx, dy, dz, lo, hi, kWidthLanes);
    alignas(32) double lower[kWidthLanes];
    bound.cheap_lanes(dx, dy, dz, lo, hi, lower, kWidthLanes);
    // The directions in increasing order of (bound, index), as sorting the pairs below would, but
    // picked one at a time: the scan stops after a few of the 49 (a sort of all of them costs ~2% of
    // an approx tree build). Picked and zero directions get an infinite bound.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const std::size_t count = grid.size();
    for (std::size_t i = 0; i < count; ++i)
      if (!(Vec3(dx[i], dy[i], dz[i]).squaredNorm() > 0.0)) lower[i] = kInf;
    for (std::size_t i = count; i < kWidthLanes; ++i) lower[i] = kInf;
    for (;;) {
      std::size_t at = 0;
      double least = lower[0];
#ifdef TIGHTBVH_GRID_SSE2
      // The least bound two lanes at a time (min_pd(x, m) keeps m where x is NaN, as the scalar
      // loop skips it), then its first index, also two lanes at a time. A finite least is found
      // below `count` (the padding is infinite); otherwise `at` is not used (the scan stops).
      __m128d m = _mm_load_pd(lower);
      for (std::size_t i = 2; i < kWidthLanes; i += 2) m = _mm_min_pd(_mm_load_pd(lower + i), m);
      least = std::min(_mm_cvtsd_f64(m), _mm_cvtsd_f64(_mm_unpackhi_pd(m, m)));
      const __m128d wanted = _mm_set1_pd(least);
      for (std::size_t i = 0; i < kWidthLanes; i += 2)
        if (const int equal = _mm_movemask_pd(_mm_cmpeq_pd(_mm_load_pd(lower + i), wanted))) {
          at = i + (equal & 1 ? 0 : 1);
          break;
        }
#else
      for (std::size_t i = 1; i < count; ++i)
        if (lower[i] < least) least = lower[i], at = i;
#endif
      if (!(least < kInf) || least * (1.0 - 1e-9) >= top.volume[kept - 1]) break;
      lower[at] = kInf;
      const Vec3 v(dx[at], dy[at], dz[at]);
      // Without a hull the full bound is the cheap one, the same value as `least` (the same
      // operations on the same extent), so it cannot skip what the test above kept.
      if (g.hull != nullptr && bound.excludes(v, top.volume[kept - 1])) continue;
      keep_if_smaller(top, kept, bopt(g, v, scratch));
    }
    return top;
  } else {
    for (std::uint32_t i = 0; i < grid.size(); ++i) {
      const Vec3 v = basis * Vec3(grid[i][0], grid[i][1], grid[i][2]);
      if (v.squaredNorm() > 0.0) order.emplace_back(bound.cheap(v), i);
    }
  }
  std::sort(order.begin(), order.end());
  for (const auto& [lower, i] : order) {
    if (lower * (1.0 - 1e-9) >= top.volume[kept - 1]) break;
    const Vec3 v = basis * Vec3(grid[i][0], grid[i][1], grid[i][2]);
    // The full bound (with the hull's projected area) skips more, at the price of a pass over
    // the hull's faces: only for the directions the cheap bound cannot skip.
    if (bound.excludes(v, top.volume[kept - 1])) continue;
    keep_if_smaller(top, kept, bopt(g, v, scratch));
  }
  return top;
}

}  // namespace

int improvement_starts(std::size_t n, Extras extras) {
  if (extras == Extras::full) return kStarts;
  return n < kFourStartsFrom ? 1 : kStarts;
}

AxisBox grid_search(const HullGeometry& g, const AxisBox& bstar, int k, bool improve_step, BoptScratch& scratch,
                    std::span<const Vec3> seeds, bool scan, Extras extras) {
  // Keep the few best boxes: the local improvement is run from each of them (it converges to
  // local minima, Section 6.5, so a second or third start often lands in a better one). The scan
  // keeps only as many boxes as will be improved: the best box, which carries the guarantee of
  // Section 6.4, is the same, and fewer Bopt calls are needed to certify it.
  const VolumeBound bound(g, bstar);
  const int starts = improvement_starts(g.size(), extras);
  TopBoxes top = scan ? scan_grid(g, bstar, bound, k, starts, scratch) : only_bstar(bstar);
  for (const Vec3& v : seeds) keep_if_smaller(top, starts, bopt(g, v, scratch));
  if (!improve_step) return top.box[0];
  const double min_gain =
      extras == Extras::by_size && g.size() < kFineImprovementFrom ? kCoarseImprovementGain : 1e-6;
  AxisBox best = top.box[0];
  double best_volume = top.volume[0];
  for (int i = 0; i < starts; ++i) {
    if (!(top.volume[i] < std::numeric_limits<double>::infinity())) break;
    const AxisBox improved = improve(g, top.box[i], scratch, min_gain, 16, top.from_bopt[i]);
    if (improved.volume() < best_volume) best_volume = improved.volume(), best = improved;
  }
  if (extras == Extras::by_size && g.size() < kTiltFrom) return best;
  return refine_direction(g, best, bound, scratch);
}

AxisBox quick_grid_search(const HullGeometry& g, const AxisBox& bstar, int k, BoptScratch& scratch,
                          std::span<const Vec3> seeds, bool scan) {
  TopBoxes top = scan ? scan_grid(g, bstar, VolumeBound(g, bstar), k, 1, scratch) : only_bstar(bstar);
  for (const Vec3& v : seeds) keep_if_smaller(top, 1, bopt(g, v, scratch));
  return improve(g, top.box[0], scratch, 1e-3, 4, top.from_bopt[0]);
}

}  // namespace tightbvh::fit_detail
