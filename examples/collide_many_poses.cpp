// Many poses of B at once: one collide_batch (and one distance_batch) call spreads the queries
// over threads and returns the results in pose order, the same for any thread count. Checked
// against one single query per pose; exit code 1 if any differs.
//   collide_many_poses [MESH_A MESH_B]   (defaults: the shipped elephant and knot)
#include <tightbvh/build.hpp>
#include <tightbvh/collide.hpp>
#include <tightbvh/distance.hpp>
#include <tightbvh/mesh.hpp>

#include <cmath>
#include <cstdio>
#include <exception>
#include <vector>

int main(int argc, char** argv) try {
  const char* path_a = argc > 2 ? argv[1] : TIGHTBVH_SOURCE_DIR "/meshes/elephant.off";
  const char* path_b = argc > 2 ? argv[2] : TIGHTBVH_SOURCE_DIR "/meshes/knot1.off";
  const tightbvh::Mesh a = tightbvh::load_mesh(path_a);
  const tightbvh::Mesh b = tightbvh::load_mesh(path_b);
  const tightbvh::Tree tree_a = tightbvh::build(a, {}), tree_b = tightbvh::build(b, {});

  // 64 poses of B on a widening spiral around A, turning about y as it goes: near ones touch, far ones not.
  std::vector<tightbvh::Pose> poses(64);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const double angle = 0.4 * static_cast<double>(i), radius = 1.5 * static_cast<double>(i) / poses.size();
    poses[i].rotation = Eigen::AngleAxisd(angle, tightbvh::Vec3::UnitY()).toRotationMatrix();
    poses[i].translation = tightbvh::Vec3(radius * std::cos(angle), 0.0, radius * std::sin(angle));
  }

  // One call each, on 2 threads (0 would take every core). A stays at the identity.
  const unsigned threads = 2;
  const tightbvh::QueryOptions all_pairs{.mode = tightbvh::QueryMode::all_pairs};
  const std::vector<tightbvh::QueryResult> hits =
      tightbvh::collide_batch(tree_a, a, {}, tree_b, b, poses, all_pairs, threads);
  const std::vector<tightbvh::DistanceResult> gaps =
      tightbvh::distance_batch(tree_a, a, {}, tree_b, b, poses, {}, threads);

  // The check: result i is the answer of a single query at pose i.
  std::size_t touching = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const tightbvh::QueryResult one = tightbvh::collide(tree_a, a, {}, tree_b, b, poses[i], all_pairs);
    const tightbvh::DistanceResult gap = tightbvh::distance(tree_a, a, {}, tree_b, b, poses[i]);
    if (hits[i].pairs != one.pairs || gaps[i].distance != gap.distance || hits[i].hit != (gap.distance == 0.0)) {
      std::fprintf(stderr, "collide_many_poses: pose %zu: the batch answer differs from the single query\n", i);
      return 1;
    }
    touching += hits[i].hit;
    if (i % 16 == 0)
      std::printf("pose %2zu: %s, %zu pairs, distance %.6f\n", i, hits[i].hit ? "hit" : "no hit", hits[i].pairs.size(),
                  gaps[i].distance);
  }
  std::printf("%zu poses on %u threads: %zu touching, %zu apart, equal to %zu single queries\n", poses.size(), threads,
              touching, poses.size() - touching, poses.size());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "collide_many_poses: %s\n", e.what());
  return 1;
}
