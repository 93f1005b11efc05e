// tightbvh build MESH [options]: build a tree, print its statistics, optionally save it and
// write the boxes of one level as an OBJ wireframe.  tightbvh inspect TREE: statistics of a
// saved tree (and, with --mesh, validation against its mesh).
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "names.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/serialize.hpp"
#include "tightbvh/tree_obj.hpp"
#include "tightbvh/validate_tree.hpp"

namespace tightbvh::cli {
namespace {

nlohmann::json stats_json(const TreeStats& s) {
  return {{"nodes", s.nodes},
          {"leaves", s.leaves},
          {"depth", {{"min", s.depth_min}, {"max", s.depth_max}}},
          {"leaf_triangles", {{"min", s.leaf_triangles_min}, {"avg", s.leaf_triangles_avg}, {"max", s.leaf_triangles_max}}},
          {"sum_volume", s.sum_volume},
          {"volume_per_level", s.volume_per_level},
          {"bytes", s.bytes},
          {"bytes_per_triangle", s.bytes_per_triangle}};
}

void print_stats(const TreeStats& s) {
  std::cout << "nodes " << s.nodes << ", leaves " << s.leaves << ", depth " << s.depth_min << ".." << s.depth_max
            << ", triangles per leaf " << s.leaf_triangles_min << "/" << s.leaf_triangles_avg << "/"
            << s.leaf_triangles_max << " (min/avg/max)\n"
            << "sum of box volumes " << s.sum_volume << "\n"
            << "bytes " << s.bytes << " (" << s.bytes_per_triangle << " per triangle)\n"
            << "volume per level:";
  for (const double v : s.volume_per_level) std::cout << ' ' << v;
  std::cout << '\n';
}

struct BuildArgs {
  std::string mesh, output, boxes_obj;
  std::string fitter = to_string(BuildOptions{}.fitter);  // the library's defaults
  std::string split{to_string(BuildOptions{}.split)};
  int grid = 0;
  double epsilon = 0.0;
  std::uint32_t leaf_size = 1;
  unsigned threads = 0;
  std::size_t level = 0;
  bool json = false, validate = false;
};

[[nodiscard]] BuildOptions parse_build_options(const BuildArgs& args, const CLI::App& cmd) {
  BuildOptions options;
  const auto fitter = parse_fitter(args.fitter);
  if (!fitter) throw InputError("--fitter: unknown fitter '" + args.fitter + "' (" + one_of(fitter_names()) + ")");
  options.fitter = *fitter;
  const auto split = parse_split_method(args.split);
  if (!split) throw InputError("--split: unknown split '" + args.split + "' (" + one_of(split_method_names()) + ")");
  options.split = *split;
  if (cmd.count("--grid")) options.fit.grid = args.grid;
  if (cmd.count("--epsilon")) options.fit.epsilon = args.epsilon;
  options.leaf_size = args.leaf_size;
  options.threads = args.threads;
  return options;
}

struct BuildRun {
  std::size_t triangles = 0;
  BuildResult result;
  std::size_t boxes = 0;  // written to --boxes-obj
};

// Builds, then validates, saves and writes the boxes as asked.
[[nodiscard]] BuildRun run_build(const BuildArgs& args, const BuildOptions& options) {
  const Mesh mesh = load_mesh(args.mesh);
  BuildRun run{mesh.triangles.size(), build_with_stats(mesh, options)};
  const Tree& tree = run.result.tree;
  if (args.validate) {
    const TreeCheck check = validate(tree, mesh);
    if (!check.ok()) throw std::runtime_error(args.mesh + ": invalid tree: " + check.errors[0]);
  }
  if (!args.output.empty()) save_tree(tree, args.output);
  if (!args.boxes_obj.empty()) {
    const std::size_t depth_max = run.result.stats.tree.depth_max;
    if (args.level > depth_max)
      throw InputError("--level " + std::to_string(args.level) + " is deeper than the tree (max depth " +
                       std::to_string(depth_max) + ")");
    run.boxes = write_boxes_obj(tree, args.level, std::filesystem::path(args.boxes_obj));
  }
  return run;
}

void print_build(const BuildArgs& args, const BuildOptions& options, const BuildRun& run) {
  const BuildStats& stats = run.result.stats;
  if (args.json) {
    nlohmann::json out = stats_json(stats.tree);
    out["mesh"] = args.mesh;
    out["triangles"] = run.triangles;
    out["fitter"] = to_string(options.fitter);
    out["split"] = std::string(to_string(options.split));
    out["leaf_size"] = options.leaf_size;
    out["seconds"] = stats.seconds;
    if (args.validate) out["valid"] = true;
    if (!args.output.empty()) out["output"] = args.output;
    if (!args.boxes_obj.empty()) out["boxes_obj"] = {{"file", args.boxes_obj}, {"level", args.level}, {"boxes", run.boxes}};
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout << args.mesh << ": " << run.triangles << " triangles, fitter " << to_string(options.fitter) << ", split "
            << to_string(options.split) << ", built in " << stats.seconds << " s\n";
  print_stats(stats.tree);
  if (args.validate) std::cout << "valid\n";
  if (!args.output.empty()) std::cout << "saved " << args.output << '\n';
  if (!args.boxes_obj.empty())
    std::cout << "wrote " << run.boxes << " boxes of level " << args.level << " to " << args.boxes_obj << '\n';
}

void add_build(CLI::App& app) {
  auto* cmd = app.add_subcommand("build", "build a tree of oriented boxes over a mesh");
  auto args = std::make_shared<BuildArgs>();
  cmd->add_option("mesh", args->mesh, "mesh file (OBJ, OFF, STL, PLY, ...)")->required();
  cmd->add_option("--fitter", args->fitter, choices(fitter_names()))->capture_default_str();
  auto* grid = cmd->add_option("--grid", args->grid, "grid radius k of approx (directions with L-inf norm <= k)")
                   ->check(positive_number());
  cmd->add_option("--epsilon", args->epsilon, "approximation factor of approx (chooses k)")
      ->check(positive_number())
      ->excludes(grid);
  cmd->add_option("--split", args->split, choices(split_method_names()))->capture_default_str();
  cmd->add_option("--leaf-size", args->leaf_size, "max triangles per leaf")
      ->check(positive_number())
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "worker threads (0: all cores)")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "save the tree to this file");
  auto* boxes = cmd->add_option("--boxes-obj", args->boxes_obj, "write the boxes of --level as an OBJ wireframe");
  cmd->add_option("--level", args->level, "tree level for --boxes-obj (root: 0)")->needs(boxes)->capture_default_str();
  cmd->add_flag("--validate", args->validate, "check the tree against the mesh (containment, partition)");
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->footer("Example:\n  tightbvh build meshes/elephant.off --fitter approx --validate -o elephant.tree");
  cmd->callback([args, cmd] {
    const BuildOptions options = parse_build_options(*args, *cmd);
    print_build(*args, options, run_build(*args, options));
  });
}

struct InspectArgs {
  std::string tree, mesh;
  bool json = false;
};

void print_inspect(const InspectArgs& args, const Tree& tree, const TreeStats& s) {
  if (args.json) {
    nlohmann::json out = stats_json(s);
    out["tree"] = args.tree;
    out["triangles"] = tree.triangle_order.size();
    out["format_version"] = kTreeFormatVersion;
    if (!args.mesh.empty()) out["valid"] = true;
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout << args.tree << ": " << tree.triangle_order.size() << " triangles, format version " << kTreeFormatVersion
            << '\n';
  print_stats(s);
  if (!args.mesh.empty()) std::cout << "valid for " << args.mesh << '\n';
}

void add_inspect(CLI::App& app) {
  auto* cmd = app.add_subcommand("inspect", "print statistics of a saved tree");
  auto args = std::make_shared<InspectArgs>();
  cmd->add_option("tree", args->tree, "tree file written by `tightbvh build -o`")->required();
  cmd->add_option("--mesh", args->mesh, "also validate the tree against this mesh");
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->footer("Example (elephant.tree as written by the example of `tightbvh build --help`):\n"
              "  tightbvh inspect elephant.tree --mesh meshes/elephant.off");
  cmd->callback([args] {
    const Tree tree = load_tree(args->tree);
    const TreeStats s = tree_stats(tree);
    if (!args->mesh.empty()) {
      const TreeCheck check = validate(tree, load_mesh(args->mesh));
      if (!check.ok()) throw std::runtime_error(args->tree + ": invalid for " + args->mesh + ": " + check.errors[0]);
    }
    print_inspect(*args, tree, s);
  });
}

}  // namespace

void add_build_command(CLI::App& app) {
  add_build(app);
  add_inspect(app);
}

}  // namespace tightbvh::cli
