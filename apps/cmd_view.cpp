// tightbvh view MESH [--fitter F ...] [--level L] [-o DIR]: a self-contained HTML page showing
// the mesh with the boxes of one tree level drawn over it, one panel per fitter (default: pca
// next to the default fitter, so the difference in tightness is visible), the level selectable
// in the page, each level's sum of box volumes printed (apps/view/).
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "names.hpp"
#include "tightbvh/build.hpp"
#include "view/page.hpp"
#include "view/scene.hpp"

namespace tightbvh::cli {
namespace {

struct ViewArgs {
  std::string mesh, output = "tightbvh-view";
  std::vector<std::string> fitters{"pca", to_string(BuildOptions{}.fitter)};
  std::size_t level = 3;  // without --level: at most the trees' depth
  bool level_given = false;
  std::uint32_t leaf_size = 1;
  unsigned threads = 0;
};

[[nodiscard]] std::vector<Fitter> parse_fitters(const std::vector<std::string>& names) {
  std::vector<Fitter> fitters;
  for (const std::string& name : names) {
    const auto fitter = parse_fitter(name);
    if (!fitter) throw InputError("--fitter: unknown fitter '" + name + "' (" + one_of(fitter_names()) + ")");
    fitters.push_back(*fitter);
  }
  return fitters;
}

void run_view(const ViewArgs& args) {
  const std::vector<Fitter> fitters = parse_fitters(args.fitters);
  const Mesh mesh = load_mesh(args.mesh);
  std::vector<BuildResult> built;
  std::size_t depth_max = 0;
  for (const Fitter& fitter : fitters) {
    BuildOptions options;
    options.fitter = fitter;
    options.leaf_size = args.leaf_size;
    options.threads = args.threads;
    built.push_back(build_with_stats(mesh, options));
    depth_max = std::max(depth_max, built.back().stats.tree.depth_max);
  }
  const std::size_t level = args.level_given ? args.level : std::min(args.level, depth_max);
  if (level > depth_max)
    throw InputError("--level " + std::to_string(args.level) + " is deeper than the trees (max depth " +
                     std::to_string(depth_max) + ")");
  nlohmann::json trees = nlohmann::json::array();
  for (std::size_t i = 0; i < fitters.size(); ++i)
    trees.push_back(view::tree_json(to_string(fitters[i]), built[i], level));
  const std::string title = std::filesystem::path(args.mesh).filename().string() + ": tree boxes, " +
                            std::to_string(mesh.triangles.size()) + " triangles";
  const auto page = view::write_page(args.output, view::trees_scene(title, mesh, level, std::move(trees)));
  std::cout << "wrote " << page.string() << " (" << fitters.size() << " fitters, levels 0.." << depth_max << ", level "
            << level << " shown first)\n";
}

}  // namespace

void add_view_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("view", "write an HTML page showing the boxes of a tree level over the mesh");
  auto args = std::make_shared<ViewArgs>();
  cmd->add_option("mesh", args->mesh, "mesh file (OBJ, OFF, STL, PLY, ...)")->required();
  cmd->add_option("--fitter", args->fitters, "fitters side by side (repeat the option): " + choices(fitter_names()))
      ->allow_extra_args(false)  // one name per --fitter: the mesh never reads as a fitter
      ->capture_default_str();
  cmd->add_option("--level", args->level, "tree level shown first (root: 0)")->capture_default_str();
  cmd->add_option("--leaf-size", args->leaf_size, "max triangles per leaf")
      ->check(positive_number())
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "build threads (0: all cores)")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "directory for index.html")->capture_default_str();
  cmd->footer("Example:\n  tightbvh view meshes/knot1.off --fitter pca --fitter approx --level 4 -o knot1-view");
  cmd->callback([args, cmd] {
    args->level_given = cmd->count("--level") > 0;
    run_view(*args);
  });
}

}  // namespace tightbvh::cli
