// The user guide's trees: choose a fitter, split and leaf size, validate, save and load a tree,
// and what a bad input throws. Run by the tests (ctest guide_trees).
#include <tightbvh/build.hpp>
#include <tightbvh/error.hpp>
#include <tightbvh/mesh.hpp>
#include <tightbvh/serialize.hpp>
#include <tightbvh/validate_tree.hpp>

#include <cstdio>
#include <filesystem>

int main() {
  const tightbvh::Mesh mesh = tightbvh::load_mesh(TIGHTBVH_SOURCE_DIR "/meshes/knot1.off");

  // The default: auto (approx near the root, cheaper fitters on smaller nodes), RAPID's split,
  // one triangle per leaf, all cores. The same tree bit for bit for any thread count.
  const tightbvh::Tree tree = tightbvh::build(mesh);

  // Options spelled out: the tightest practical boxes, a balanced split, small leaves, two threads.
  const tightbvh::BuildResult built = tightbvh::build_with_stats(mesh, {.fitter = tightbvh::FitMethod::approx,
                                                                        .split = tightbvh::SplitMethod::median,
                                                                        .leaf_size = 4,
                                                                        .threads = 2});
  std::printf("approx tree: %zu nodes, sum of box volumes %.4f, built in %.3f s\n", built.stats.tree.nodes,
              built.stats.tree.sum_volume, built.stats.seconds);

  // Every box contains its triangles, the leaves partition the mesh.
  const tightbvh::TreeCheck check = tightbvh::validate(tree, mesh);
  std::printf("default tree valid: %s\n", check.ok() ? "yes" : check.summary().c_str());

  // Save and load (versioned, checksummed; a damaged file is an InputError naming it).
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "tightbvh_guide_knot1.tree";
  tightbvh::save_tree(tree, file);
  const tightbvh::Tree loaded = tightbvh::load_tree(file);
  std::printf("loaded %zu nodes\n", loaded.nodes.size());
  std::filesystem::remove(file);

  // Bad input throws tightbvh::InputError, whose message names the file, mesh or option.
  try {
    const tightbvh::Tree bad = tightbvh::build(mesh, {.leaf_size = 0});
  } catch (const tightbvh::InputError& e) {
    std::printf("InputError: %s\n", e.what());
  }
  return 0;
}
