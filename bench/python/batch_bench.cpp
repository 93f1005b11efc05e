// tightbvh-batch-bench: the C++ side of collide_batch_bench.py. Loads two meshes, their saved
// trees and a pose file (one "r00 r01 r02 r10 r11 r12 r20 r21 r22 tx ty tz" per line, B in A's
// frame), then times collide_batch over all poses `--reps` times and prints JSON: per repetition
// the wall-clock and the calling thread's CPU seconds, and the answers (to compare with Python's).
//   tightbvh-batch-bench MESH_A TREE_A MESH_B TREE_B POSES [--reps R] [--threads T] [--all-pairs]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include "../thread_clock.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/pose_text.hpp"
#include "tightbvh/serialize.hpp"

namespace {

using namespace tightbvh;

std::vector<Pose> read_poses(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  std::vector<Pose> poses;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') poses.push_back(parse_pose(line));  // tightbvh-bench --write-poses
  return poses;
}

struct Args {
  std::string mesh_a, tree_a, mesh_b, tree_b, poses;
  int reps = 5;
  unsigned threads = 1;
  bool all_pairs = false;
};

Args parse_args(int argc, char** argv) {
  Args args;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--reps" && i + 1 < argc)
      args.reps = std::atoi(argv[++i]);
    else if (arg == "--threads" && i + 1 < argc)
      args.threads = static_cast<unsigned>(std::atoi(argv[++i]));
    else if (arg == "--all-pairs")
      args.all_pairs = true;
    else
      positional.push_back(arg);
  }
  if (positional.size() != 5 || args.reps < 1)
    throw InputError(
        "usage: tightbvh-batch-bench MESH_A TREE_A MESH_B TREE_B POSES [--reps R] [--threads T] [--all-pairs]");
  args.mesh_a = positional[0], args.tree_a = positional[1], args.mesh_b = positional[2];
  args.tree_b = positional[3], args.poses = positional[4];
  return args;
}

}  // namespace

int main(int argc, char** argv) try {
  const Args args = parse_args(argc, argv);
  const Mesh a = load_mesh(args.mesh_a), b = load_mesh(args.mesh_b);
  const Tree tree_a = load_tree(args.tree_a), tree_b = load_tree(args.tree_b);
  const std::vector<Pose> poses = read_poses(args.poses);
  const QueryOptions options{.mode = args.all_pairs ? QueryMode::all_pairs : QueryMode::first_hit};
  std::string wall = "[", cpu = "[";
  std::size_t hits = 0, pairs = 0;
  for (int rep = 0; rep < args.reps; ++rep) {
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = bench_support::thread_seconds();
    hits = pairs = 0;
    {  // freeing the results is timed too, as it is on the Python side
      const std::vector<QueryResult> results =
          collide_batch(tree_a, a, Pose{}, tree_b, b, poses, options, args.threads);
      for (const QueryResult& r : results) hits += r.hit, pairs += r.pairs.size();
    }
    const double cpu_seconds = bench_support::thread_seconds() - cpu_start;
    const double wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    char text[64];
    std::snprintf(text, sizeof text, "%s%.9g", rep ? ", " : "", wall_seconds);
    wall += text;
    std::snprintf(text, sizeof text, "%s%.9g", rep ? ", " : "", cpu_seconds);
    cpu += text;
  }
  std::printf("{\"poses\": %zu, \"hits\": %zu, \"pairs\": %zu, \"wall_seconds\": %s], \"cpu_seconds\": %s]}\n",
              poses.size(), hits, pairs, wall.c_str(), cpu.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "tightbvh-batch-bench: %s\n", e.what());
  return 1;
}
