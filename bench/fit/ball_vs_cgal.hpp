#pragma once
// Part of tightbvh-fit-vs-cgal (included by fit_vs_cgal.cpp only, so CGAL stays in that one
// translation unit): our exact bounding_ball against CGAL::Min_sphere_of_spheres_d, and
// fast_ball's (Ritter's) excess radius over the exact one, on every mesh.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Min_sphere_of_spheres_d.h>
#include <CGAL/Min_sphere_of_spheres_d_traits_3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <utility>
#include <vector>

#include "../thread_clock.hpp"
#include "corpus_vertices.hpp"
#include "tightbvh/ball.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::ball_bench {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
// Square roots on: CGAL's radius is a double (the default represents it as a + b sqrt(t)).
using Traits = CGAL::Min_sphere_of_spheres_d_traits_3<K, double, CGAL::Tag_true>;

// Seconds per call (thread CPU), repeated until `budget` seconds were spent.
template <typename F>
double seconds_per_call(F&& f, double budget) {
  int calls = 0;
  const double start = bench_support::thread_seconds();
  double spent = 0.0;
  do {
    f();
    ++calls;
    spent = bench_support::thread_seconds() - start;
  } while (spent < budget);
  return spent / calls;
}

inline double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

inline int compare_balls(const std::vector<std::filesystem::path>& files, double budget = 0.05) {
  std::printf("%-34s %8s %14s %10s %10s %10s %9s %9s\n", "mesh", "vertices", "cgal radius", "rel diff", "ours us",
              "cgal us", "cgal/ours", "fast exc");
  std::vector<double> diffs, ratios, excess;
  int within = 0;
  for (const auto& file : files) {
    const std::optional<std::vector<Vec3>> loaded = fit_bench::vertices_or_skip(file);
    if (!loaded) continue;
    const std::vector<Vec3>& v = *loaded;
    std::vector<Traits::Sphere> spheres;
    spheres.reserve(v.size());
    for (const Vec3& p : v) spheres.emplace_back(K::Point_3(p.x(), p.y(), p.z()), 0.0);
    Ball ours, fast;
    double cgal_radius = 0.0;
    const double t_ours = seconds_per_call([&] { ours = bounding_ball(v); }, budget);
    const double t_cgal = seconds_per_call(
        [&] {
          CGAL::Min_sphere_of_spheres_d<Traits> ms(spheres.begin(), spheres.end());
          cgal_radius = ms.radius();
        },
        budget);
    fast = fast_ball(v);
    const double diff = std::abs(ours.radius - cgal_radius) / cgal_radius;
    const double exc = fast.radius / ours.radius - 1.0;
    diffs.push_back(diff), ratios.push_back(t_cgal / t_ours), excess.push_back(exc);
    within += diff <= 1e-9;
    std::printf("%-34s %8zu %14.8g %10.2e %10.1f %10.1f %9.2f %9.4f\n", file.filename().c_str(), v.size(), cgal_radius,
                diff, 1e6 * t_ours, 1e6 * t_cgal, t_cgal / t_ours, exc);
    std::fflush(stdout);
  }
  if (diffs.empty()) return 1;
  std::printf("\nballs on %zu meshes: radius rel diff vs CGAL worst %.2e median %.2e (<= 1e-9: %d / %zu); "
              "CGAL/ours time worst %.2f median %.2f; fast_ball excess worst %.4f median %.4f\n",
              diffs.size(), *std::max_element(diffs.begin(), diffs.end()), median_of(diffs), within, diffs.size(),
              *std::min_element(ratios.begin(), ratios.end()), median_of(ratios),
              *std::max_element(excess.begin(), excess.end()), median_of(excess));
  return 0;
}

}  // namespace tightbvh::ball_bench
