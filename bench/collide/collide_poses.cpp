// A small driver for instruction counts (callgrind) and A/B checks of collide(): builds the trees
// of two meshes, then runs collide() on every pose of a pose file (tightbvh-bench --write-poses)
// and prints the totals, a hash of every answer (hit, pairs, box and triangle tests), so that two
// builds can be compared for identical results, and the queries' thread CPU time (REPEATS passes).
// With `models`, the queries are collide() on two Models (the wide descent) instead of the trees.
// Only run_queries() is meant to be counted:
//   valgrind --tool=callgrind --toggle-collect='*run_queries*' \
//       build/bin/tightbvh-collide-poses meshes/elephant.off meshes/knot1.off poses.txt approx first_hit
#include <cstdint>
#include <ctime>
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/pose_text.hpp"

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
    std::fprintf(stderr, "usage: %s MESH_A MESH_B POSES FITTER first_hit|all_pairs [REPEATS [trees|models]]\n", argv[0]);
    return 2;
  }
  const Mesh ma = load_mesh(argv[1]), mb = load_mesh(argv[2]);
  const std::vector<Pose> poses = read_poses(argv[3]);
  const auto fitter = parse_fitter(argv[4]);
  if (!fitter) throw InputError(std::string("unknown fitter ") + argv[4]);
  const std::string mode_name = argv[5];
  const QueryMode mode = mode_name == "all_pairs" ? QueryMode::all_pairs : QueryMode::first_hit;
  const int repeats = argc > 6 ? std::stoi(argv[6]) : 1;
  BuildOptions options;
  options.fitter = *fitter;
  options.threads = 1;
  const Tree ta = build(ma, options), tb = build(mb, options);
  const std::string target = argc > 7 ? argv[7] : "trees";
  if (target != "trees" && target != "models") throw InputError("expected trees or models, got " + target);
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
  const Totals t = run_queries(ta, ma, tb, mb, poses, mode, repeats, workspace, pa, pb);
  const double seconds = cpu() - start;
  std::printf("poses %zu mode %s hits %llu pairs %llu box_tests %llu triangle_tests %llu hash %016llx cpu_s %.4f\n",
              poses.size(), mode_name.c_str(), (unsigned long long)t.hits, (unsigned long long)t.pairs,
              (unsigned long long)t.box_tests, (unsigned long long)t.triangle_tests, (unsigned long long)t.hash, seconds);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "tightbvh-collide-poses: %s\n", e.what());
  return 1;
}
