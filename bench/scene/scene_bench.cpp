// Google Benchmark of the scene's top level: one frame = move a fraction of the objects
// (set_poses), then collide(scene). n objects (small spheres sharing 10 models) in a cube sized
// so that each object has a few neighbours; args: objects, percent moved per frame. Counters per
// frame: rebuilds and refits of the top-level tree (Scene::tree_stats), touching pairs. The hook
// for comparing top-level schemes (refit/rebuild against an incremental tree) on the same frames.
//
//   build/bin/tightbvh-scene-bench --benchmark_filter=Frame
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "tightbvh/model.hpp"
#include "tightbvh/scene.hpp"
#include "scene/scene_fixtures.hpp"  // uv_sphere, random_pose: the scene tests' shapes and poses

namespace {

using namespace tightbvh;
using query_test::uv_sphere;
using scene_test::random_pose;

void BM_Frame(benchmark::State& state) {
  const auto objects = static_cast<std::size_t>(state.range(0));
  const double moved_fraction = static_cast<double>(state.range(1)) / 100.0;
  std::vector<ModelPtr> models;
  for (int i = 0; i < 10; ++i) models.push_back(make_model(uv_sphere(6 + i, 8 + i, 0.5)));
  // About 3 objects of diameter 1 per cube of side 2.
  const double extent = 2.0 * std::cbrt(static_cast<double>(objects) / 3.0);
  std::mt19937_64 rng(1);
  Scene scene;
  std::vector<ObjectId> ids;
  for (std::size_t i = 0; i < objects; ++i) ids.push_back(scene.add(models[i % 10], random_pose(rng, extent)));
  const auto moved = std::max<std::size_t>(1, static_cast<std::size_t>(moved_fraction * static_cast<double>(objects)));
  std::vector<ObjectId> which(moved);
  std::vector<Pose> poses(moved);
  const SceneTreeStats before = scene.tree_stats();
  std::size_t pairs = 0;
  std::uniform_real_distribution<double> step(-0.05, 0.05);
  for (auto _ : state) {
    // Small steps (a simulation's frame): each moved object shifts by up to 0.05.
    for (std::size_t k = 0; k < moved; ++k) {
      which[k] = ids[rng() % ids.size()];
      poses[k] = scene.object(which[k]).pose;
      poses[k].translation += Vec3(step(rng), step(rng), step(rng));
    }
    scene.set_poses(which, poses);
    pairs += collide(scene).size();
  }
  const SceneTreeStats after = scene.tree_stats();
  const auto frames = static_cast<double>(state.iterations());
  state.counters["rebuilds"] = static_cast<double>(after.rebuilds - before.rebuilds) / frames;
  state.counters["refits"] = static_cast<double>(after.refits - before.refits) / frames;
  state.counters["pairs"] = static_cast<double>(pairs) / frames;
  state.counters["frames/s"] = benchmark::Counter(frames, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Frame)->ArgsProduct({{10, 100, 1000, 10000}, {10, 100}})->Unit(benchmark::kMicrosecond);

}  // namespace
