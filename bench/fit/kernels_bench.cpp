// Micro-benchmarks of the hot kernels.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "tightbvh/fit.hpp"

namespace {

std::vector<tightbvh::Vec3> random_points(std::size_t n) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> normal;
  std::vector<tightbvh::Vec3> points(n);
  for (auto& p : points) p = tightbvh::Vec3(normal(rng), 2 * normal(rng), 0.5 * normal(rng));
  return points;
}

void BM_FitAabb(benchmark::State& state) {
  const auto points = random_points(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(tightbvh::fit_points(points, {.method = tightbvh::FitMethod::aabb}));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_FitAabb)->Arg(10)->Arg(100)->Arg(1000)->Arg(10000);

}  // namespace
