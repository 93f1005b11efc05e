// A small driver for instruction counts (callgrind) and A/B checks of collide(): builds the trees
// of two meshes, then runs collide() on every pose of a pose file (tightbvh-bench --write-poses)
// and prints the totals, a hash of every answer (hit, pairs, box and triangle tests), so that two
// builds can be compared for identical results, and the queries' thread CPU time (REPEATS passes).
// With `models`, the queries are collide() on two Models (the wide descent) instead of the trees.
// Mode `distance` runs distance() instead (hash of the distances; box_tests and triangle_tests
// are its node_pairs and triangle_pairs, hits the poses at distance 0); target `wide` runs the
// search over wide nodes (query_detail::distance_wide, docs/design-notes/query-core.md, "distance
// on the wide nodes") instead of distance() on the models.
// Only run_queries() is meant to be counted:
//   valgrind --tool=callgrind --toggle-collect='*run_queries*' \
//       build/bin/tightbvh-collide-poses meshes/elephant.off meshes/knot1.off poses.txt approx first_hit
#include <bit>
#include <cstdint>
#include <ctime>
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/distance.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/pose_text.hpp"
#include "collide/wide_collide.hpp"
#include "collide/wide_nodes.hpp"

namespace {

using namespace tightbvh;

std::vector<Pose> read_poses(const char* path) {
  std::ifstream in(path);
  if (!in) throw InputError(std::string(path) + ": cannot open");
  std::vector<Pose> poses;
  for (std::string line; std::getline(in, line);) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    if (line.find_first_not_of(" \t\r") != std::string::npos) poses.push_back(parse_pose(line));
  }
  return poses;
}

struct Totals {
  std::uint64_t hits = 0, pairs = 0, box_tests = 0, triangle_tests = 0, hash = 1469598103934665603ull;
  void mix(std::uint64_t v) { hash = (hash ^ v) * 1099511628211ull; }
};

// The wide trees of A and B, for target `wide`.
struct WidePair {
  query_detail::WideTree a, b;
};

[[gnu::noinline]] Totals run_distances(const Tree& ta, const Mesh& ma, const Tree& tb, const Mesh& mb,
                                       const std::vector<Pose>& poses, int repeats, QueryWorkspace& workspace,
                                       const Model* model_a, const Model* model_b, const WidePair* wide) {
  Totals t;
  for (int r = 0; r < repeats; ++r)
    for (const Pose& p : poses) {
      const DistanceResult d =
          wide != nullptr
              ? query_detail::distance_wide(ta, wide->a, ma, Pose::identity(), tb, wide->b, mb, p, {}, workspace)
          : model_a != nullptr ? distance(*model_a, Pose::identity(), *model_b, p, {}, workspace)
                               : distance(ta, ma, Pose::identity(), tb, mb, p, {}, workspace);
      t.hits += d.distance == 0.0;
      t.box_tests += d.stats.node_pairs;
      t.triangle_tests += d.stats.triangle_pairs;
      t.mix(std::bit_cast<std::uint64_t>(d.distance));
    }
  return t;
}

[[gnu::noinline]] Totals run_queries(const Tree& ta, const Mesh& ma, const Tree& tb, const Mesh& mb,
                                     const std::vector<Pose>& poses, QueryMode mode, int repeats,
                                     QueryWorkspace& workspace, const Model* model_a, const Model* model_b) {
  Totals t;
  for (int r = 0; r < repeats; ++r)
    for (const Pose& p : poses) {
      const QueryOptions options{.mode = mode};
      const QueryResult q = model_a != nullptr
                                ? collide(*model_a, Pose::identity(), *model_b, p, options, workspace)
                                : collide(ta, ma, Pose::identity(), tb, mb, p, options, workspace);
      t.hits += q.hit;
      t.pairs += q.pairs.size();
      t.box_tests += q.stats.box_tests;
      t.triangle_tests += q.stats.triangle_tests;
      t.mix(q.hit);
      t.mix(q.stats.box_tests);
      t.mix(q.stats.triangle_tests);
      for (const auto& pr : q.pairs) t.mix((std::uint64_t{pr.a} << 32) | pr.b);
    }
  return t;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 6) {
    std::fprintf(stderr,
                 "usage: %s MESH_A MESH_B POSES FITTER first_hit|all_pairs|distance [REPEATS [trees|models|wide]]\n",
                 argv[0]);
    return 2;
  }
  const Mesh ma = load_mesh(argv[1]), mb = load_mesh(argv[2]);
  const std::vector<Pose> poses = read_poses(argv[3]);
  const auto fitter = parse_fitter(argv[4]);
  if (!fitter) throw InputError(std::string("unknown fitter ") + argv[4]);
  const std::string mode_name = argv[5];
  if (mode_name != "first_hit" && mode_name != "all_pairs" && mode_name != "distance")
    throw InputError("expected first_hit, all_pairs or distance, got " + mode_name);
  const QueryMode mode = mode_name == "all_pairs" ? QueryMode::all_pairs : QueryMode::first_hit;
  const int repeats = argc > 6 ? std::stoi(argv[6]) : 1;
  BuildOptions options;
  options.fitter = *fitter;
  options.threads = 1;
  const Tree ta = build(ma, options), tb = build(mb, options);
  const std::string target = argc > 7 ? argv[7] : "trees";
  if (target != "trees" && target != "models" && target != "wide")
    throw InputError("expected trees, models or wide, got " + target);
  if (target == "wide" && mode_name != "distance") throw InputError("target wide is for mode distance only");
  const WidePair wide{query_detail::build_wide(ta), query_detail::build_wide(tb)};
  const Model model_a(ma, ta), model_b(mb, tb);
  const Model* pa = target == "models" ? &model_a : nullptr;
  const Model* pb = target == "models" ? &model_b : nullptr;
  QueryWorkspace workspace;  // grown by one query first, so that only the queries are counted
  if (!poses.empty()) (void)collide(ta, ma, Pose::identity(), tb, mb, poses[0], {.mode = mode}, workspace);
  const auto cpu = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  };
  const double start = cpu();
  const Totals t = mode_name == "distance" ? run_distances(ta, ma, tb, mb, poses, repeats, workspace, pa, pb,
                                                           target == "wide" ? &wide : nullptr)
                                           : run_queries(ta, ma, tb, mb, poses, mode, repeats, workspace, pa, pb);
  const double seconds = cpu() - start;
  std::printf("poses %zu mode %s hits %llu pairs %llu box_tests %llu triangle_tests %llu hash %016llx cpu_s %.4f\n",
              poses.size(), mode_name.c_str(), (unsigned long long)t.hits, (unsigned long long)t.pairs,
              (unsigned long long)t.box_tests, (unsigned long long)t.triangle_tests, (unsigned long long)t.hash, seconds);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "tightbvh-collide-poses: %s\n", e.what());
  return 1;
}
