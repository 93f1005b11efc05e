// tightbvh scene SCENE.json [--distance D] [--all-pairs] [--json] [--fitter F] [--threads N]:
// loads a scene file (scene_file.hpp) and prints its touching object pairs (with --distance also
// those closer than D), for the scene as loaded and, when it has frames, after each frame's moves.
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.hpp"
#include "names.hpp"
#include "tightbvh/scene.hpp"
#include "tightbvh/scene_file.hpp"

namespace tightbvh::cli {
namespace {

struct Args {
  std::string path, fitter = to_string(BuildOptions{}.fitter);
  double distance = 0.0;  // 0: not asked
  bool all_pairs = false;
  bool json = false;
  unsigned threads = 1;
};

struct Answer {
  std::vector<ObjectPairHit> touching;
  std::vector<ObjectPairDistance> closer;
};

Answer query(const Scene& scene, const Args& args) {
  Answer answer;
  const QueryOptions options{.mode = args.all_pairs ? QueryMode::all_pairs : QueryMode::first_hit};
  answer.touching = collide(scene, options, args.threads);
  if (args.distance > 0.0) answer.closer = distance_within(scene, args.distance, {}, args.threads);
  return answer;
}

nlohmann::json to_json(const Scene& scene, const Answer& answer, const Args& args) {
  nlohmann::json out;
  out["pairs"] = nlohmann::json::array();
  for (const ObjectPairHit& hit : answer.touching)
    out["pairs"].push_back({scene.object(hit.a).name, scene.object(hit.b).name});
  if (args.all_pairs) {
    out["triangle_pairs"] = nlohmann::json::array();
    for (const ObjectPairHit& hit : answer.touching) out["triangle_pairs"].push_back(hit.result.pairs.size());
  }
  if (args.distance > 0.0) {
    out["closer"] = nlohmann::json::array();
    out["distances"] = nlohmann::json::array();
    for (const ObjectPairDistance& d : answer.closer) {
      out["closer"].push_back({scene.object(d.a).name, scene.object(d.b).name});
      out["distances"].push_back(d.result.distance);
    }
  }
  return out;
}

void print_text(const std::string& title, const Scene& scene, const Answer& answer, const Args& args) {
  std::cout << title << ": " << answer.touching.size() << " touching object pairs\n";
  for (const ObjectPairHit& hit : answer.touching) {
    std::cout << "  " << scene.object(hit.a).name << ' ' << scene.object(hit.b).name;
    if (args.all_pairs) std::cout << "  (" << hit.result.pairs.size() << " triangle pairs)";
    std::cout << '\n';
  }
  if (args.distance > 0.0) {
    std::cout << title << ": " << answer.closer.size() << " object pairs closer than " << args.distance << '\n';
    for (const ObjectPairDistance& d : answer.closer)
      std::cout << "  " << scene.object(d.a).name << ' ' << scene.object(d.b).name << "  " << d.result.distance << '\n';
  }
}

void run_scene(const Args& args) {
  const auto fitter = parse_fitter(args.fitter);
  if (!fitter) throw InputError("unknown fitter '" + args.fitter + "'");
  if (!(args.distance >= 0.0)) throw InputError("--distance: must be > 0, got " + std::to_string(args.distance));
  BuildOptions build_options;
  build_options.fitter = *fitter;
  SceneFile file = load_scene_file(args.path, build_options);
  const Answer first = query(file.scene, args);
  nlohmann::json out = to_json(file.scene, first, args);
  if (!args.json) print_text("scene", file.scene, first, args);
  if (!file.frames.empty()) out["frames"] = nlohmann::json::array();
  for (std::size_t i = 0; i < file.frames.size(); ++i) {
    file.scene.set_poses(file.frames[i].objects, file.frames[i].poses);
    const Answer answer = query(file.scene, args);
    if (args.json)
      out["frames"].push_back(to_json(file.scene, answer, args));
    else
      print_text("frame " + std::to_string(i), file.scene, answer, args);
  }
  if (args.json) std::cout << out.dump(2) << '\n';
}

}  // namespace

void add_scene_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("scene", "touching object pairs of a scene file, per frame (docs/scenes.md)");
  auto args = std::make_shared<Args>();
  cmd->add_option("scene", args->path, "scene file (JSON: models, objects, allowed pairs, frames)")->required();
  cmd->add_option("--distance", args->distance, "also list the object pairs closer than D");
  cmd->add_flag("--all-pairs", args->all_pairs, "find every touching triangle pair of each object pair");
  cmd->add_option("--fitter", args->fitter, choices(fitter_names()))->capture_default_str();
  cmd->add_option("--threads", args->threads, "query threads (0: all cores)")->capture_default_str();
  cmd->add_flag("--json", args->json,
                "print JSON: {\"pairs\": [[name_a, name_b], ...], \"frames\": [{\"pairs\": ...}, ...]}");
  cmd->footer("Example:\n  tightbvh scene examples/scenes/workcell.json --distance 0.05");
  cmd->callback([args] { run_scene(*args); });
}

}  // namespace tightbvh::cli
