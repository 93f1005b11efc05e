// tightbvh collide MESH_A MESH_B --pose "r00 r01 r02 r10 r11 r12 r20 r21 r22 tx ty tz"
//   [--all-pairs] [--margin D] [--solid] [--contacts] [--fitter F] [--json] [--view DIR]: builds both trees and
// runs one query with A at the identity and B at the given pose (B's transform in A's frame, rotation
// row-major). --view writes DIR/index.html: both posed meshes with the touching triangles
// highlighted, the intersection curve with --contacts, and the node pairs the descent visited
// (collide_trace, run once more for the page).
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.hpp"
#include "names.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/closed.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/collide_trace.hpp"
#include "tightbvh/pose_text.hpp"
#include "view/page.hpp"
#include "view/scene.hpp"

namespace tightbvh::cli {

Pose parse_pose_option(const std::string& text) {
  try {
    return parse_pose(text);
  } catch (const InputError& e) {
    throw InputError(std::string("--pose: ") + e.what());
  }
}

void require_non_negative(const CLI::Option& option, double value, bool infinity_allowed) {
  if (value >= 0.0 && (std::isfinite(value) || infinity_allowed)) return;
  throw InputError(option.get_name() + " must be " + (infinity_allowed ? ">= 0 (or inf)" : "finite and >= 0") +
                   ", got " + (option.count() > 0 ? option.as<std::string>() : std::to_string(value)));
}

MeshPair load_pair(const std::string& mesh_a, const std::string& mesh_b, const std::string& pose,
                   const std::string& fitter, std::uint32_t leaf_size, unsigned threads) {
  MeshPair pair;
  pair.pose_b = parse_pose_option(pose);
  const auto parsed = parse_fitter(fitter);
  if (!parsed) throw InputError("--fitter: unknown fitter '" + fitter + "' (" + one_of(fitter_names()) + ")");
  pair.fitter = *parsed;
  pair.a = load_mesh(mesh_a);
  pair.b = load_mesh(mesh_b);
  BuildOptions options;
  options.fitter = pair.fitter;
  options.leaf_size = leaf_size;
  options.threads = threads;
  const auto start = std::chrono::steady_clock::now();
  pair.ta = build(pair.a, options);
  pair.tb = build(pair.b, options);
  pair.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return pair;
}

namespace {

struct Args {
  std::string mesh_a, mesh_b, pose = "1 0 0 0 1 0 0 0 1 0 0 0", fitter = to_string(BuildOptions{}.fitter);
  std::string view;  // directory of the page, if asked
  std::uint32_t leaf_size = 1;
  unsigned threads = 0;
  double margin = 0.0;
  bool all_pairs = false, json = false, solid = false, contacts = false;
};

struct Run {
  MeshPair pair;
  QueryResult result;
  double query_seconds = 0.0;
};

[[nodiscard]] QueryOptions query_options(const Args& args) {
  return {.mode = args.all_pairs ? QueryMode::all_pairs : QueryMode::first_hit, .margin = args.margin};
}

// Builds both trees and runs the query.
[[nodiscard]] Run run_collide(const Args& args) {
  Run run{load_pair(args.mesh_a, args.mesh_b, args.pose, args.fitter, args.leaf_size, args.threads), {}};
  const MeshPair& p = run.pair;
  // --solid: the meshes' closedness once, outside the timed query (an open mesh is the error).
  const Closedness closed_a = args.solid ? check_closed(p.a) : Closedness{};
  const Closedness closed_b = args.solid ? check_closed(p.b) : Closedness{};
  const QueryOptions options{.mode = args.all_pairs ? QueryMode::all_pairs : QueryMode::first_hit,
                             .margin = args.margin,
                             .solid = args.solid,
                             .closed_a = &closed_a,
                             .closed_b = &closed_b,
                             .contacts = args.contacts};
  const auto start = std::chrono::steady_clock::now();
  run.result = collide(p.ta, p.a, Pose::identity(), p.tb, p.b, p.pose_b, options);
  run.query_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

// The page of --view (before anything is printed: a failure is the one error line).
void write_view(const Args& args, const Run& run) {
  const auto name = [](const std::string& path) { return std::filesystem::path(path).filename().string(); };
  const std::string title = name(args.mesh_a) + " (A) and " + name(args.mesh_b) + " (B): contacts, fitter " +
                            to_string(run.pair.fitter);
  const MeshPair& p = run.pair;
  nlohmann::json scene = view::contacts_scene(title, {p.a, p.b, p.pose_b, run.result, args.all_pairs});
  // The descent again, recorded (not timed): the same node pairs as the query above.
  const CollideTrace trace = collide_trace(p.ta, p.a, Pose::identity(), p.tb, p.b, p.pose_b, query_options(args),
                                           {.max_pairs = view::kMaxDrawnPairs});
  scene["descent"] = view::descent_json(trace, p.ta, p.tb, p.pose_b);
  view::write_page(args.view, scene);
}

void print_collide(const Args& args, const Run& run) {
  const QueryResult& r = run.result;
  if (args.json) {
    nlohmann::json pairs = nlohmann::json::array();
    for (const TrianglePair& p : r.pairs) pairs.push_back({p.a, p.b});
    nlohmann::json out = {{"mesh_a", args.mesh_a},
                          {"mesh_b", args.mesh_b},
                          {"fitter", to_string(run.pair.fitter)},
                          {"mode", args.all_pairs ? "all_pairs" : "first_hit"},
                          {"margin", args.margin},
                          {"solid", args.solid},
                          {"hit", r.hit},
                          {"inside", to_string(r.inside)},
                          {"pair_count", r.pairs.size()},
                          {"pairs", pairs},
                          {"box_tests", r.stats.box_tests},
                          {"triangle_tests", r.stats.triangle_tests},
                          {"seconds", run.query_seconds},
                          {"build_seconds", run.pair.build_seconds}};
    if (args.contacts) {
      nlohmann::json contacts = nlohmann::json::array();
      for (const Contact& c : r.contacts) {
        nlohmann::json points = nlohmann::json::array();
        for (int i = 0; i < c.count; ++i) points.push_back({c.points[i].x(), c.points[i].y(), c.points[i].z()});
        contacts.push_back({{"kind", to_string(c.kind)}, {"coplanar", c.coplanar}, {"points", points}});
      }
      out["curve_length"] = r.curve_length;
      out["contacts"] = contacts;
    }
    if (!args.view.empty()) out["view"] = (std::filesystem::path(args.view) / "index.html").string();
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout << "hit: " << (r.hit ? "yes" : "no") << '\n';
  if (r.inside == Inside::b_in_a) std::cout << "inside: B is inside A (no surfaces touch)\n";
  if (r.inside == Inside::a_in_b) std::cout << "inside: A is inside B (no surfaces touch)\n";
  std::cout
            << (args.all_pairs ? "pairs: " : "pairs (first hit): ") << r.pairs.size() << '\n'
            << (args.contacts ? "intersection curve: " + std::to_string(r.curve_length) + " long\n" : std::string())
            << "box tests: " << r.stats.box_tests << '\n'
            << "triangle tests: " << r.stats.triangle_tests << '\n'
            << "seconds: " << run.query_seconds << " (query), " << run.pair.build_seconds << " (build, fitter "
            << to_string(run.pair.fitter) << ")\n";
  if (!args.view.empty()) std::cout << "wrote " << (std::filesystem::path(args.view) / "index.html").string() << '\n';
}

}  // namespace

void add_collide_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("collide", "collision query between two meshes (A at identity, B at --pose)");
  auto args = std::make_shared<Args>();
  cmd->add_option("mesh_a", args->mesh_a, "mesh A (OBJ, OFF, STL, PLY, ...)")->required();
  cmd->add_option("mesh_b", args->mesh_b, "mesh B")->required();
  cmd->add_option("--pose", args->pose, "B's pose in A's frame: \"r00 r01 r02 r10 r11 r12 r20 r21 r22 tx ty tz\"")
      ->capture_default_str();
  cmd->add_flag("--all-pairs", args->all_pairs, "report every touching triangle pair (default: first hit)");
  auto* margin = cmd->add_option("--margin", args->margin,
                                 "report triangle pairs at distance <= D instead of touching ones")
      ->capture_default_str();
  cmd->add_flag("--contacts", args->contacts,
                "with --all-pairs (no margin): where each pair's triangles meet, and the intersection curve's length "
                "(--view draws the curve)");
  cmd->add_flag("--solid", args->solid,
                "closed meshes are solids: also a hit when one is inside the other (error for an open mesh)");
  cmd->add_option("--fitter", args->fitter, choices(fitter_names()))->capture_default_str();
  cmd->add_option("--leaf-size", args->leaf_size, "max triangles per leaf")
      ->check(positive_number())
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "build threads (0: all cores)")->capture_default_str();
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->add_option("--view", args->view,
                  "write DIR/index.html: the posed meshes, touching triangles highlighted, the descent's node pairs");
  cmd->footer("Example:\n  tightbvh collide meshes/elephant.off meshes/knot1.off --pose \"1 0 0 0 1 0 0 0 1 0.2 0 0\" "
              "--all-pairs");
  cmd->callback([args, margin] {
    require_non_negative(*margin, args->margin);
    const Run run = run_collide(*args);
    if (!args->view.empty()) write_view(*args, run);
    print_collide(*args, run);
  });
}

}  // namespace tightbvh::cli
