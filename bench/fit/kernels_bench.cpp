// Micro-benchmarks of the fitters and their kernels (Google Benchmark):
//   BM_Fit/<method>/<source>/<n>: every fitter on node-sized inputs, the n mesh vertices
//     nearest to one vertex (what a BVH node holds), and on Gaussian sets for contrast;
//   BM_FitMesh/<method>/<mesh>: every fitter on the shipped meshes;
//   BM_Hull/<source>/<n>: the 3D convex hull alone.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "tightbvh/fit.hpp"
#include "tightbvh/hull.hpp"
#include "tightbvh/mesh.hpp"

namespace {

using tightbvh::FitMethod;
using tightbvh::Vec3;

const auto kMethods = tightbvh::all_fit_methods();

std::filesystem::path source(const std::string& relative) { return std::filesystem::path(TIGHTBVH_SOURCE_DIR) / relative; }

// The largest available real mesh: a corpus mesh when fetched, else the shipped knot.
const std::vector<Vec3>& big_mesh_vertices() {
  static const std::vector<Vec3> vertices = [] {
    for (const char* name : {"meshes/corpus/cgal/armadillo.off", "meshes/knot1.off"})
      if (std::filesystem::exists(source(name))) return tightbvh::load_mesh(source(name)).vertices;
    return std::vector<Vec3>{};
  }();
  return vertices;
}

// The n vertices nearest to a fixed vertex: a spatially coherent "node" of a real mesh.
std::vector<Vec3> mesh_node(std::size_t n) {
  const auto& all = big_mesh_vertices();
  std::vector<Vec3> points(all);
  const Vec3 seed = points[points.size() / 3];
  n = std::min(n, points.size());
  std::nth_element(points.begin(), points.begin() + static_cast<std::ptrdiff_t>(n) - 1, points.end(),
                   [&](const Vec3& a, const Vec3& b) { return (a - seed).squaredNorm() < (b - seed).squaredNorm(); });
  points.resize(n);
  return points;
}

std::vector<Vec3> gaussian(std::size_t n) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> normal;
  std::vector<Vec3> points(n);
  for (auto& p : points) p = Vec3(normal(rng), 2 * normal(rng), 0.5 * normal(rng));
  return points;
}

void register_all() {
  for (const std::size_t n : {10, 30, 100, 1000, 10000}) {
    for (const bool from_mesh : {true, false}) {
      const std::string src = from_mesh ? "mesh-node" : "gaussian";
      const auto points = std::make_shared<std::vector<Vec3>>(from_mesh ? mesh_node(n) : gaussian(n));
      const std::string suffix = "/" + src + "/" + std::to_string(n);
      for (FitMethod m : kMethods) {
        // exact, eberly2015 (quadratic in the hull's edges) and approx-snap on 10,000 points take
        // up to seconds per call: left out here.
        if ((m == FitMethod::exact || m == FitMethod::eberly2015 || m == FitMethod::approx_snap) && n > 1000) continue;
        benchmark::RegisterBenchmark(("BM_Fit/" + std::string(tightbvh::to_string(m)) + suffix).c_str(),
                                     [points, m](benchmark::State& state) {
                                       tightbvh::FitWorkspace ws;
                                       for (auto _ : state)
                                         benchmark::DoNotOptimize(tightbvh::fit_points(*points, {.method = m}, ws));
                                       state.counters["points"] = static_cast<double>(points->size());
                                       state.counters["hull"] = static_cast<double>(ws.last_hull_vertices());
                                     })
            ->Unit(benchmark::kMicrosecond);
      }
      benchmark::RegisterBenchmark(("BM_Hull" + suffix).c_str(), [points](benchmark::State& state) {
        tightbvh::ConvexHull3 hull;
        tightbvh::HullWorkspace ws;
        for (auto _ : state) {
          tightbvh::convex_hull(*points, hull, ws);
          benchmark::DoNotOptimize(hull.vertices.data());
        }
        state.counters["hull"] = static_cast<double>(hull.vertices.size());
      })->Unit(benchmark::kMicrosecond);
    }
  }
  for (const char* name : {"elephant", "knot1"}) {
    const auto mesh = std::make_shared<tightbvh::Mesh>(tightbvh::load_mesh(source(std::string("meshes/") + name + ".off")));
    const auto corners = std::make_shared<std::vector<Vec3>>(tightbvh::triangle_corners(*mesh));
    for (FitMethod m : kMethods) {
      benchmark::RegisterBenchmark(("BM_FitMesh/" + std::string(tightbvh::to_string(m)) + "/" + name).c_str(),
                                   [mesh, corners, m](benchmark::State& state) {
                                     tightbvh::FitWorkspace ws;
                                     for (auto _ : state)
                                       benchmark::DoNotOptimize(
                                           m == FitMethod::pca ? tightbvh::fit_triangles(*corners, {.method = m}, ws)
                                                               : tightbvh::fit_points(mesh->vertices, {.method = m}, ws));
                                     state.counters["hull"] = static_cast<double>(ws.last_hull_vertices());
                                   })
          ->Unit(benchmark::kMillisecond);
    }
  }
}

const bool registered = (register_all(), true);

}  // namespace
