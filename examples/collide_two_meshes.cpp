// Load two meshes as models (a mesh, its tree and the tree's wide float nodes), ask which
// triangle pairs touch with B moved, print them.
//   collide_two_meshes [MESH_A MESH_B]   (defaults: the shipped elephant and knot)
#include <tightbvh/mesh.hpp>
#include <tightbvh/model.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) try {
  const char* path_a = argc > 2 ? argv[1] : TIGHTBVH_SOURCE_DIR "/meshes/elephant.off";
  const char* path_b = argc > 2 ? argv[2] : TIGHTBVH_SOURCE_DIR "/meshes/knot1.off";
  // load_mesh and Model throw InputError on bad input (a malformed file, NaN, bad indices).
  const tightbvh::Model a(tightbvh::load_mesh(path_a), {.fitter = tightbvh::FitMethod::approx});
  const tightbvh::Model b(tightbvh::load_mesh(path_b));  // the default fitter: auto

  tightbvh::Pose pose_b;  // B in A's frame
  pose_b.translation = tightbvh::Vec3(0.2, 0.0, 0.0);
  const tightbvh::QueryResult result =
      tightbvh::collide(a, tightbvh::Pose{}, b, pose_b, {.mode = tightbvh::QueryMode::all_pairs});

  std::printf("%s: %zu touching triangle pairs (%llu box tests, %llu triangle tests)\n",
              result.hit ? "hit" : "no hit", result.pairs.size(),
              static_cast<unsigned long long>(result.stats.box_tests),
              static_cast<unsigned long long>(result.stats.triangle_tests));
  for (std::size_t i = 0; i < result.pairs.size() && i < 10; ++i)
    std::printf("  triangle %u of A touches triangle %u of B\n", result.pairs[i].a, result.pairs[i].b);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "collide_two_meshes: %s\n", e.what());
  return 1;
}
