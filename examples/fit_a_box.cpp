// Fit a box to one mesh with every method and print the volumes (smaller is tighter).
//   fit_a_box [MESH]   (default: the shipped knot)
#include <tightbvh/fit.hpp>
#include <tightbvh/mesh.hpp>

#include <cstdio>
#include <exception>
#include <vector>

int main(int argc, char** argv) try {
  const char* path = argc > 1 ? argv[1] : TIGHTBVH_SOURCE_DIR "/meshes/knot1.off";
  const tightbvh::Mesh mesh = tightbvh::load_mesh(path);
  for (const char* name : {"aabb", "pca", "pca-vertex", "diameter", "approx", "exact"}) {
    tightbvh::FitOptions options;
    options.method = *tightbvh::parse_fit_method(name);
    const tightbvh::Obb box = tightbvh::fit_points(mesh.vertices, options);
    std::printf("%-10s volume %.6g  half extents %.4g %.4g %.4g\n", name, box.volume(), box.half_extents.x(),
                box.half_extents.y(), box.half_extents.z());
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "fit_a_box: %s\n", e.what());
  return 1;
}
