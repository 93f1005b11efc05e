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

inline double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// One batch of `calls` calls of h: adds the seconds per call to `times`, returns the seconds spent.
template <typename H>
double timed_batch(H& h, int calls, std::vector<double>& times) {
  const double start = bench_support::thread_seconds();
  for (int c = 0; c < calls; ++c) h();
  const double spent = bench_support::thread_seconds() - start;
  times.push_back(spent / calls);
  return spent;
}

// Calls per batch: one call timed (after a first, warm-up call), the batch about budget / 10.
template <typename H>
int batch_size(H& h, double budget) {
  h();
  std::vector<double> one;
  timed_batch(h, 1, one);
  return one[0] >= 0.1 * budget ? 1 : static_cast<int>(0.1 * budget / std::max(one[0], 1e-8)) + 1;
}

// Thread CPU seconds per call of f and of g, fair to tiny calls: each is timed in batches (one
// pair of clock reads per batch of calls, the batch sized to about a tenth of `budget`), because
// a read of the thread CPU clock costs about 1.6 us on the benchmark machine, which timed around
// every call added as much to each call of both sides (it made a 2 us call look like 3.6 us).
// Batches of f and g alternate, so load changes hit both; at least 3 batches each, until both
// spent `budget`; the median batch of each.
template <typename F, typename G>
std::pair<double, double> seconds_per_call_pair(F&& f, G&& g, double budget) {
  const int nf = batch_size(f, budget), ng = batch_size(g, budget);
  std::vector<double> tf, tg;
  double spent_f = 0.0, spent_g = 0.0;
  while (tf.size() < 3 || spent_f < budget || spent_g < budget) {
    spent_f += timed_batch(f, nf, tf);
    spent_g += timed_batch(g, ng, tg);
  }
  return {median_of(tf), median_of(tg)};
}

// The same for one function (budget 0: one call, timed once).
template <typename F>
double seconds_per_call(F&& f, double budget) {
  std::vector<double> times;
  if (budget <= 0.0) {
    timed_batch(f, 1, times);
    return times[0];
  }
  const int n = batch_size(f, budget);
  double spent = 0.0;
  while (times.size() < 3 || spent < budget) spent += timed_batch(f, n, times);
  return median_of(times);
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
    const auto [t_ours, t_cgal] = seconds_per_call_pair(
        [&] { ours = bounding_ball(v); },
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
