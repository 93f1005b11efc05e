#include "tightbvh/fit.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <cmath>
#include <string>

#include "fitters.hpp"
#include "dito.hpp"
#include "frame.hpp"
#include "kernel_extremes.hpp"
#include "pca.hpp"
#include "tightbvh/hull.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/min_rect.hpp"
#include "../name_table.hpp"
#include "workspace.hpp"

#if defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2)
#include <emmintrin.h>
#define TIGHTBVH_FIT_SSE2 1
#endif

namespace tightbvh {
namespace {

constexpr detail::NameTable<FitMethod, 11> kNames({{
    {FitMethod::aabb, "aabb"},
    {FitMethod::pca, "pca"},
    {FitMethod::pca_vertex, "pca-vertex"},
    {FitMethod::diameter, "diameter"},
    {FitMethod::approx, "approx"},
    {FitMethod::approx_snap, "approx-snap"},
    {FitMethod::exact, "exact"},
    {FitMethod::eberly2015, "eberly2015"},
    {FitMethod::approx_kernel, "approx-kernel"},
    {FitMethod::normal_bopt, "normal-bopt"},
    {FitMethod::dito, "dito"},
}});

// approx-snap's default epsilon when none is given.
constexpr double kDefaultSnapEpsilon = 0.1;

void check_finite(std::span<const Vec3> points) {
  if (points.empty()) throw InputError("fit: empty point set");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("fit: point " + std::to_string(i) + " is not finite (NaN or Inf coordinate)");
}

// Planar, collinear and single-point sets: a zero-volume box (the thickness is whatever the
// points have), with the minimum-area rectangle in the plane for planar sets.
Mat3 degenerate_axes(const ConvexHull3& hull, std::vector<Vec2>& polygon, std::vector<Vec2>& chain) {
  if (hull.dimension <= 0 || hull.vertices.size() < 2) return Mat3::Identity();
  if (hull.dimension == 1) return fit_detail::frame_from_axis(hull.vertices[1] - hull.vertices[0]);
  const Mat3 frame = fit_detail::frame_from_axis(hull.plane_normal);
  const Vec3 u = frame.col(1), w = frame.col(2);
  polygon.clear();
  for (const Vec3& p : hull.vertices) polygon.emplace_back(u.dot(p - hull.vertices[0]), w.dot(p - hull.vertices[0]));
  const std::size_t m = convex_hull_2d(polygon, chain);
  const Rect2 rect = min_area_rect(std::span<const Vec2>(polygon.data(), m));
  Mat3 axes;
  axes.col(0) = rect.axis.x() * u + rect.axis.y() * w;
  axes.col(1) = -rect.axis.y() * u + rect.axis.x() * w;
  axes.col(2) = frame.col(0);
  return fit_detail::orthonormalize(axes);
}

// Sets with at most this many distinct points skip the 3D hull in `approx` and `diameter`:
// Bopt projects all points instead of the hull's silhouette (same boxes). The hull costs ~1 us
// for 10 points and ~3 us for 30, so `diameter` (one Bopt) still gains from skipping it up to 32
// points, `approx` (dozens of Bopt calls, cheaper on the silhouette) only up to 24. Measured on
// approx tree builds, where nodes below 64 points take a single improvement start
// (Extras::by_size) and so leave fewer Bopt calls to pay for a hull: 24 takes 0.6-1.5% fewer
// instructions than 16 (knot1, camel, elephant; 32 gains no more on elephant), with the same
// trees' sums of volumes.
constexpr std::size_t kSmallSetApprox = 24;
constexpr std::size_t kSmallSetDiameter = 32;

// Sorts the points (lexicographically) and drops repeated ones.
void sort_unique(std::vector<Vec3>& points) {
  const auto less = [](const Vec3& a, const Vec3& b) {
    return a.x() < b.x() || (a.x() == b.x() && (a.y() < b.y() || (a.y() == b.y() && a.z() < b.z())));
  };
  std::sort(points.begin(), points.end(), less);
  points.erase(std::unique(points.begin(), points.end()), points.end());
}

// The distinct points of a small set (sorted), or false when there are more than `limit`.
bool distinct_small(std::span<const Vec3> points, std::size_t limit, std::vector<Vec3>& out) {
  if (points.size() > 4 * limit) return false;
  out.assign(points.begin(), points.end());
  sort_unique(out);
  return out.size() <= limit;
}

// pca / pca-vertex: one pass for the moments, one for the extents, relative to the first point
// (near the set, so far-away sets keep their precision). The finiteness check rides on the
// extents pass: only when something is not finite is the input scanned for the bad point.
Obb fit_checked(std::span<const Vec3> points, const FitOptions& options, FitWorkspace& workspace,
                std::span<const Vec3> seeds = {}, fit_detail::Extras extras = fit_detail::Extras::full);

// `given`: the PCA axes when the caller already has them (a tree node's, from its moments).
Obb fit_pca(std::span<const Vec3> points, std::span<const Vec3> triangle_corners, const Mat3* given = nullptr) {
  using namespace fit_detail;
  if (points.empty()) throw InputError("fit: empty point set");
  const Vec3 origin = points[0];
  if (!origin.allFinite()) check_finite(points);
  const Mat3 axes = given                     ? *given
                    : triangle_corners.empty() ? pca_vertex_axes(points, origin)
                                               : pca_triangle_axes(triangle_corners, origin);
  bool finite = true;
  const Obb box = box_with_axes(points, axes, origin, finite);
  if (!finite) check_finite(points);  // throws on NaN/Inf input; an overflow keeps the box
  return box;
}

// approx-kernel: an epsilon-kernel in miniature (Agarwal, Har-Peled & Varadarajan 2004,
// "Approximating extent measures of points"; Barequet & Har-Peled Section 6.3 snap to a grid for
// the same purpose). The extreme points of the set along the 49 primitive directions of the k = 2
// grid, taken in the PCA box's frame scaled by its extents (the affine map that makes the set
// fat, as the kernel construction prescribes), keep the set's width in every direction to within
// a few percent. approx's grid scan and a short axis improvement (quick_grid_search) then run on
// those <= 98 points, and the extents are taken over the whole set, so the box contains it.
// O(n): one pass for the covariance, one for the extremes, one for the extents; the PCA box is
// kept when smaller. In the `auto` tree fitter (nodes of 64-2047 triangles) it keeps ~90% of
// approx's volume gain over pca at ~3x pca's build time
// (docs/design-notes/auto-fitter.md, "Spend the search where the volume is"). A k = 3 kernel (145
// directions) or approx's full search on the kernel (restarts, tilts) cost 15-30% more build time
// for +-2% of gain (measured with tightbvh-build-bench; a tree's topology moves with its boxes, so
// it goes either way).
constexpr int kKernelGrid = 2;
// Sets of at least this many points (tree nodes of ~512 triangles and more, which hold most of a
// tree's volume) scan the k = 2 grid on the kernel's hull; smaller ones the k = 1 grid on the
// kernel's points themselves.
constexpr std::size_t kKernelLargeSet = 256;

}  // namespace

namespace fit_detail {

void kernel_extremes_sse2(const double* xyz, std::size_t n, const double (&center_xyz)[3], const KernelDirections& d,
                          KernelExtremes& out) {
  constexpr std::size_t kPadded = kKernelLanes;
  const double* const dx = d.x;
  const double* const dy = d.y;
  const double* const dz = d.z;
  double* const lo = out.lo;
  double* const hi = out.hi;
  double* const at_lo = out.at_lo;
  double* const at_hi = out.at_hi;
  const Vec3 center(center_xyz[0], center_xyz[1], center_xyz[2]);
  const auto point = [&](std::size_t p) { return Vec3(xyz[3 * p], xyz[3 * p + 1], xyz[3 * p + 2]); };
  std::fill(lo, lo + kPadded, std::numeric_limits<double>::infinity());
  std::fill(hi, hi + kPadded, -std::numeric_limits<double>::infinity());
  std::fill(at_lo, at_lo + kPadded, 0.0);
  std::fill(at_hi, at_hi + kPadded, 0.0);
#ifdef TIGHTBVH_FIT_SSE2
  // Blocks of kBlock points: the block's extremes by min/max (two directions per instruction, no
  // index to carry), then, only for the directions where the block beats the running extreme
  // (after the first blocks: rarely, so the branch is predictable), the first point of the block
  // reaching it, found by computing its projection again (the same operations, so the same
  // value). The same extremes and points as a point-by-point scan with strict comparisons (the
  // first point that reaches an extreme), at ~45% fewer instructions: the index selects of that
  // scan cost as much as the projections.
  constexpr std::size_t kBlock = 8;
  const auto projection = [&](std::size_t p, std::size_t i) {
    const Vec3 q = point(p) - center;
    return _mm_add_pd(_mm_add_pd(_mm_mul_pd(_mm_load_pd(&dx[i]), _mm_set1_pd(q.x())), _mm_mul_pd(_mm_load_pd(&dy[i]), _mm_set1_pd(q.y()))),
                      _mm_mul_pd(_mm_load_pd(&dz[i]), _mm_set1_pd(q.z())));
  };
  // The first point of [begin, end) whose projection on direction i + j is `value`.
  const auto first_reaching = [&](std::size_t begin, std::size_t end, std::size_t i, std::size_t j, double value) {
    std::size_t p = begin;
    for (; p + 1 < end; ++p) {
      alignas(16) double d[2];
      _mm_store_pd(d, projection(p, i));
      if (d[j] == value) break;
    }
    return p;
  };
  __m128d qx[kBlock], qy[kBlock], qz[kBlock];  // the block's points relative to the center, broadcast
  for (std::size_t b = 0; b < n; b += kBlock) {
    const std::size_t b_end = std::min(n, b + kBlock);
    const std::size_t count = b_end - b;
    for (std::size_t k = 0; k < count; ++k) {
      const Vec3 q = point(b + k) - center;
      qx[k] = _mm_set1_pd(q.x()), qy[k] = _mm_set1_pd(q.y()), qz[k] = _mm_set1_pd(q.z());
    }
    // Direction pair by direction pair, so that the pair and its block extremes stay in registers.
    for (std::size_t i = 0; i < kPadded; i += 2) {
      const __m128d ax = _mm_load_pd(&dx[i]), ay = _mm_load_pd(&dy[i]), az = _mm_load_pd(&dz[i]);
      __m128d block_lo = _mm_set1_pd(std::numeric_limits<double>::infinity());
      __m128d block_hi = _mm_set1_pd(-std::numeric_limits<double>::infinity());
      for (std::size_t k = 0; k < count; ++k) {
        const __m128d d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(ax, qx[k]), _mm_mul_pd(ay, qy[k])), _mm_mul_pd(az, qz[k]));
        block_lo = _mm_min_pd(block_lo, d);
        block_hi = _mm_max_pd(block_hi, d);
      }
      const int below = _mm_movemask_pd(_mm_cmplt_pd(block_lo, _mm_load_pd(&lo[i])));
      const int above = _mm_movemask_pd(_mm_cmpgt_pd(block_hi, _mm_load_pd(&hi[i])));
      if ((below | above) == 0) continue;
      alignas(16) double block_lo_at[2], block_hi_at[2];
      _mm_store_pd(block_lo_at, block_lo);
      _mm_store_pd(block_hi_at, block_hi);
      for (std::size_t j = 0; j < 2; ++j) {
        if (below & (1 << j)) {
          lo[i + j] = block_lo_at[j];
          at_lo[i + j] = static_cast<double>(first_reaching(b, b_end, i, j, lo[i + j]));
        }
        if (above & (1 << j)) {
          hi[i + j] = block_hi_at[j];
          at_hi[i + j] = static_cast<double>(first_reaching(b, b_end, i, j, hi[i + j]));
        }
      }
    }
  }
#else
  for (std::size_t p = 0; p < n; ++p) {
    const Vec3 q = point(p) - center;
    const double index = static_cast<double>(p);
    for (std::size_t i = 0; i < kPadded; ++i) {
      const double d = dx[i] * q.x() + dy[i] * q.y() + dz[i] * q.z();
      if (d < lo[i]) lo[i] = d, at_lo[i] = index;
      if (d > hi[i]) hi[i] = d, at_hi[i] = index;
    }
  }
#endif
}

}  // namespace fit_detail

namespace {

// The kernel's points (distinct, sorted) into `out`.
void extreme_point_kernel(std::span<const Vec3> points, const Obb& frame, std::vector<Vec3>& out) {
  const auto& grid = fit_detail::primitive_grid(kKernelGrid);
  constexpr std::size_t kMax = 49;
  const std::size_t count = std::min(grid.size(), kMax);
  const double largest = frame.half_extents.maxCoeff();
  const Vec3 scale = frame.half_extents.cwiseMax(1e-9 * largest).cwiseInverse();
  // The grid vectors of the unit cube mapped back to the set, one array per coordinate (padded
  // to whole lanes with zero vectors, whose extremes are never read).
  constexpr std::size_t kPadded = fit_detail::kKernelLanes;
  static_assert(kPadded >= kMax && kPadded % 4 == 0);
  fit_detail::KernelDirections directions{};
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3 d = frame.axes * Vec3(grid[i][0] * scale.x(), grid[i][1] * scale.y(), grid[i][2] * scale.z());
    directions.x[i] = d.x(), directions.y[i] = d.y(), directions.z[i] = d.z();
  }
  // The extreme values and the points reaching them (indices as doubles: exact below 2^53, and
  // one select serves both). Strict comparisons keep the first point that reaches an extreme.
  fit_detail::KernelExtremes extremes;
  const double* const at_lo = extremes.at_lo;
  const double* const at_hi = extremes.at_hi;
  const double center[3] = {frame.center.x(), frame.center.y(), frame.center.z()};
  if (fit_detail::has_avx_kernel()) {
    fit_detail::kernel_extremes_avx(points.front().data(), points.size(), center, directions, extremes);
  } else {
    fit_detail::kernel_extremes_sse2(points.front().data(), points.size(), center, directions, extremes);
  }
  // Many directions share an extreme point: drop repeated indices first (cheap integer sort), so
  // that only the distinct points are sorted (the same result as sorting all 98).
  std::array<std::size_t, 2 * kMax> at;
  for (std::size_t i = 0; i < count; ++i) {
    at[i] = static_cast<std::size_t>(at_lo[i]);
    at[count + i] = static_cast<std::size_t>(at_hi[i]);
  }
  std::sort(at.begin(), at.begin() + 2 * count);
  const auto end = std::unique(at.begin(), at.begin() + 2 * count);
  out.clear();
  for (auto i = at.begin(); i != end; ++i) out.push_back(points[*i]);
  sort_unique(out);
}

Obb fit_kernel(std::span<const Vec3> points, std::span<const Vec3> triangle_corners, FitWorkspace& workspace,
               const Mat3* pca_axes = nullptr, const Mat3* parent_axes = nullptr) {
  using namespace fit_detail;
  FitOptions approx;  // flat or collinear kernels: approx on the whole set handles them
  approx.method = FitMethod::approx;
  const Obb pca = fit_pca(points, triangle_corners, pca_axes);  // throws on NaN/Inf
  auto& s = workspace.scratch();
  const bool large = points.size() >= kKernelLargeSet;
  extreme_point_kernel(points, pca, s.distinct);
  s.last_hull_vertices = s.distinct.size();
  const Vec3 origin = pca.center;
  if (affine_dimension(s.distinct).dimension < 3) return fit_checked(points, approx, workspace);
  AxisBox best;
  // Below the root of an `auto` tree: Bopt along the parent's axes and along the node's own PCA
  // axes instead of the grid scan. The parent's frame suits most children; the PCA axes (already
  // computed above) rescue the nodes it does not suit, for 3 more Bopt calls: a closer share of
  // approx's gain and fewer box tests in separated poses (docs/design-notes/auto-fitter.md,
  // "Search from the parent's box").
  std::array<Vec3, 6> seed_store;
  if (parent_axes != nullptr)
    for (int j = 0; j < 3; ++j) seed_store[j] = parent_axes->col(j), seed_store[3 + j] = pca.axes.col(j);
  const std::span<const Vec3> seeds(seed_store.data(), parent_axes != nullptr ? seed_store.size() : 0);
  const bool scan = parent_axes == nullptr;
  if (large) {
    convex_hull(s.distinct, s.hull, s.hull_workspace);
    s.geometry.reset(s.hull, origin);
    s.last_hull_vertices = s.hull.vertices.size();
    best = quick_grid_search(s.geometry, lemma_box(s.geometry, s.bopt), 2, s.bopt, seeds, scan);
  } else {
    // No hull: Bopt projects every kernel point (a few dozen), cheaper than hulling them first
    // for the ~15 Bopt calls of the quick search.
    s.geometry.reset_points(s.distinct, origin);
    best = quick_grid_search(s.geometry, lemma_box(s.geometry, s.bopt), 1, s.bopt, seeds, scan);
  }
  const Obb box = box_with_axes(points, orthonormalize(best.axes), origin);
  return smaller_box(box, pca) ? box : pca;
}

// normal-bopt's candidate directions: the triangles' area-weighted normal and the normals of up to
// kTriangleNormals of the triangles themselves (every ceil(T / kTriangleNormals)-th of T).
constexpr std::size_t kTriangleNormals = 31;
constexpr std::size_t kNormalLanes = 32;  // 1 + kTriangleNormals, a whole number of AVX lanes
static_assert(kNormalLanes >= 1 + kTriangleNormals && kNormalLanes % 4 == 0);

// The triangles' area-weighted normal (summed over all of them) or one of the candidates' own
// normals, whichever the points are thinnest across (width (max - min of d . p) / |d|; the first
// on ties; zero and non-finite candidates never win; the summed normal when none qualifies). A
// curved or folded patch is often thinner across one of its own triangles' planes than across its
// mean plane, and the minimum box of a patch is nearly flush with it
// (docs/design-notes/auto-fitter.md, "Small nodes: one Bopt along the thinnest normal"). One
// projection pass over the points for all candidates (four per AVX instruction).
Vec3 thinnest_normal(std::span<const Vec3> points, std::span<const Vec3> triangle_corners) {
  alignas(32) std::array<double, kNormalLanes> dx, dy, dz, lo, hi;
  const std::size_t triangles = triangle_corners.size() / 3;
  const std::size_t stride = (triangles + kTriangleNormals - 1) / kTriangleNormals;
  Vec3 summed = Vec3::Zero();
  std::size_t count = 1;  // slot 0: the summed normal
  for (std::size_t t = 0, next = 0; t < triangles; ++t) {
    const Vec3* c = &triangle_corners[3 * t];
    const Vec3 n = (c[1] - c[0]).cross(c[2] - c[0]);  // edges: no origin to lose precision to
    summed += n;
    if (t != next) continue;
    dx[count] = n.x(), dy[count] = n.y(), dz[count] = n.z(), ++count;
    next += stride;
  }
  dx[0] = summed.x(), dy[0] = summed.y(), dz[0] = summed.z();
  const std::size_t lanes = (count + 3) / 4 * 4;
  for (std::size_t i = count; i < lanes; ++i) dx[i] = dy[i] = dz[i] = 0.0;
  fit_detail::projection_ranges(points, dx.data(), dy.data(), dz.data(), lo.data(), hi.data(), lanes);
  std::size_t best = 0;
  double least = std::numeric_limits<double>::infinity();  // of width^2
  for (std::size_t i = 0; i < count; ++i) {
    const double norm2 = (dx[i] * dx[i] + dy[i] * dy[i]) + dz[i] * dz[i];
    const double width2 = (hi[i] - lo[i]) * (hi[i] - lo[i]) / norm2;  // NaN (never less) for 0 or overflow
    if (width2 < least) least = width2, best = i;
  }
  return {dx[best], dy[best], dz[best]};
}

// normal-bopt: Bopt(S, {n}) of Barequet & Har-Peled (Section 6.3) for one direction n: of the
// triangles' area-weighted normal and their own normals (thinnest_normal), the one across which
// the set is thinnest (without triangles: the PCA box's thinnest axis, the normal of the
// best-fitting plane): the box with an axis along n and the minimum-area rectangle (rotating
// calipers) of the set projected onto the plane orthogonal to it. For the small nodes of a tree,
// which are patches of the surface, the minimum box is nearly flush with the patch, so this one
// direction does much of what approx's scan of dozens does, at the cost of one projection pass for
// the candidates, one for Bopt and a 2D hull. In `auto` (nodes of 2-63 triangles) boxes flush with
// a patch are thin where the other mesh's surface comes close, so they cull better in queries than
// their volume says (docs/design-notes/auto-fitter.md,
// "Small nodes: one Bopt along the thinnest normal"). The PCA box is kept when smaller (a patch
// that folds over, a normal that sums to nothing). With `fallback_axes` (auto below the root: the
// parent box's axes) the box along those is the fallback instead, and no PCA is computed.
Obb fit_normal_bopt(std::span<const Vec3> points, std::span<const Vec3> triangle_corners, FitWorkspace& workspace,
                    const Mat3* pca_axes = nullptr, const Mat3* fallback_axes = nullptr) {
  using namespace fit_detail;
  // Throws on empty or NaN/Inf input.
  const Obb pca = fit_pca(points, triangle_corners, fallback_axes != nullptr ? fallback_axes : pca_axes);
  Vec3 normal = Vec3::Zero();
  if (triangle_corners.empty()) {
    Eigen::Index thinnest = 0;
    pca.half_extents.minCoeff(&thinnest);
    normal = pca.axes.col(thinnest);
  } else {
    normal = thinnest_normal(points, triangle_corners);
  }
  if (!(normal.squaredNorm() > 0.0) || !normal.allFinite()) return pca;
  auto& s = workspace.scratch();
  s.last_hull_vertices = 0;
  ++s.bopt.calls;
  // No 3D hull: the 2D hull of the projection suffices (and no copy of the points either).
  const AxisBox best = bopt_of_points(points, pca.center, normal, s.bopt);
  // Bopt projected every point: its extents are the set's in its frame (orthonormal to rounding),
  // so no second pass over the points measures them again.
  Obb box;
  box.axes = best.axes;
  box.half_extents = 0.5 * (best.hi - best.lo);
  box.center = pca.center + best.axes * (0.5 * (best.hi + best.lo));
  return smaller_box(box, pca) ? box : pca;
}

// Every method but pca and pca-vertex (fit_points and fit_triangles send those to fit_pca), on
// finite points.
Obb fit_checked(std::span<const Vec3> points, const FitOptions& options, FitWorkspace& workspace,
                std::span<const Vec3> seeds, fit_detail::Extras extras) {
  using namespace fit_detail;
  auto& s = workspace.scratch();
  s.last_hull_vertices = 0;
  if (options.method == FitMethod::aabb) return to_obb(bounds_of(points));
  if (options.method == FitMethod::dito) return dito_box(points);  // no hull
  const Vec3 origin = local_origin(points);
  // Hull-based methods.
  if ((options.method == FitMethod::approx || options.method == FitMethod::diameter) &&
      distinct_small(points, options.method == FitMethod::approx ? kSmallSetApprox : kSmallSetDiameter, s.distinct) &&
      affine_dimension(s.distinct).dimension == 3) {  // the hull's own classification: they agree
    s.geometry.reset_points(s.distinct, origin);  // no hull: Bopt projects every point
    s.last_hull_vertices = s.distinct.size();
  } else {
    convex_hull(points, s.hull, s.hull_workspace);
    s.last_hull_vertices = s.hull.vertices.size();
    if (s.hull.dimension < 3) return box_with_axes(points, degenerate_axes(s.hull, s.polygon, s.bopt.chain), origin);
    s.geometry.reset(s.hull, origin);
  }
  Mat3 axes;
  switch (options.method) {
    case FitMethod::diameter:
      axes = diameter_box(s.geometry, s.bopt).axes;
      break;
    case FitMethod::approx: {
      const int k = options.epsilon ? grid_for_epsilon(*options.epsilon) : options.grid;
      axes = grid_search(s.geometry, lemma_box(s.geometry, s.bopt), k, options.improve, s.bopt, seeds, seeds.empty(),
                         extras)
                 .axes;
      break;
    }
    case FitMethod::approx_snap:
      axes = fit_detail::snap_axes(s, options.epsilon.value_or(kDefaultSnapEpsilon));
      break;
    case FitMethod::exact:
      axes = exact_box(s.geometry, s.exact, s.bopt).axes;
      break;
    case FitMethod::eberly2015:
      axes = eberly2015_box(s.geometry, s.eberly2015, s.bopt).axes;
      break;
    default:
      throw std::logic_error("fit: unknown method");
  }
  return box_with_axes(points, orthonormalize(axes), origin);
}

}  // namespace

namespace fit_detail {

bool uses_pca_axes(FitMethod method) {
  return method == FitMethod::approx_kernel || method == FitMethod::normal_bopt;
}

Obb fit_triangles_with_pca_axes(std::span<const Vec3> corners, std::span<const Vec3> vertices,
                                const FitOptions& options, FitWorkspace& workspace, const Mat3* pca_axes,
                                const Mat3* parent_axes) {
  if (corners.size() % 3 != 0) throw InputError("fit: triangle corners must come in threes");
  if (corners.empty() != vertices.empty()) throw InputError("fit: corners and vertices must be the same point set");
  switch (options.method) {
    case FitMethod::approx_kernel:
      return fit_kernel(vertices, corners, workspace, pca_axes, parent_axes);
    case FitMethod::normal_bopt:
      return fit_normal_bopt(vertices, corners, workspace, pca_axes, parent_axes);
    case FitMethod::approx:
      if (parent_axes != nullptr) {
        // approx's improvement and tilt search from the best Bopt box along the parent's axes,
        // without the grid scan (auto below the root).
        check_finite(vertices);
        const std::array<Vec3, 3> seeds = {parent_axes->col(0), parent_axes->col(1), parent_axes->col(2)};
        return fit_checked(vertices, options, workspace, seeds);
      }
      return fit_triangles(corners, vertices, options, workspace);
    default:
      return fit_triangles(corners, vertices, options, workspace);
  }
}

Obb fit_tree_node_approx(std::span<const Vec3> corners, std::span<const Vec3> vertices, const FitOptions& options,
                         FitWorkspace& workspace) {
  if (corners.size() % 3 != 0) throw InputError("fit: triangle corners must come in threes");
  if (corners.empty() || vertices.empty()) throw InputError("fit: corners and vertices must be the same point set");
  check_finite(vertices);
  FitOptions approx = options;
  approx.method = FitMethod::approx;
  return fit_checked(vertices, approx, workspace, {}, Extras::by_size);
}

}  // namespace fit_detail

FitWorkspace::FitWorkspace() : scratch_(std::make_unique<Scratch>()) {}
FitWorkspace::~FitWorkspace() = default;
FitWorkspace::FitWorkspace(FitWorkspace&&) noexcept = default;
FitWorkspace& FitWorkspace::operator=(FitWorkspace&&) noexcept = default;
std::size_t FitWorkspace::last_hull_vertices() const { return scratch_->last_hull_vertices; }

std::optional<FitMethod> parse_fit_method(std::string_view name) {
  return kNames.parse(name);
}

std::string_view to_string(FitMethod method) {
  return kNames.name(method);
}

std::span<const FitMethod> all_fit_methods() { return kNames.values(); }
std::span<const std::string_view> fit_method_names() { return kNames.names(); }

// e -> k. The proof of Theorem 6.4.3 needs k = c/e with a constant c that is far too
// pessimistic in practice (m = max(4/e, 6) and grid cells of 1/(10m + 20) of the optimum).
// We use k = ceil(0.15 / e), from a measurement: on 144 point sets (40 random sets of four
// kinds and the 104 corpus meshes with hulls of at most 400 vertices) the worst relative
// excess of approx (with the local improvement) over exact was 2.5% at k = 2, 1.4% at k = 3,
// 0.9% at k = 6 and 0.63% at k = 8, i.e. about 0.05/k; 0.15/k leaves a factor 3.
int grid_for_epsilon(double epsilon) {
  if (!(epsilon > 0.0) || !std::isfinite(epsilon)) throw InputError("fit: epsilon must be a positive number");
  return static_cast<int>(std::clamp(std::ceil(0.15 / epsilon), 1.0, 64.0));
}

Obb fit_points(std::span<const Vec3> points, const FitOptions& options) {
  FitWorkspace workspace;
  return fit_points(points, options, workspace);
}

Obb fit_points(std::span<const Vec3> points, const FitOptions& options, FitWorkspace& workspace) {
  if (options.method == FitMethod::pca || options.method == FitMethod::pca_vertex) {
    workspace.scratch().last_hull_vertices = 0;
    return fit_pca(points, {});
  }
  if (options.method == FitMethod::approx_kernel) return fit_kernel(points, {}, workspace);
  if (options.method == FitMethod::normal_bopt) return fit_normal_bopt(points, {}, workspace);
  check_finite(points);
  return fit_checked(points, options, workspace);
}

Obb fit_triangles(std::span<const Vec3> corners, const FitOptions& options) {
  FitWorkspace workspace;
  return fit_triangles(corners, options, workspace);
}

Obb fit_triangles(std::span<const Vec3> corners, const FitOptions& options, FitWorkspace& workspace) {
  if (corners.size() % 3 != 0) throw InputError("fit: triangle corners must come in threes");
  if (options.method == FitMethod::pca || options.method == FitMethod::pca_vertex) {
    workspace.scratch().last_hull_vertices = 0;
    return fit_pca(corners, options.method == FitMethod::pca ? corners : std::span<const Vec3>{});
  }
  if (options.method == FitMethod::approx_kernel) return fit_kernel(corners, corners, workspace);
  if (options.method == FitMethod::normal_bopt) return fit_normal_bopt(corners, corners, workspace);
  check_finite(corners);
  return fit_checked(corners, options, workspace);
}

Obb fit_triangles(std::span<const Vec3> corners, std::span<const Vec3> vertices, const FitOptions& options,
                  FitWorkspace& workspace) {
  if (corners.size() % 3 != 0) throw InputError("fit: triangle corners must come in threes");
  if (corners.empty() != vertices.empty()) throw InputError("fit: corners and vertices must be the same point set");
  switch (options.method) {
    case FitMethod::pca:
    case FitMethod::pca_vertex:  // FCL's covariance is that of the corners, repeats included
      return fit_triangles(corners, options, workspace);
    case FitMethod::approx_kernel:
      return fit_kernel(vertices, corners, workspace);
    case FitMethod::normal_bopt:
      return fit_normal_bopt(vertices, corners, workspace);
    default:
      check_finite(vertices);
      return fit_checked(vertices, options, workspace);
  }
}

}  // namespace tightbvh
