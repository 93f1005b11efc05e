#pragma once
// Part of tightbvh-fit-vs-cgal (--containers; no CGAL here): Sunday's comparison of bounding
// containers ("Bounding Containers for Polygons, Polyhedra, and Point Sets") over the corpus: every
// container's volume relative to the exact minimum box, and its fit time, as a Markdown table
// (median and worst ratio, median thread CPU time over the meshes).
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "ball_vs_cgal.hpp"
#include "tightbvh/ball.hpp"
#include "tightbvh/dop.hpp"
#include "tightbvh/ellipsoid.hpp"
#include "tightbvh/fit.hpp"
#include "tightbvh/hull.hpp"
#include "corpus_vertices.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::containers_bench {

struct Container {
  const char* name;    // the table's row
  const char* column;  // the per-mesh listing's column
  // Fits the container to the points and returns its volume.
  std::function<double(std::span<const Vec3>, FitWorkspace&)> volume;
};

inline double box_volume(std::span<const Vec3> v, FitMethod method, FitWorkspace& ws) {
  return fit_points(v, {.method = method}, ws).volume();
}

// The table's rows, in Sunday's order (cheap to tight); the exact box, the reference, last.
inline std::vector<Container> containers(double epsilon) {
  return {
      {"aabb", "aabb", [](auto v, auto& ws) { return box_volume(v, FitMethod::aabb, ws); }},
      {"diamond (8-DOP)", "diamond", [](auto v, auto&) { return bounding_dop(v, DopKind::diamond).volume(); }},
      {"14-DOP (box + diamond)", "14-DOP", [](auto v, auto&) { return bounding_dop(v, DopKind::dop14).volume(); }},
      {"ball (exact)", "ball", [](auto v, auto&) { return bounding_ball(v).volume(); }},
      {"fast ball (Ritter)", "fastball", [](auto v, auto&) { return fast_ball(v).volume(); }},
      {"ellipsoid", "ellipsd", [epsilon](auto v, auto&) { return bounding_ellipsoid(v, epsilon).volume(); }},
      {"pca box", "pca", [](auto v, auto& ws) { return box_volume(v, FitMethod::pca, ws); }},
      {"approx box", "approx", [](auto v, auto& ws) { return box_volume(v, FitMethod::approx, ws); }},
      {"exact box", "exact", [](auto v, auto& ws) { return box_volume(v, FitMethod::exact, ws); }},
  };
}

inline std::string time_text(double seconds) {
  char text[32];
  if (seconds < 1e-3)
    std::snprintf(text, sizeof text, "%.1f µs", 1e6 * seconds);
  else
    std::snprintf(text, sizeof text, "%.2f ms", 1e3 * seconds);
  return text;
}

inline void print_table(const std::vector<Container>& rows, const std::vector<std::vector<double>>& ratios,
                        const std::vector<std::vector<double>>& seconds) {
  std::printf(
      "\n| container | volume / exact box, median | worst | median fit "
      "time |\n|---|---|---|---|\n");
  for (std::size_t c = 0; c < rows.size(); ++c)
    std::printf("| %s | %.3f | %.3f | %s |\n", rows[c].name, ball_bench::median_of(ratios[c]),
                *std::max_element(ratios[c].begin(), ratios[c].end()),
                time_text(ball_bench::median_of(seconds[c])).c_str());
}

// Meshes whose hull has more than `exact_max_hull` vertices are skipped (no reference box), as are
// flat ones (a zero reference volume). Every container except the exact box is timed by repetition
// for `budget` seconds; the exact box once.
inline int compare_containers(const std::vector<std::filesystem::path>& files, double epsilon,
                              std::size_t exact_max_hull, double budget = 0.02) {
  const std::vector<Container> rows = containers(epsilon);
  std::vector<std::vector<double>> ratios(rows.size()), seconds(rows.size());
  std::printf("%-34s %8s %6s %12s", "mesh", "vertices", "hull", "exact box");
  for (std::size_t c = 0; c + 1 < rows.size(); ++c) std::printf(" %8s", rows[c].column);
  std::printf("\n");
  int flat = 0, big = 0;
  FitWorkspace ws;
  for (const auto& file : files) {
    const std::optional<std::vector<Vec3>> loaded = fit_bench::vertices_or_skip(file);
    if (!loaded) continue;
    const std::vector<Vec3>& v = *loaded;
    const ConvexHull3 hull = convex_hull(v);
    if (hull.dimension < 3 || hull.vertices.size() > exact_max_hull) {
      std::printf("%-34s skipped: %s\n", file.filename().c_str(),
                  hull.dimension < 3 ? "flat" : "hull above --exact-max-hull");
      ++(hull.dimension < 3 ? flat : big);
      continue;
    }
    std::vector<double> volume(rows.size());
    for (std::size_t c = 0; c < rows.size(); ++c) {
      const bool once = c + 1 == rows.size();
      seconds[c].push_back(
          ball_bench::seconds_per_call([&] { volume[c] = rows[c].volume(v, ws); }, once ? 0.0 : budget));
    }
    std::printf("%-34s %8zu %6zu %12.6g", file.filename().c_str(), v.size(), hull.vertices.size(), volume.back());
    for (std::size_t c = 0; c < rows.size(); ++c) {
      ratios[c].push_back(volume[c] / volume.back());
      if (c + 1 < rows.size()) std::printf(" %8.4f", ratios[c].back());
    }
    std::printf("\n");
    std::fflush(stdout);
  }
  if (ratios[0].empty()) return 1;
  std::printf(
      "\n%zu meshes (%d flat and %d with hulls above %zu vertices skipped); "
      "ellipsoid eps = %g; thread CPU "
      "time per fit, whole function (hull included where the method uses it)\n",
      ratios[0].size(), flat, big, exact_max_hull, epsilon);
  print_table(rows, ratios, seconds);
  return 0;
}

}  // namespace tightbvh::containers_bench
