// Google Benchmark of the point queries (point_query.hpp): points per second of closest_points
// against the brute force over every triangle and against CGAL's AABB_tree (closest_point_and_
// primitive, CGAL 5.5), one thread each, on shipped meshes, for points uniform in the mesh's
// bounding box and points near the surface (within 1% of the diagonal). The answers are checked
// in the same run: every engine's distances against tightbvh's (a benchmark whose engine disagrees
// reports an error instead of a time). CGAL stays in this one translation unit.
#include <benchmark/benchmark.h>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "tightbvh/mesh.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/point_query.hpp"

namespace {

using tightbvh::Vec3;

using Kernel = CGAL::Simple_cartesian<double>;
using Triangles = std::vector<Kernel::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Triangles::const_iterator>;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

const char* const kMeshes[] = {"elephant.off", "fandisk.off", "camel.off"};
const char* const kKinds[] = {"uniform", "near"};
constexpr std::size_t kPoints = 20000;
constexpr std::size_t kBrutePoints = 200;  // the brute force runs on the first of them only

struct Case {
  tightbvh::ModelPtr model;
  std::vector<Vec3> points;
  Triangles triangles;
  std::unique_ptr<CgalTree> cgal;
  std::vector<double> distances;  // tightbvh's, the reference of the checks
};

// Points of one kind for one mesh, deterministic.
std::vector<Vec3> make_points(const tightbvh::Mesh& mesh, const std::string& kind) {
  std::mt19937_64 rng(42);
  Vec3 lo = mesh.vertices[0], hi = lo;
  for (const Vec3& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 0.01 * (hi - lo).norm() / std::sqrt(3.0));
  std::vector<Vec3> points;
  for (std::size_t i = 0; i < kPoints; ++i) {
    if (kind == "uniform") {
      points.push_back(lo + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(hi - lo));
      continue;
    }
    const auto t = static_cast<std::size_t>(u(rng) * static_cast<double>(mesh.triangles.size())) % mesh.triangles.size();
    const auto [a, b, c] = mesh.corners(t);
    double x = u(rng), y = u(rng);
    if (x + y > 1.0) x = 1.0 - x, y = 1.0 - y;
    points.push_back(a + x * (b - a) + y * (c - a) + Vec3(n(rng), n(rng), n(rng)));
  }
  return points;
}

Case& get_case(const std::string& mesh_name, const std::string& kind) {
  static std::map<std::string, Case> cases;
  const std::string key = mesh_name + "/" + kind;
  if (auto it = cases.find(key); it != cases.end()) return it->second;
  Case& c = cases[key];
  c.model = tightbvh::make_model(tightbvh::load_mesh(std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/" + mesh_name));
  c.points = make_points(c.model->mesh(), kind);
  for (std::uint32_t t = 0; t < c.model->mesh().triangles.size(); ++t) {
    const auto [a, b, p] = c.model->mesh().corners(t);
    c.triangles.emplace_back(Kernel::Point_3(a.x(), a.y(), a.z()), Kernel::Point_3(b.x(), b.y(), b.z()),
                             Kernel::Point_3(p.x(), p.y(), p.z()));
  }
  c.cgal = std::make_unique<CgalTree>(c.triangles.cbegin(), c.triangles.cend());
  c.cgal->accelerate_distance_queries();
  for (const tightbvh::ClosestPoint& r :
       tightbvh::closest_points(*c.model, tightbvh::Pose::identity(), c.points, {.threads = 1}))
    c.distances.push_back(r.distance);
  return c;
}

// A distance that differs from tightbvh's by more than rounding (CGAL's closest point is its own
// construction) is an error.
bool agrees(double got, double want) { return std::abs(got - want) <= 1e-9 * (1.0 + want); }

void tightbvh_closest(benchmark::State& state, const std::string& mesh, const std::string& kind) {
  Case& c = get_case(mesh, kind);
  for (auto _ : state) {
    auto r = tightbvh::closest_points(*c.model, tightbvh::Pose::identity(), c.points, {.threads = 1});
    benchmark::DoNotOptimize(r.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * c.points.size()));
}

void brute_closest(benchmark::State& state, const std::string& mesh, const std::string& kind) {
  Case& c = get_case(mesh, kind);
  const std::vector<Vec3> points(c.points.begin(), c.points.begin() + kBrutePoints);
  std::vector<tightbvh::ClosestPoint> r;
  for (auto _ : state) {
    r = tightbvh::closest_points_brute_force(c.model->mesh(), tightbvh::Pose::identity(), points);
    benchmark::DoNotOptimize(r.data());
  }
  for (std::size_t i = 0; i < points.size(); ++i)
    if (r[i].distance != c.distances[i]) state.SkipWithError("the brute force disagrees with closest_points");
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points.size()));
}

void cgal_closest(benchmark::State& state, const std::string& mesh, const std::string& kind) {
  Case& c = get_case(mesh, kind);
  std::vector<double> d(c.points.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      const Kernel::Point_3 p(c.points[i].x(), c.points[i].y(), c.points[i].z());
      const auto [q, primitive] = c.cgal->closest_point_and_primitive(p);
      d[i] = std::sqrt(CGAL::squared_distance(p, q));
      benchmark::DoNotOptimize(primitive);
    }
  }
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < d.size(); ++i) wrong += agrees(d[i], c.distances[i]) ? 0 : 1;
  if (wrong > 0) state.SkipWithError(("CGAL disagrees on " + std::to_string(wrong) + " points").c_str());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * c.points.size()));
}

[[maybe_unused]] const bool registered = [] {
  for (const char* mesh : kMeshes)
    for (const char* kind : kKinds) {
      const std::string suffix = std::string(mesh) + "/" + kind;
      benchmark::RegisterBenchmark(("ClosestPoints/tightbvh/" + suffix).c_str(), tightbvh_closest, mesh, kind)
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("ClosestPoints/brute/" + suffix).c_str(), brute_closest, mesh, kind)
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("ClosestPoints/cgal/" + suffix).c_str(), cgal_closest, mesh, kind)
          ->Unit(benchmark::kMillisecond);
    }
  return true;
}();

}  // namespace
