// tightbvh-hull-bench MESH... [--reps R]: our Quickhull (convex_hull) against the
// qhull-based hull (bench/oracles/qhull_oracle.cpp: probe, prefilter, 'Qt Q8') on the vertices of
// each mesh: median thread CPU time of R calls each, hull vertex counts, and how many vertices
// only one of the two reports.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "../thread_clock.hpp"
#include "qhull_oracle.hpp"
#include "tightbvh/hull.hpp"
#include "tightbvh/mesh.hpp"

namespace {

using tightbvh::bench_support::thread_seconds;

template <typename F>
double median_seconds(int reps, F&& f) {
  std::vector<double> times;
  for (int r = 0; r < reps; ++r) {
    const double start = thread_seconds();
    f();
    times.push_back(thread_seconds() - start);
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 21;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--reps") == 0 && i + 1 < argc)
      reps = std::max(1, std::atoi(argv[++i]));
    else
      files.emplace_back(argv[i]);
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: tightbvh-hull-bench MESH... [--reps R]\n");
    return 2;
  }
  std::printf("%-32s %7s | %8s %6s | %8s %6s | %7s | %s\n", "mesh", "points", "qhull ms", "verts", "ours ms", "verts",
              "speedup", "only qhull / only ours");
  for (const std::string& file : files) {
    const auto points = tightbvh::load_mesh(file).vertices;
    tightbvh::ConvexHull3 ours, theirs;
    tightbvh::HullWorkspace ws;
    tightbvh::oracle::QhullWorkspace qws;
    const double t_qhull = median_seconds(reps, [&] { (void)tightbvh::oracle::qhull_hull(points, theirs, qws); });
    const double t_ours = median_seconds(reps, [&] { tightbvh::convex_hull(points, ours, ws); });
    std::vector<std::uint32_t> a(theirs.input_index), b(ours.input_index), only_a, only_b;
    // Compare positions, not indices: duplicates may be represented by either copy.
    const auto key = [&](std::uint32_t i) { return std::array<double, 3>{points[i].x(), points[i].y(), points[i].z()}; };
    const auto less = [&](std::uint32_t x, std::uint32_t y) { return key(x) < key(y); };
    std::sort(a.begin(), a.end(), less);
    std::sort(b.begin(), b.end(), less);
    std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(only_a), less);
    std::set_difference(b.begin(), b.end(), a.begin(), a.end(), std::back_inserter(only_b), less);
    const std::string name = file.substr(file.find_last_of('/') + 1);
    std::printf("%-32s %7zu | %8.3f %6zu | %8.3f %6zu | %6.1fx | %zu / %zu\n", name.c_str(), points.size(), 1e3 * t_qhull,
                theirs.vertices.size(), 1e3 * t_ours, ours.vertices.size(), t_qhull / t_ours, only_a.size(),
                only_b.size());
    std::fflush(stdout);
  }
  return 0;
}
