// Google Benchmark of the point queries (point_query.hpp), one thread each, on shipped closed
// meshes: points per second of
// - closest_points against the brute force over every triangle and against CGAL's AABB_tree
//   (closest_point_and_primitive, CGAL 5.5), for points uniform in the mesh's bounding box and
//   points near the surface (within 1% of the diagonal);
// - contains and signed_distance against CGAL's Side_of_triangle_mesh (exact predicates: Epick)
//   with, for the signed distance, the AABB_tree's closest point, on those points and on an
//   axis-aligned grid through the bounding box (where one ray's parity meets edges and vertices).
// The answers are checked in the same run against tightbvh's (exact for the sides: classify_point):
// a distance that disagrees makes the benchmark an error instead of a time; wrong sides are
// counted and reported (counter wrong_sides). CGAL stays in this one translation unit.
#include <benchmark/benchmark.h>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>

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
using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Epick::Point_3>;
using CgalSide = CGAL::Side_of_triangle_mesh<SurfaceMesh, Epick>;

const char* const kMeshes[] = {"elephant.off", "fandisk.off", "camel.off"};
const char* const kKinds[] = {"uniform", "near"};
const char* const kSideKinds[] = {"uniform", "near", "grid"};
constexpr std::size_t kPoints = 20000;
constexpr std::size_t kBrutePoints = 200;  // the brute force runs on the first of them only

struct Case {
  tightbvh::ModelPtr model;
  std::vector<Vec3> points;
  Triangles triangles;
  std::unique_ptr<CgalTree> cgal;
  std::vector<double> distances;  // tightbvh's, the reference of the checks
  SurfaceMesh surface;            // for CGAL's Side_of_triangle_mesh (built on first use)
  std::unique_ptr<CgalSide> side;
  std::vector<tightbvh::Containment> sides;  // tightbvh's exact sides (built on first use)
};

// Points of one kind for one mesh, deterministic.
std::vector<Vec3> make_points(const tightbvh::Mesh& mesh, const std::string& kind) {
  std::mt19937_64 rng(42);
  Vec3 lo = mesh.vertices[0], hi = lo;
  for (const Vec3& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 0.01 * (hi - lo).norm() / std::sqrt(3.0));
  std::vector<Vec3> points;
  if (kind == "grid") {  // about kPoints points, the bounding box's faces included
    const int n = static_cast<int>(std::cbrt(static_cast<double>(kPoints)));
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
          points.push_back(lo + Vec3(i, j, k).cwiseProduct(hi - lo) / static_cast<double>(n - 1));
    return points;
  }
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

// The case with CGAL's side oracle and tightbvh's exact sides.
Case& get_side_case(const std::string& mesh_name, const std::string& kind) {
  Case& c = get_case(mesh_name, kind);
  if (c.side) return c;
  const tightbvh::Mesh& mesh = c.model->mesh();
  std::vector<SurfaceMesh::Vertex_index> vertices;
  for (const Vec3& v : mesh.vertices) vertices.push_back(c.surface.add_vertex(Epick::Point_3(v.x(), v.y(), v.z())));
  for (const auto& t : mesh.triangles) c.surface.add_face(vertices[t[0]], vertices[t[1]], vertices[t[2]]);
  c.side = std::make_unique<CgalSide>(c.surface);
  c.sides = tightbvh::contains(*c.model, tightbvh::Pose::identity(), c.points, 1);
  return c;
}

tightbvh::Containment from_cgal(CGAL::Bounded_side side) {
  return side == CGAL::ON_BOUNDED_SIDE ? tightbvh::Containment::inside
         : side == CGAL::ON_BOUNDARY   ? tightbvh::Containment::on_surface
                                       : tightbvh::Containment::outside;
}

// The side a signed distance gives (0 on the surface).
tightbvh::Containment side_of(double signed_distance) {
  return signed_distance < 0.0   ? tightbvh::Containment::inside
         : signed_distance > 0.0 ? tightbvh::Containment::outside
                                 : tightbvh::Containment::on_surface;
}

void report_sides(benchmark::State& state, const Case& c, const std::vector<tightbvh::Containment>& got) {
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < got.size(); ++i) wrong += got[i] == c.sides[i] ? 0 : 1;
  state.counters["wrong_sides"] = static_cast<double>(wrong);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * c.points.size()));
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

void tightbvh_contains(benchmark::State& state, const std::string& mesh, const std::string& kind) {
  Case& c = get_side_case(mesh, kind);
  std::vector<tightbvh::Containment> r;
  for (auto _ : state) {
    r = tightbvh::contains(*c.model, tightbvh::Pose::identity(), c.points, 1);
    benchmark::DoNotOptimize(r.data());
  }
  report_sides(state, c, r);
}

void cgal_contains(benchmark::State& state, const std::string& mesh, const std::string& kind) {
  Case& c = get_side_case(mesh, kind);
  std::vector<tightbvh::Containment> r(c.points.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < c.points.size(); ++i)
      r[i] = from_cgal((*c.side)(Epick::Point_3(c.points[i].x(), c.points[i].y(), c.points[i].z())));
    benchmark::DoNotOptimize(r.data());
  }
  report_sides(state, c, r);
}

void tightbvh_signed(benchmark::State& state, const std::string& mesh, const std::string& kind) {
  Case& c = get_side_case(mesh, kind);
  std::vector<tightbvh::ClosestPoint> r;
  for (auto _ : state) {
    r = tightbvh::signed_distance(*c.model, tightbvh::Pose::identity(), c.points, {.threads = 1});
    benchmark::DoNotOptimize(r.data());
  }
  std::vector<tightbvh::Containment> sides;
  for (std::size_t i = 0; i < r.size(); ++i) {
    // 0 exactly on the surface (classify_point), else the unsigned distance.
    const double want = c.sides[i] == tightbvh::Containment::on_surface ? 0.0 : c.distances[i];
    if (std::abs(r[i].distance) != want) state.SkipWithError("signed_distance disagrees with closest_points");
    sides.push_back(side_of(r[i].distance));
  }
  report_sides(state, c, sides);
}

// CGAL's signed distance: the AABB_tree's closest point and Side_of_triangle_mesh's side.
void cgal_signed(benchmark::State& state, const std::string& mesh, const std::string& kind) {
  Case& c = get_side_case(mesh, kind);
  std::vector<double> d(c.points.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      const Kernel::Point_3 p(c.points[i].x(), c.points[i].y(), c.points[i].z());
      const double unsigned_distance = std::sqrt(CGAL::squared_distance(p, c.cgal->closest_point(p)));
      const CGAL::Bounded_side side = (*c.side)(Epick::Point_3(p.x(), p.y(), p.z()));
      d[i] = side == CGAL::ON_BOUNDED_SIDE ? -unsigned_distance : side == CGAL::ON_BOUNDARY ? 0.0 : unsigned_distance;
    }
    benchmark::DoNotOptimize(d.data());
  }
  std::size_t wrong = 0;
  std::vector<tightbvh::Containment> sides;
  for (std::size_t i = 0; i < d.size(); ++i) {
    wrong += agrees(std::abs(d[i]), c.distances[i]) ? 0 : 1;
    sides.push_back(side_of(d[i]));
  }
  if (wrong > 0) state.SkipWithError(("CGAL's distance disagrees on " + std::to_string(wrong) + " points").c_str());
  report_sides(state, c, sides);
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
  for (const char* mesh : kMeshes)
    for (const char* kind : kSideKinds) {
      const std::string suffix = std::string(mesh) + "/" + kind;
      benchmark::RegisterBenchmark(("Contains/tightbvh/" + suffix).c_str(), tightbvh_contains, mesh, kind)
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("Contains/cgal/" + suffix).c_str(), cgal_contains, mesh, kind)
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("SignedDistance/tightbvh/" + suffix).c_str(), tightbvh_signed, mesh, kind)
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("SignedDistance/cgal/" + suffix).c_str(), cgal_signed, mesh, kind)
          ->Unit(benchmark::kMillisecond);
    }
  return true;
}();

}  // namespace
