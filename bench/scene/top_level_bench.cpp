// Google Benchmark of the scene's top level alone, the measurement behind its design
// (docs/design-notes/scenes.md): one frame moves a share of n boxes by a small step, brings the
// structure up to date and lists the box pairs that overlap. Strategies:
//   RefitWalk    refit the median-split tree, then one self walk of the whole tree
//   RebuildWalk  rebuild the tree, then one self walk
//   RefitUpdate  refit, then update last frame's pairs from the moved boxes only: drop their pairs
//                and walk the tree once per moved box (the scene's pair cache)
//   Dynamic      a dynamic tree with fat boxes (dynamic_tree.hpp: Bullet's btDbvt, FCL's manager),
//                a self walk over the fat boxes filtered by the exact ones
// Args: objects, percent moved per frame. Counter: pairs per frame (equal for every strategy).
//
//   build/bin/tightbvh-scene-bench --benchmark_filter=TopLevel
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "dynamic_tree.hpp"
#include "scene/top_tree.hpp"

namespace {

using namespace tightbvh;
using scene_detail::TopTree;

enum Strategy { kRefitWalk, kRebuildWalk, kRefitUpdate, kDynamic };

// n boxes of side 0.5 to 1, about three per cube of side 2 (as tightbvh-scene-bench's BM_Frame).
struct Boxes {
  std::vector<Aabb> boxes;
  std::mt19937_64 rng{1};
  explicit Boxes(std::size_t n) {
    const double extent = 2.0 * std::cbrt(static_cast<double>(n) / 3.0);
    std::uniform_real_distribution<double> at(0.0, extent), side(0.5, 1.0);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 c(at(rng), at(rng), at(rng));
      const Vec3 h = 0.5 * Vec3(side(rng), side(rng), side(rng));
      boxes.push_back({c - h, c + h});
    }
  }
  // Moves `count` random boxes by up to 0.05 per axis; their indices go to `moved` (distinct).
  void step(std::size_t count, std::vector<std::uint32_t>& moved, std::vector<char>& is_moved) {
    std::uniform_real_distribution<double> d(-0.05, 0.05);
    moved.clear();
    while (moved.size() < count) {
      const auto i = static_cast<std::uint32_t>(rng() % boxes.size());
      if (is_moved[i]) continue;
      is_moved[i] = 1;
      moved.push_back(i);
      const Vec3 v(d(rng), d(rng), d(rng));
      boxes[i].min += v;
      boxes[i].max += v;
    }
  }
};

using Pair = std::pair<std::uint32_t, std::uint32_t>;

void walk(const TopTree& tree, std::vector<Pair>& pairs) {
  pairs.clear();
  scene_detail::close_pairs(tree, tree, true, 0.0, [&](std::uint32_t i, std::uint32_t j) { pairs.emplace_back(i, j); });
}

void BM_TopLevel(benchmark::State& state) {
  const auto strategy = static_cast<Strategy>(state.range(0));
  const auto n = static_cast<std::size_t>(state.range(1));
  const auto count = std::max<std::size_t>(1, n * static_cast<std::size_t>(state.range(2)) / 100);
  Boxes b(n);
  TopTree tree;
  tree.build(b.boxes);
  bench::DynamicTree dynamic(0.1);
  for (std::uint32_t i = 0; i < n; ++i) dynamic.insert(i, b.boxes[i]);
  std::vector<Pair> pairs;
  walk(tree, pairs);
  std::vector<std::uint32_t> moved;
  std::vector<char> is_moved(n, 0);
  std::size_t total = 0;
  for (auto _ : state) {
    b.step(count, moved, is_moved);
    switch (strategy) {
      case kRefitWalk:
        tree.refit(b.boxes);
        walk(tree, pairs);
        break;
      case kRebuildWalk:
        tree.build(b.boxes);
        walk(tree, pairs);
        break;
      case kRefitUpdate:
        tree.refit(b.boxes);
        std::erase_if(pairs, [&](const Pair& p) { return is_moved[p.first] || is_moved[p.second]; });
        for (const std::uint32_t m : moved)
          scene_detail::close_items(tree, b.boxes[m], 0.0, [&](std::uint32_t o) {
            if (o != m && (!is_moved[o] || o > m)) pairs.emplace_back(m, o);
          });
        break;
      case kDynamic:
        for (const std::uint32_t m : moved) dynamic.move(m, b.boxes[m]);
        pairs.clear();
        dynamic.self_pairs(0.0, [&](std::uint32_t i, std::uint32_t j) {
          if (scene_detail::boxes_within(b.boxes[i], b.boxes[j], 0.0)) pairs.emplace_back(i, j);
        });
        break;
    }
    for (const std::uint32_t m : moved) is_moved[m] = 0;
    total += pairs.size();
    benchmark::DoNotOptimize(pairs.data());
  }
  state.counters["pairs"] = static_cast<double>(total) / static_cast<double>(state.iterations());
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TopLevel)
    ->ArgNames({"strategy", "objects", "percent"})
    ->ArgsProduct({{kRefitWalk, kRebuildWalk, kRefitUpdate, kDynamic}, {10, 100, 1000, 10000}, {1, 10, 25, 100}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
