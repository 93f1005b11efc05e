// A deforming mesh: twist A a little more every frame, refit its tree (same topology, boxes fitted
// again to the moved triangles: much cheaper than a new build), and collide it against B.
// Each frame's pairs are checked against a tree built from scratch; exit code 1 if they differ.
//   refit_deforming_mesh [MESH_A MESH_B]   (defaults: the shipped elephant and knot)
#include <tightbvh/build.hpp>
#include <tightbvh/collide.hpp>
#include <tightbvh/mesh.hpp>
#include <tightbvh/refit.hpp>

#include <cmath>
#include <cstdio>
#include <exception>

int main(int argc, char** argv) try {
  const char* path_a = argc > 2 ? argv[1] : TIGHTBVH_SOURCE_DIR "/meshes/elephant.off";
  const char* path_b = argc > 2 ? argv[2] : TIGHTBVH_SOURCE_DIR "/meshes/knot1.off";
  const tightbvh::Mesh rest = tightbvh::load_mesh(path_a);  // A's undeformed shape
  const tightbvh::Mesh b = tightbvh::load_mesh(path_b);
  tightbvh::Mesh a = rest;  // deformed every frame: the same triangles, moved vertices
  // pca is refit's default fitter (its fast path); building with it keeps frame 0 as built.
  const tightbvh::BuildOptions options{.fitter = tightbvh::FitMethod::pca};
  tightbvh::Tree tree_a = tightbvh::build(a, options);
  const tightbvh::Tree tree_b = tightbvh::build(b, {});

  tightbvh::Pose pose_b;  // B in A's frame, fixed; A moves by deforming
  pose_b.translation = tightbvh::Vec3(0.2, 0.0, 0.0);
  const tightbvh::QueryOptions all_pairs{.mode = tightbvh::QueryMode::all_pairs};
  const tightbvh::Vec3 center = tightbvh::check_mesh(rest).bounds.center();

  constexpr int kFrames = 8;
  for (int frame = 0; frame < kFrames; ++frame) {
    // Twist about the vertical axis through A's center: the turn grows with the height.
    const double twist = 1.5 * frame / (kFrames - 1);  // radians per unit of height
    for (std::size_t i = 0; i < rest.vertices.size(); ++i) {
      const tightbvh::Vec3 p = rest.vertices[i] - center;
      const double angle = twist * p.y(), c = std::cos(angle), s = std::sin(angle);
      a.vertices[i] = center + tightbvh::Vec3(c * p.x() + s * p.z(), p.y(), -s * p.x() + c * p.z());
    }
    tightbvh::refit(tree_a, a);  // every box fitted again; throws if the triangles changed
    const tightbvh::QueryResult result = tightbvh::collide(tree_a, a, {}, tree_b, b, pose_b, all_pairs);

    // The check: a tree built from scratch on this frame's mesh finds exactly the same pairs.
    const tightbvh::Tree fresh_tree = tightbvh::build(a, options);
    const tightbvh::QueryResult fresh = tightbvh::collide(fresh_tree, a, {}, tree_b, b, pose_b, all_pairs);
    std::printf("frame %d: twist %.2f rad, %zu touching pairs, %llu box tests (fresh build: %llu)\n", frame, twist,
                result.pairs.size(), static_cast<unsigned long long>(result.stats.box_tests),
                static_cast<unsigned long long>(fresh.stats.box_tests));
    if (result.pairs != fresh.pairs) {
      std::fprintf(stderr, "refit_deforming_mesh: frame %d: the refitted tree's pairs differ from a fresh build's\n",
                   frame);
      return 1;
    }
  }
  std::printf("refitted tree agrees with fresh builds on all %d frames\n", kFrames);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "refit_deforming_mesh: %s\n", e.what());
  return 1;
}
