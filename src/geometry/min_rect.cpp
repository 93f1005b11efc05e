// Rotating calipers (Toussaint 1983) for the minimum-area rectangle of a convex polygon.
#include "tightbvh/min_rect.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#define TIGHTBVH_MIN_RECT_SSE2 1
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#define TIGHTBVH_MIN_RECT_AVX 1
namespace tightbvh::detail {
// min_rect_avx.cpp: the pair loop below, four directions per AVX instruction.
void pair_areas_avx(const double* px, const double* py, std::size_t n, const double* ex, const double* ey,
                    std::size_t pairs, double* area);
}  // namespace tightbvh::detail
namespace {
// Whether pair_areas_avx may run: asked of the CPU once.
bool avx_available() {
  static const bool avx = __builtin_cpu_supports("avx");
  return avx;
}
}  // namespace
#endif

namespace tightbvh {
namespace {

Rect2 rect_along(std::span<const Vec2> polygon, const Vec2& axis) {
  const Vec2 perp(-axis.y(), axis.x());
  Rect2 r;
  r.axis = axis;
  r.min = Vec2::Constant(std::numeric_limits<double>::infinity());
  r.max = -r.min;
  for (const Vec2& p : polygon) {
    const Vec2 q(axis.dot(p), perp.dot(p));
    r.min = r.min.cwiseMin(q);
    r.max = r.max.cwiseMax(q);
  }
  return r;
}

}  // namespace

Rect2 min_area_rect(std::span<const Vec2> polygon) {
  const std::size_t n = polygon.size();
  if (n == 0) return {};
  if (n == 1) return rect_along(polygon, Vec2::UnitX());
  if (n == 2) {
    const Vec2 d = polygon[1] - polygon[0];
    const double len = d.norm();
    return rect_along(polygon, len > 0.0 ? Vec2(d / len) : Vec2::UnitX());
  }
  // For edge i (from p[i] to p[i+1], counter-clockwise, interior on the left) keep three
  // calipers: r = farthest along the edge, t = farthest from the edge line (towards the
  // interior), l = farthest against the edge direction. Each only moves forward: O(n).
  // `edge(i)` is p[i+1] - p[i]: read from a table for the usual few-vertex polygons (each edge
  // is tested several times), computed again for large ones (no allocation); the same values.
  const auto next = [n](std::size_t i) { return i + 1 == n ? 0 : i + 1; };
  const auto calipers = [&](const auto& edge) {
    std::size_t r = 0, t = 0, l = 0;
    double best_area = std::numeric_limits<double>::infinity();
    std::size_t best_edge = 0;
    for (std::size_t i = 0; i < n; ++i) {
      // u = e, v = e rotated: unnormalised (the caliper tests only use signs), so the area is
      // the product of the two spans over |e|^2; no square root per edge.
      const Vec2 e = edge(i);
      const double len2 = e.squaredNorm();
      if (!(len2 > 0.0)) continue;
      const Vec2& u = e;
      const Vec2 v(-u.y(), u.x());
      const Vec2& o = polygon[i];
      if (i == 0) {
        r = next(i);
        t = r;
        l = 0;
      }
      // Advance r while it increases the projection on u; t on v; l while it decreases on u.
      std::size_t guard = 0;
      while (guard++ < n && u.dot(edge(r)) > 0.0) r = next(r);
      if (i == 0) t = r;
      guard = 0;
      while (guard++ < n && v.dot(edge(t)) > 0.0) t = next(t);
      if (i == 0) l = t;
      guard = 0;
      while (guard++ < n && u.dot(edge(l)) < 0.0) l = next(l);
      const double width = u.dot(polygon[r] - o) - u.dot(polygon[l] - o);
      const double height = v.dot(polygon[t] - o);
      const double area = width * height / len2;
      if (area < best_area) {
        best_area = area;
        best_edge = i;
      }
    }
    return best_edge;
  };
  constexpr std::size_t kTable = 64;
  std::size_t best_edge = 0;
#ifdef TIGHTBVH_MIN_RECT_AVX
  if (n <= kMinAreaRectEdgeScanMax && avx_available()) {
    // Each edge's rectangle by a scan of all vertices, four edges per AVX instruction
    // (pair_areas_avx with the edges as directions): O(n^2) but without the calipers' branches,
    // which mispredict on the few-vertex polygons of Bopt's silhouettes. The same minimum up to
    // rounding (the calipers' extremes are the scan's maxima); the rectangle is measured again below.
    // Absolute projections, as rect_along's: Bopt's polygons lie near their origin (local frames).
    alignas(32) double px[kMinAreaRectEdgeScanMax], py[kMinAreaRectEdgeScanMax];
    alignas(32) double ex[kMinAreaRectEdgeScanMax + 3], ey[kMinAreaRectEdgeScanMax + 3];
    alignas(32) double area[kMinAreaRectEdgeScanMax + 3];
    for (std::size_t i = 0; i < n; ++i) px[i] = polygon[i].x(), py[i] = polygon[i].y();
    for (std::size_t i = 0; i < n; ++i) ex[i] = px[next(i)] - px[i], ey[i] = py[next(i)] - py[i];
    for (std::size_t i = n; i < n + 3; ++i) ex[i] = ey[i] = 0.0;  // the last lanes' padding
    detail::pair_areas_avx(px, py, n, ex, ey, n, area);
    double best_area = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i)
      if (ex[i] * ex[i] + ey[i] * ey[i] > 0.0 && area[i] < best_area) best_area = area[i], best_edge = i;
  } else
#endif
  if (n <= kTable) {
    Vec2 table[kTable];
    for (std::size_t i = 0; i < n; ++i) table[i] = polygon[next(i)] - polygon[i];
    best_edge = calipers([&](std::size_t i) -> const Vec2& { return table[i]; });
  } else {
    best_edge = calipers([&](std::size_t i) -> Vec2 { return polygon[next(i)] - polygon[i]; });
  }
  const Vec2 e = polygon[next(best_edge)] - polygon[best_edge];
  const double len = e.norm();
  // The final extents are recomputed over all vertices, so the rectangle always contains the
  // polygon even if a caliper stopped early on nearly-collinear vertices.
  return rect_along(polygon, len > 0.0 ? Vec2(e / len) : Vec2::UnitX());
}

Rect2 min_area_rect_of_points(std::span<const Vec2> points) {
  const std::size_t n = points.size();
  if (n == 0) return {};
  // As min_area_rect: per direction e (unnormalised), the spans along e and its perpendicular over
  // |e|^2; the first direction of the smallest area wins.
  double best_area = std::numeric_limits<double>::infinity();
  Vec2 best = Vec2::Zero();
#ifdef TIGHTBVH_MIN_RECT_SSE2
  if (n <= kMinAreaRectOfPointsMax) {
    // Two pair directions per SSE2 instruction: the same products, sums, spans and areas as the
    // scalar loop below (e . p = ex px + ey py, min_pd(q, lo) = std::min(lo, q)), so the same
    // rectangle bit for bit; the areas are then compared in the scalar loop's order.
    constexpr std::size_t kPairs = kMinAreaRectOfPointsMax * (kMinAreaRectOfPointsMax - 1) / 2;
    alignas(16) double px[kMinAreaRectOfPointsMax], py[kMinAreaRectOfPointsMax];
    alignas(16) double ex[kPairs + 4] = {}, ey[kPairs + 4] = {}, area[kPairs + 4];
    for (std::size_t k = 0; k < n; ++k) px[k] = points[k].x(), py[k] = points[k].y();
    std::size_t pairs = 0;
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j, ++pairs) ex[pairs] = px[j] - px[i], ey[pairs] = py[j] - py[i];
    const __m128d sign = _mm_set1_pd(-0.0);
#ifdef TIGHTBVH_MIN_RECT_AVX
    const bool avx = avx_available();
    if (avx) detail::pair_areas_avx(px, py, n, ex, ey, pairs, area);
    for (std::size_t q = 0; q < pairs && !avx; q += 2) {
#else
    for (std::size_t q = 0; q < pairs; q += 2) {
#endif
      const __m128d x = _mm_load_pd(ex + q), y = _mm_load_pd(ey + q);
      const __m128d my = _mm_xor_pd(y, sign);  // v = (-ey, ex), negated as the scalar loop does
      const auto along = [&](std::size_t k) {
        return _mm_add_pd(_mm_mul_pd(x, _mm_set1_pd(px[k])), _mm_mul_pd(y, _mm_set1_pd(py[k])));
      };
      const auto across = [&](std::size_t k) {
        return _mm_add_pd(_mm_mul_pd(my, _mm_set1_pd(px[k])), _mm_mul_pd(x, _mm_set1_pd(py[k])));
      };
      __m128d u_lo = along(0), u_hi = u_lo, v_lo = across(0), v_hi = v_lo;
      for (std::size_t k = 1; k < n; ++k) {
        const __m128d a = along(k), b = across(k);
        u_lo = _mm_min_pd(a, u_lo), u_hi = _mm_max_pd(a, u_hi);
        v_lo = _mm_min_pd(b, v_lo), v_hi = _mm_max_pd(b, v_hi);
      }
      const __m128d len2 = _mm_add_pd(_mm_mul_pd(x, x), _mm_mul_pd(y, y));
      _mm_store_pd(area + q, _mm_div_pd(_mm_mul_pd(_mm_sub_pd(u_hi, u_lo), _mm_sub_pd(v_hi, v_lo)), len2));
    }
    std::size_t at = pairs;
    for (std::size_t q = 0; q < pairs; ++q)
      if (ex[q] * ex[q] + ey[q] * ey[q] > 0.0 && area[q] < best_area) best_area = area[q], at = q;
    if (at < pairs) best = Vec2(ex[at], ey[at]);
  } else
#endif
  {
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j) {
        const Vec2 e = points[j] - points[i];
        const double len2 = e.squaredNorm();
        if (!(len2 > 0.0)) continue;
        const Vec2 v(-e.y(), e.x());
        // The spans of the points' own projections (the callers' points are near their origin).
        double u_lo = e.dot(points[0]), u_hi = u_lo, v_lo = v.dot(points[0]), v_hi = v_lo;
        for (std::size_t k = 1; k < n; ++k) {
          const double a = e.dot(points[k]), b = v.dot(points[k]);
          u_lo = std::min(u_lo, a), u_hi = std::max(u_hi, a);
          v_lo = std::min(v_lo, b), v_hi = std::max(v_hi, b);
        }
        const double area = (u_hi - u_lo) * (v_hi - v_lo) / len2;
        if (area < best_area) best_area = area, best = e;
      }
  }
  const double len = best.norm();
  // The extents over all points along the chosen axis, as min_area_rect measures them.
  return rect_along(points, len > 0.0 ? Vec2(best / len) : Vec2::UnitX());
}

}  // namespace tightbvh
