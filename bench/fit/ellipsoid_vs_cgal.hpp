#pragma once
// Part of tightbvh-fit-vs-cgal (included by fit_vs_cgal.cpp only, so CGAL stays in that one
// translation unit): our bounding_ellipsoid against CGAL::Approximate_min_ellipsoid_d (Khachiyan's
// algorithm on the lifted points), both asked for a (1+eps)-approximation of the minimum-volume
// enclosing ellipsoid, on every mesh: volume ratio and thread CPU time.
#include <CGAL/Approximate_min_ellipsoid_d.h>
#include <CGAL/Approximate_min_ellipsoid_d_traits_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/MP_Float.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <numbers>
#include <vector>

#include "ball_vs_cgal.hpp"
#include "tightbvh/ellipsoid.hpp"
#include "tightbvh/hull.hpp"
#include "corpus_vertices.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::ellipsoid_bench {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
// MP_Float as in CGAL's own example: the exact type only checks the achieved epsilon.
using Traits = CGAL::Approximate_min_ellipsoid_d_traits_3<K, CGAL::MP_Float>;
using Ame = CGAL::Approximate_min_ellipsoid_d<Traits>;

// CGAL's ellipsoid as a user obtains it: construction plus the semi-axis lengths (which scale by
// the achieved epsilon, computed exactly). Returns its volume.
inline double cgal_ellipsoid_volume(const std::vector<K::Point_3>& points, double epsilon) {
  Ame ame(epsilon, points.begin(), points.end());
  if (!ame.is_full_dimensional()) return 0.0;
  auto axis = ame.axes_lengths_begin();
  return 4.0 / 3.0 * std::numbers::pi * axis[0] * axis[1] * axis[2];
}

struct Summary {
  std::vector<double> ratios, speedups;
  int within = 0;  // volume ratio <= 1 + epsilon
  int fast = 0;    // speed-up >= 5
};

inline void print_summary(const Summary& s, double epsilon, int flat, int capped, int cgal_degenerate,
                          std::size_t max_vertices) {
  std::printf(
      "\nellipsoids (eps = %g) on %zu meshes (skipped: %d flat, %d above %zu vertices, %d that CGAL calls not "
      "full-dimensional): volume ours/CGAL <= %g on %d / %zu (worst %.5f, median %.5f); speed-up >= 5x on %d / %zu "
      "(median %.1fx, slowest %.1fx)\n",
      epsilon, s.ratios.size(), flat, capped, max_vertices, cgal_degenerate, 1.0 + epsilon, s.within, s.ratios.size(),
      *std::max_element(s.ratios.begin(), s.ratios.end()), ball_bench::median_of(s.ratios), s.fast, s.speedups.size(),
      ball_bench::median_of(s.speedups), *std::min_element(s.speedups.begin(), s.speedups.end()));
}

// Meshes with more than `max_vertices` vertices are skipped (CGAL's time grows with n times its
// iteration count); flat meshes too (CGAL's axes need a full-dimensional set).
inline int compare_ellipsoids(const std::vector<std::filesystem::path>& files, double epsilon, std::size_t max_vertices,
                              double budget = 0.05) {
  std::printf("%-34s %8s %6s %12s %10s %10s %10s %9s\n", "mesh", "vertices", "hull", "cgal volume", "ours/cgal",
              "ours ms", "cgal ms", "speed-up");
  Summary s;
  int flat = 0, capped = 0, cgal_degenerate = 0;
  for (const auto& file : files) {
    const std::optional<std::vector<Vec3>> loaded = fit_bench::vertices_or_skip(file);
    if (!loaded) continue;
    const std::vector<Vec3>& v = *loaded;
    const ConvexHull3 hull = convex_hull(v);
    if (hull.dimension < 3) {
      std::printf("%-34s skipped: flat (hull dimension %d)\n", file.filename().c_str(), hull.dimension);
      ++flat;
      continue;
    }
    if (v.size() > max_vertices) {
      std::printf(
          "%-34s skipped: %zu vertices > --ellipsoid-max-vertices %zu "
          "(CGAL's time cap)\n",
          file.filename().c_str(), v.size(), max_vertices);
      ++capped;
      continue;
    }
    std::vector<K::Point_3> cgal_points;
    cgal_points.reserve(v.size());
    for (const Vec3& p : v) cgal_points.emplace_back(p.x(), p.y(), p.z());
    Ellipsoid ours;
    double cgal_volume = 0.0;
    const auto [t_ours, t_cgal] = ball_bench::seconds_per_call_pair(
        [&] { ours = bounding_ellipsoid(v, epsilon); },
        [&] { cgal_volume = cgal_ellipsoid_volume(cgal_points, epsilon); }, budget);
    if (cgal_volume == 0.0) {  // CGAL's numerical rank test calls some simplices degenerate
      std::printf("%-34s skipped: CGAL reports the set as not full-dimensional (our volume %.6g)\n",
                  file.filename().c_str(), ours.volume());
      ++cgal_degenerate;
      continue;
    }
    const double ratio = ours.volume() / cgal_volume;
    const double speedup = t_cgal / t_ours;
    s.ratios.push_back(ratio), s.speedups.push_back(speedup);
    s.within += ratio <= 1.0 + epsilon;
    s.fast += speedup >= 5.0;
    std::printf("%-34s %8zu %6zu %12.6g %10.5f %10.3f %10.3f %8.1fx\n", file.filename().c_str(), v.size(),
                hull.vertices.size(), cgal_volume, ratio, 1e3 * t_ours, 1e3 * t_cgal, speedup);
    std::fflush(stdout);
  }
  if (s.ratios.empty()) return 1;
  print_summary(s, epsilon, flat, capped, cgal_degenerate, max_vertices);
  return 0;
}

}  // namespace tightbvh::ellipsoid_bench
