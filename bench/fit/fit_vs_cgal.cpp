// tightbvh-fit-vs-cgal: our `approx` and `exact` against CGAL::oriented_bounding_box
// (Chang, Gorissen & Melchior 2011, as implemented in CGAL's Optimal_bounding_box package) on
// every mesh of a directory: volume ratio and time ratio (medians of a few repetitions).
// Sub-modes: --balls (ball_vs_cgal.hpp), --ellipsoids (ellipsoid_vs_cgal.hpp), --containers
// (containers_table.hpp, Sunday's table over every container), --hulls.
// The only translation unit that includes CGAL.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Optimal_bounding_box/oriented_bounding_box.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../thread_clock.hpp"
#include "ball_vs_cgal.hpp"
#include "containers_table.hpp"
#include "ellipsoid_vs_cgal.hpp"
#include "tightbvh/fit.hpp"
#include "tightbvh/hull.hpp"
#include "tightbvh/mesh.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Timed {
  double volume = 0.0;
  double seconds = 0.0;
};

using tightbvh::bench_support::thread_seconds;  // both sides are single-threaded

template <typename F>
Timed repeat(int reps, F&& f) {
  std::vector<double> times, volumes;
  for (int r = 0; r < reps; ++r) {
    const double start = thread_seconds();
    const double v = f();
    times.push_back(thread_seconds() - start);
    volumes.push_back(v);
  }
  return {median(volumes), median(times)};
}

// CGAL's box: the transformation maps the points into the frame where the box is axis aligned.
double cgal_volume(const std::vector<K::Point_3>& points) {
  K::Aff_transformation_3 t;
  CGAL::oriented_bounding_box(points, t, CGAL::parameters::use_convex_hull(true));
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (const auto& p : points) {
    const K::Point_3 q = t.transform(p);
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], q[k]), hi[k] = std::max(hi[k], q[k]);
  }
  return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
}

// Seconds per call (thread CPU) of f, repeated until at least `budget` seconds were spent.
template <typename F>
double per_call(F&& f, double budget = 0.2) {
  int calls = 0;
  const double start = thread_seconds();
  double spent = 0.0;
  do {
    f();
    ++calls;
    spent = thread_seconds() - start;
  } while (spent < budget);
  return spent / calls;
}

// Our convex_hull (dimension check, Quickhull, edge/face graph) against CGAL's
// quickhull (CGAL::convex_hull_3 into a Surface_mesh) on node-sized inputs: the n vertices of a
// mesh nearest to one of its vertices.
void compare_hulls(const std::filesystem::path& mesh_path) {
  const auto all = tightbvh::load_mesh(mesh_path).vertices;
  std::printf("hull timing on %s nodes (thread CPU per call)\n%8s %6s %12s %12s %8s\n", mesh_path.filename().c_str(),
              "points", "hull", "ours us", "CGAL us", "CGAL/ours");
  for (std::size_t n : {10, 30, 100, 300, 1000, 3000, 10000}) {
    if (n > all.size()) break;
    std::vector<tightbvh::Vec3> node(all);
    const tightbvh::Vec3 seed = node[node.size() / 3];
    std::nth_element(node.begin(), node.begin() + static_cast<std::ptrdiff_t>(n) - 1, node.end(),
                     [&](const auto& a, const auto& b) { return (a - seed).squaredNorm() < (b - seed).squaredNorm(); });
    node.resize(n);
    std::vector<K::Point_3> cgal_points;
    for (const auto& p : node) cgal_points.emplace_back(p.x(), p.y(), p.z());
    tightbvh::ConvexHull3 hull;
    tightbvh::HullWorkspace ws;
    const double ours = per_call([&] { tightbvh::convex_hull(node, hull, ws); });
    CGAL::Surface_mesh<K::Point_3> sm;
    const double cgal = per_call([&] {
      sm.clear();
      CGAL::convex_hull_3(cgal_points.begin(), cgal_points.end(), sm);
    });
    std::printf("%8zu %6zu %12.1f %12.1f %8.2f\n", n, hull.vertices.size(), 1e6 * ours, 1e6 * cgal, cgal / ours);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"compare tightbvh's approx and exact boxes with CGAL::oriented_bounding_box"};
  std::vector<std::string> inputs{std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/corpus/cgal"};
  int reps = 3;
  int grid = tightbvh::FitOptions{}.grid;
  std::size_t exact_max_hull = 1500;
  std::string json_path;
  app.add_option("inputs", inputs, "mesh files or directories of meshes")->capture_default_str();
  app.add_option("--reps", reps, "repetitions per measurement (medians)")->capture_default_str();
  app.add_option("--grid", grid, "approx grid radius k")->capture_default_str();
  app.add_option("--exact-max-hull", exact_max_hull, "run exact only when the hull has at most this many vertices")
      ->capture_default_str();
  app.add_option("--json", json_path, "also write the per-mesh results to this JSON file");
  std::string hulls_mesh;
  app.add_option("--hulls", hulls_mesh, "only time our convex_hull vs CGAL::convex_hull_3 on nodes of this mesh");
  bool balls = false;
  app.add_flag("--balls", balls, "only compare bounding_ball with CGAL::Min_sphere_of_spheres_d (and fast_ball)");
  bool ellipsoids = false;
  app.add_flag("--ellipsoids", ellipsoids,
               "only compare bounding_ellipsoid with CGAL::Approximate_min_ellipsoid_d at --epsilon");
  bool containers = false;
  app.add_flag("--containers", containers,
               "only print Sunday's table: every container's volume relative to the exact box, and fit time");
  double epsilon = 0.01;
  app.add_option("--epsilon", epsilon, "ellipsoid (1+eps) volume approximation (--ellipsoids, --containers)")
      ->capture_default_str();
  std::size_t ellipsoid_max_vertices = 1000000;
  app.add_option("--ellipsoid-max-vertices", ellipsoid_max_vertices,
                 "--ellipsoids: skip meshes with more vertices (CGAL's time cap)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (!hulls_mesh.empty()) {
    compare_hulls(hulls_mesh);
    return 0;
  }

  std::vector<std::filesystem::path> files;
  for (const auto& in : inputs) {
    if (std::filesystem::is_directory(in)) {
      for (const auto& e : std::filesystem::directory_iterator(in))
        if (e.is_regular_file()) files.push_back(e.path());
    } else {
      files.emplace_back(in);
    }
  }
  std::sort(files.begin(), files.end());
  if (balls) return tightbvh::ball_bench::compare_balls(files);
  if (ellipsoids) return tightbvh::ellipsoid_bench::compare_ellipsoids(files, epsilon, ellipsoid_max_vertices);
  if (containers) return tightbvh::containers_bench::compare_containers(files, epsilon, exact_max_hull);

  nlohmann::json out = nlohmann::json::array();
  std::printf("%-34s %8s %6s %12s %9s | %9s %9s %8s | %9s %9s\n", "mesh", "vertices", "hull", "cgal volume", "cgal s",
              "approx/c", "speedup", "approx s", "exact/c", "exact s");
  int approx_volume_ok = 0, approx_speed_ok = 0, exact_ok = 0, exact_run = 0, compared = 0;
  std::vector<double> speedups;
  for (const auto& file : files) {
    tightbvh::Mesh mesh;
    try {
      mesh = tightbvh::load_mesh(file);
    } catch (const std::exception& e) {
      std::printf("%-34s skipped: %s\n", file.filename().c_str(), e.what());
      continue;
    }
    const auto& v = mesh.vertices;
    const tightbvh::ConvexHull3 hull = tightbvh::convex_hull(v);
    if (hull.dimension < 3) {
      std::printf("%-34s skipped: flat (hull dimension %d)\n", file.filename().c_str(), hull.dimension);
      continue;
    }
    std::vector<K::Point_3> cgal_points;
    cgal_points.reserve(v.size());
    for (const auto& p : v) cgal_points.emplace_back(p.x(), p.y(), p.z());

    tightbvh::FitWorkspace ws;
    const Timed cgal = repeat(reps, [&] { return cgal_volume(cgal_points); });
    const Timed approx = repeat(reps, [&] {
      return tightbvh::fit_points(v, {.method = tightbvh::FitMethod::approx, .grid = grid}, ws).volume();
    });
    Timed exact{-1.0, -1.0};
    const bool run_exact = hull.vertices.size() <= exact_max_hull;
    if (run_exact)
      exact = repeat(1, [&] { return tightbvh::fit_points(v, {.method = tightbvh::FitMethod::exact}, ws).volume(); });
    ++compared;
    const double approx_ratio = approx.volume / cgal.volume;
    const double speedup = cgal.seconds / approx.seconds;
    speedups.push_back(speedup);
    approx_volume_ok += approx_ratio <= 1.005;
    approx_speed_ok += speedup >= 10.0;
    if (run_exact) {
      ++exact_run;
      exact_ok += exact.volume <= cgal.volume * (1 + 1e-9);
    }
    std::printf("%-34s %8zu %6zu %12.6g %9.5f | %9.5f %8.1fx %9.5f | ", file.filename().c_str(), v.size(),
                hull.vertices.size(), cgal.volume, cgal.seconds, approx_ratio, speedup, approx.seconds);
    if (run_exact)
      std::printf("%9.5f %9.4f\n", exact.volume / cgal.volume, exact.seconds);
    else
      std::printf("%9s %9s\n", "-", "-");
    std::fflush(stdout);
    nlohmann::json row{{"mesh", file.filename().string()},
                       {"vertices", v.size()},
                       {"hull_vertices", hull.vertices.size()},
                       {"cgal_volume", cgal.volume},
                       {"cgal_seconds", cgal.seconds},
                       {"approx_volume", approx.volume},
                       {"approx_seconds", approx.seconds},
                       {"approx_volume_ratio", approx_ratio},
                       {"approx_speedup", speedup}};
    if (run_exact) {
      row["exact_volume"] = exact.volume;
      row["exact_seconds"] = exact.seconds;
      row["exact_volume_ratio"] = exact.volume / cgal.volume;
    }
    out.push_back(row);
  }
  std::printf("\n%d meshes compared (approx k=%d, %d repetitions, medians of thread CPU time)\n", compared, grid, reps);
  std::printf("approx volume <= 1.005 x CGAL: %d / %d\n", approx_volume_ok, compared);
  std::printf("approx >= 10x faster than CGAL: %d / %d (median speedup %.1fx)\n", approx_speed_ok, compared,
              median(speedups));
  std::printf("exact volume <= CGAL: %d / %d (exact run on hulls <= %zu vertices)\n", exact_ok, exact_run,
              exact_max_hull);
  if (!json_path.empty()) {
    std::ofstream f(json_path);
    f << nlohmann::json{{"grid", grid}, {"repetitions", reps}, {"meshes", out}}.dump(2) << '\n';
  }
  return 0;
}
