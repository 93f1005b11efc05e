// tightbvh build MESH [options]: build a tree, print its statistics, optionally save it and
// write the boxes of one level as an OBJ wireframe.  tightbvh inspect TREE: statistics of a
// saved tree (and, with --mesh, validation against its mesh).
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/serialize.hpp"
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

// 8 corners and the 12 edges of each box at depth `level`, as OBJ `v` and `l` lines.
std::size_t write_boxes_obj(const Tree& tree, std::size_t level, const std::string& path) {
  std::ostringstream out;
  out.precision(17);
  out << "# tightbvh: boxes of tree level " << level << "\n";
  std::size_t boxes = 0;
  std::vector<std::pair<std::uint32_t, std::size_t>> stack{{0, 0}};
  while (!stack.empty()) {
    const auto [index, depth] = stack.back();
    stack.pop_back();
    const Node& node = tree.nodes[index];
    if (depth == level) {
      // Obb::corners: bit 0 -> +axis 0, bit 1 -> +axis 1, bit 2 -> +axis 2.
      for (const Vec3& c : node.box.corners()) out << "v " << c.x() << ' ' << c.y() << ' ' << c.z() << '\n';
      const std::size_t base = 8 * boxes + 1;
      for (int a = 0; a < 8; ++a)
        for (const int bit : {1, 2, 4})
          if (!(a & bit)) out << "l " << base + a << ' ' << base + (a | bit) << '\n';
      ++boxes;
      continue;
    }
    if (!node.is_leaf()) {
      stack.push_back({node.first + 1, depth + 1});
      stack.push_back({node.first, depth + 1});
    }
  }
  std::ofstream file(path);
  if (!file) throw InputError(path + ": cannot open for writing");
  file << out.str();
  if (!file.flush()) throw InputError(path + ": write failed");
  return boxes;
}

void add_build(CLI::App& app) {
  auto* cmd = app.add_subcommand("build", "build a tree of oriented boxes over a mesh");
  struct Args {
    std::string mesh, fitter = "auto", split = "rapid", output, boxes_obj;
    int grid = 0;
    double epsilon = 0.0;
    std::uint32_t leaf_size = 1;
    unsigned threads = 0;
    std::size_t level = 0;
    bool json = false, validate = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("mesh", args->mesh, "mesh file (OBJ, OFF, STL, PLY, ...)")->required();
  cmd->add_option("--fitter", args->fitter, "auto | aabb | pca | pca-vertex | diameter | approx | approx-snap | exact")
      ->capture_default_str();
  auto* grid = cmd->add_option("--grid", args->grid, "grid radius k of approx (directions with L-inf norm <= k)")
                   ->check(CLI::PositiveNumber);
  cmd->add_option("--epsilon", args->epsilon, "approximation factor of approx (chooses k)")
      ->check(CLI::PositiveNumber)
      ->excludes(grid);
  cmd->add_option("--split", args->split, "rapid | median | binned")->capture_default_str();
  cmd->add_option("--leaf-size", args->leaf_size, "max triangles per leaf")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--threads", args->threads, "worker threads (0: all cores)")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "save the tree to this file");
  auto* boxes = cmd->add_option("--boxes-obj", args->boxes_obj, "write the boxes of --level as an OBJ wireframe");
  cmd->add_option("--level", args->level, "tree level for --boxes-obj (root: 0)")->needs(boxes)->capture_default_str();
  cmd->add_flag("--validate", args->validate, "check the tree against the mesh (containment, partition)");
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->callback([args, cmd] {
    BuildOptions options;
    const auto fitter = parse_fitter(args->fitter);
    if (!fitter) throw InputError("unknown fitter '" + args->fitter + "'");
    options.fitter = *fitter;
    const auto split = parse_split_method(args->split);
    if (!split) throw InputError("unknown split '" + args->split + "' (rapid, median or binned)");
    options.split = *split;
    if (cmd->count("--grid")) options.fit.grid = args->grid;
    if (cmd->count("--epsilon")) options.fit.epsilon = args->epsilon;
    options.leaf_size = args->leaf_size;
    options.threads = args->threads;

    const Mesh mesh = load_mesh(args->mesh);
    const BuildResult result = build_with_stats(mesh, options);
    if (args->validate) {
      const TreeCheck check = validate(result.tree, mesh);
      if (!check.ok()) throw std::runtime_error("invalid tree: " + check.errors[0]);
    }
    if (!args->output.empty()) save_tree(result.tree, args->output);
    std::size_t box_count = 0;
    if (!args->boxes_obj.empty()) {
      if (args->level > result.stats.tree.depth_max)
        throw InputError("--level " + std::to_string(args->level) + " is deeper than the tree (max depth " +
                         std::to_string(result.stats.tree.depth_max) + ")");
      box_count = write_boxes_obj(result.tree, args->level, args->boxes_obj);
    }
    if (args->json) {
      nlohmann::json out = stats_json(result.stats.tree);
      out["mesh"] = args->mesh;
      out["triangles"] = mesh.triangles.size();
      out["fitter"] = to_string(options.fitter);
      out["split"] = std::string(to_string(options.split));
      out["leaf_size"] = options.leaf_size;
      out["seconds"] = result.stats.seconds;
      if (args->validate) out["valid"] = true;
      if (!args->output.empty()) out["output"] = args->output;
      if (!args->boxes_obj.empty()) out["boxes_obj"] = {{"file", args->boxes_obj}, {"level", args->level}, {"boxes", box_count}};
      std::cout << out.dump(2) << '\n';
    } else {
      std::cout << args->mesh << ": " << mesh.triangles.size() << " triangles, fitter " << to_string(options.fitter)
                << ", split " << to_string(options.split) << ", built in " << result.stats.seconds << " s\n";
      print_stats(result.stats.tree);
      if (args->validate) std::cout << "valid\n";
      if (!args->output.empty()) std::cout << "saved " << args->output << '\n';
      if (!args->boxes_obj.empty())
        std::cout << "wrote " << box_count << " boxes of level " << args->level << " to " << args->boxes_obj << '\n';
    }
  });
}

void add_inspect(CLI::App& app) {
  auto* cmd = app.add_subcommand("inspect", "print statistics of a saved tree");
  struct Args {
    std::string tree, mesh;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("tree", args->tree, "tree file written by `tightbvh build -o`")->required();
  cmd->add_option("--mesh", args->mesh, "also validate the tree against this mesh");
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->callback([args] {
    const Tree tree = load_tree(args->tree);
    const TreeStats s = tree_stats(tree);
    if (!args->mesh.empty()) {
      const TreeCheck check = validate(tree, load_mesh(args->mesh));
      if (!check.ok()) throw std::runtime_error(args->tree + ": invalid for " + args->mesh + ": " + check.errors[0]);
    }
    if (args->json) {
      nlohmann::json out = stats_json(s);
      out["tree"] = args->tree;
      out["triangles"] = tree.triangle_order.size();
      out["format_version"] = kTreeFormatVersion;
      if (!args->mesh.empty()) out["valid"] = true;
      std::cout << out.dump(2) << '\n';
    } else {
      std::cout << args->tree << ": " << tree.triangle_order.size() << " triangles, format version "
                << kTreeFormatVersion << '\n';
      print_stats(s);
      if (!args->mesh.empty()) std::cout << "valid for " << args->mesh << '\n';
    }
  });
}

}  // namespace

void add_build_command(CLI::App& app) {
  add_build(app);
  add_inspect(app);
}

}  // namespace tightbvh::cli
