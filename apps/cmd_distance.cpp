// tightbvh distance MESH_A MESH_B --pose "r00 r01 r02 r10 r11 r12 r20 r21 r22 tx ty tz"
//   [--abs-error E] [--rel-error R] [--upper-bound D] [--solid] [--signed] [--fitter F] [--json] [--view DIR]:
// builds both trees and returns the minimum distance with A at the identity and B at the given pose (as collide);
// --signed: negative by the deepest vertex when the solids overlap. --view
// writes DIR/index.html: both posed meshes, the closest triangles and the segment between the closest points.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "names.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/closed.hpp"
#include "tightbvh/distance.hpp"
#include "view/page.hpp"
#include "view/scene.hpp"

namespace tightbvh::cli {
namespace {

struct Args {
  std::string mesh_a, mesh_b, pose = "1 0 0 0 1 0 0 0 1 0 0 0", fitter = to_string(BuildOptions{}.fitter);
  std::uint32_t leaf_size = 1;
  unsigned threads = 0;
  DistanceOptions options;
  bool json = false;
  std::string view;  // directory of the page, if asked
};

struct Run {
  MeshPair pair;
  DistanceResult result;
  double query_seconds = 0.0;
};

[[nodiscard]] Run run_distance(const Args& args) {
  Run run{load_pair(args.mesh_a, args.mesh_b, args.pose, args.fitter, args.leaf_size, args.threads), {}};
  const MeshPair& p = run.pair;
  // --solid, --signed: the meshes' closedness once, outside the timed query (an open mesh is the error).
  const bool solids = args.options.solid || args.options.signed_distance;
  const Closedness closed_a = solids ? check_closed(p.a) : Closedness{};
  const Closedness closed_b = solids ? check_closed(p.b) : Closedness{};
  DistanceOptions options = args.options;
  options.closed_a = &closed_a;
  options.closed_b = &closed_b;
  const auto start = std::chrono::steady_clock::now();
  run.result = distance(p.ta, p.a, Pose::identity(), p.tb, p.b, p.pose_b, options);
  run.query_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

// The page of --view (before anything is printed: a failure is the one error line).
void write_view(const Args& args, const Run& run) {
  const auto name = [](const std::string& path) { return std::filesystem::path(path).filename().string(); };
  const std::string title = name(args.mesh_a) + " (A) and " + name(args.mesh_b) + " (B): distance, fitter " +
                            to_string(run.pair.fitter);
  view::write_page(args.view, view::distance_scene(title, {run.pair.a, run.pair.b, run.pair.pose_b, run.result}));
}

[[nodiscard]] nlohmann::json to_json(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

void print_distance(const Args& args, const Run& run) {
  const DistanceResult& r = run.result;
  if (args.json) {
    nlohmann::json out = {{"mesh_a", args.mesh_a},
                          {"mesh_b", args.mesh_b},
                          {"fitter", to_string(run.pair.fitter)},
                          {"distance", r.distance},
                          {"beyond_upper_bound", r.beyond_upper_bound},
                          {"solid", args.options.solid},
                          {"inside", to_string(r.inside)},
                          {"signed", args.options.signed_distance},
                          {"node_pairs", r.stats.node_pairs},
                          {"triangle_pairs", r.stats.triangle_pairs},
                          {"seconds", run.query_seconds},
                          {"build_seconds", run.pair.build_seconds}};
    if (args.options.signed_distance) {
      out["deepest"] = to_string(r.deepest);
      out["penetration_lower_bound_is_zero"] = r.penetration_lower_bound_is_zero;
      out["curve_length"] = r.curve_length;
      if (r.deepest != Inside::none) out["deepest_vertex"] = r.deepest_vertex;
    }
    if (!args.view.empty()) out["view"] = (std::filesystem::path(args.view) / "index.html").string();
    if (!r.beyond_upper_bound) {
      if (r.inside == Inside::none && r.deepest == Inside::none) out["triangles"] = {r.pair.a, r.pair.b};
      out["point_a"] = to_json(r.point_a);
      out["point_b"] = to_json(r.point_b);
      out["point_a_local"] = to_json(r.point_a_local);
      out["point_b_local"] = to_json(r.point_b_local);
    }
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout.precision(17);
  if (r.beyond_upper_bound) {
    std::cout << "distance: >= " << r.distance << " (upper bound reached)\n";
  } else if (r.inside != Inside::none) {
    std::cout << "distance: 0 (" << (r.inside == Inside::b_in_a ? "B is inside A" : "A is inside B")
              << ", no surfaces touch)\n"
              << "common point: " << r.point_a.transpose() << '\n';
  } else if (r.deepest != Inside::none) {
    const bool a_in_b = r.deepest == Inside::a_in_b;
    std::cout << "distance: " << r.distance << " (the solids overlap: penetration of the deepest vertex)\n"
              << "deepest vertex: " << r.deepest_vertex << (a_in_b ? " of A, inside B\n" : " of B, inside A\n")
              << "point on A: " << r.point_a.transpose() << '\n'
              << "point on B: " << r.point_b.transpose() << '\n';
  } else {
    std::cout << "distance: " << r.distance << '\n'
              << "triangles: " << r.pair.a << " (A), " << r.pair.b << " (B)\n"
              << "point on A: " << r.point_a.transpose() << '\n'
              << "point on B: " << r.point_b.transpose() << '\n';
    if (r.penetration_lower_bound_is_zero)
      std::cout << "penetration bound: 0 (no vertex inside the other solid); intersection curve: " << r.curve_length
                << " long\n";
  }
  std::cout.precision(6);
  std::cout << "node pairs: " << r.stats.node_pairs << '\n'
            << "triangle pairs: " << r.stats.triangle_pairs << '\n'
            << "seconds: " << run.query_seconds << " (query), " << run.pair.build_seconds << " (build, fitter "
            << to_string(run.pair.fitter) << ")\n";
  if (!args.view.empty()) std::cout << "wrote " << (std::filesystem::path(args.view) / "index.html").string() << '\n';
}

}  // namespace

void add_distance_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("distance", "minimum distance between two meshes (A at identity, B at --pose)");
  auto args = std::make_shared<Args>();
  cmd->add_option("mesh_a", args->mesh_a, "mesh A (OBJ, OFF, STL, PLY, ...)")->required();
  cmd->add_option("mesh_b", args->mesh_b, "mesh B")->required();
  cmd->add_option("--pose", args->pose, "B's pose in A's frame: \"r00 r01 r02 r10 r11 r12 r20 r21 r22 tx ty tz\"")
      ->capture_default_str();
  auto* abs_error = cmd->add_option("--abs-error", args->options.absolute_error, "stop once within this absolute error")
      ->capture_default_str();
  auto* rel_error = cmd->add_option("--rel-error", args->options.relative_error, "stop once within this relative error")
      ->capture_default_str();
  auto* upper_bound = cmd->add_option("--upper-bound", args->options.upper_bound, "only report distances below this")
      ->capture_default_str();
  cmd->add_flag("--solid", args->options.solid,
                "closed meshes are solids: 0 when one is inside the other (error for an open mesh)");
  cmd->add_flag("--signed", args->options.signed_distance,
                "closed meshes are solids: negative when they overlap, minus the depth of the deepest vertex inside "
                "the other solid (error for an open mesh)");
  cmd->add_option("--fitter", args->fitter, choices(fitter_names()))->capture_default_str();
  cmd->add_option("--leaf-size", args->leaf_size, "max triangles per leaf")
      ->check(positive_number())
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "build threads (0: all cores)")->capture_default_str();
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->add_option("--view", args->view,
                  "write DIR/index.html: the posed meshes, the closest triangles and the segment between the closest "
                  "points");
  cmd->footer(
      "Example:\n  tightbvh distance meshes/elephant.off meshes/knot1.off --pose \"1 0 0 0 1 0 0 0 1 1.5 0 0\"");
  cmd->callback([args, abs_error, rel_error, upper_bound] {
    require_non_negative(*abs_error, args->options.absolute_error);
    require_non_negative(*rel_error, args->options.relative_error);
    require_non_negative(*upper_bound, args->options.upper_bound, true);
    const Run run = run_distance(*args);
    if (!args->view.empty()) write_view(*args, run);
    print_distance(*args, run);
  });
}

}  // namespace tightbvh::cli
