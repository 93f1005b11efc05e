// tightbvh-bench: whole tree-vs-tree collision queries of tightbvh against FCL, Bullet and ODE
// on the same poses, every answer checked against our exact reference.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include <CLI/CLI.hpp>

#include "bench.hpp"
#include "check.hpp"
#include "output.hpp"
#include "poses.hpp"
#include "report.hpp"

namespace tb = tightbvh::bench;
using tightbvh::Pose;

namespace {

constexpr double kMinSample = 0.02;  // seconds of CPU per timed sample (short ones are noise)

std::vector<tb::EngineInfo> all_engines() {
  std::vector<tb::EngineInfo> all;
  for (auto list : {tb::tightbvh_engines(), tb::fcl_engines(), tb::bullet_engines(), tb::ode_engines()})
    for (auto& e : list) all.push_back(std::move(e));
  return all;
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string default_mesh(const char* name) {
  const std::filesystem::path shipped = std::filesystem::path(TIGHTBVH_SOURCE_DIR) / "meshes" / name;
  return std::filesystem::exists(shipped) ? shipped.string() : (std::filesystem::path("meshes") / name).string();
}

// A one-line progress bar on stderr, only when stderr is a terminal.
struct Progress {
  bool enabled = isatty(fileno(stderr)) != 0;
  void show(const std::string& label, double fraction) const {
    if (!enabled) return;
    const int width = 30, done = int(fraction * width + 0.5);
    std::fprintf(stderr, "\r%-44.44s [%s%s] %3d%%", label.c_str(), std::string(done, '#').c_str(),
                 std::string(width - done, ' ').c_str(), int(fraction * 100 + 0.5));
    std::fflush(stderr);
  }
  void done() const {
    if (enabled) std::fprintf(stderr, "\r%80s\r", "");
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tightbvh-bench: tree-vs-tree collision queries, tightbvh vs FCL, Bullet and ODE"};
  // A later occurrence of an option overrides an earlier one, so scripts/run can pass defaults
  // and let its own arguments override them.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  std::string mesh_a = default_mesh("elephant.off"), mesh_b = default_mesh("knot1.off");
  std::string engines_arg = "all", scenario_arg = "all", modes_arg = "first_hit,all_pairs";
  std::string poses_file, write_poses_file, json_file, csv_file, report_dir;
  int poses = 100, repetitions = 5;
  std::uint64_t seed = 1;
  double budget = 1.0;
  bool list = false;
  app.add_option("--mesh-a", mesh_a, "mesh A (stays at identity)")->capture_default_str();
  app.add_option("--mesh-b", mesh_b, "mesh B (moved by each pose)")->capture_default_str();
  app.add_option("--engines", engines_arg, "comma-separated engines, or 'all' (see --list-engines)")
      ->capture_default_str();
  app.add_option("--poses", poses, "poses per scenario")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "random seed of the generated poses")->capture_default_str();
  app.add_option("--scenario", scenario_arg, "overlap | near | separated | all")->capture_default_str();
  app.add_option("--poses-file", poses_file, "read poses (12 numbers a line) instead of generating them");
  app.add_option("--write-poses", write_poses_file, "save the generated poses");
  app.add_option("--modes", modes_arg, "first_hit,all_pairs")->capture_default_str();
  app.add_option("--repetitions", repetitions, "timed passes (median reported)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--budget", budget, "seconds after which no further timed pass starts")->capture_default_str();
  app.add_option("--json", json_file, "write results as JSON");
  app.add_option("--csv", csv_file, "write results as CSV");
  app.add_option("--report", report_dir, "write an HTML report (index.html) into this folder");
  app.add_flag("--list-engines", list, "list the engines and what they support");
  CLI11_PARSE(app, argc, argv);

  try {
    auto engines = all_engines();
    if (list) {
      for (const auto& e : engines)
        std::printf("%-18s first_hit:%-3s all_pairs:%-3s %s\n", e.name.c_str(), e.first_hit ? "yes" : "no",
                    e.all_pairs ? "yes" : "no", e.note.c_str());
      return 0;
    }
    // Engine selection: unknown names are an error, not silently skipped.
    if (engines_arg != "all") {
      std::vector<tb::EngineInfo> chosen;
      for (const auto& name : split_list(engines_arg)) {
        auto it = std::find_if(engines.begin(), engines.end(), [&](const auto& e) { return e.name == name; });
        if (it == engines.end()) {
          std::string known;
          for (const auto& e : engines) known += " " + e.name;
          std::cerr << "tightbvh-bench: unknown engine '" << name << "'; known:" << known << "\n";
          return 2;
        }
        chosen.push_back(*it);
      }
      engines = std::move(chosen);
    }
    std::vector<tb::Mode> modes;
    for (const auto& m : split_list(modes_arg)) {
      if (m == "first_hit") modes.push_back(tb::Mode::first_hit);
      else if (m == "all_pairs") modes.push_back(tb::Mode::all_pairs);
      else {
        std::cerr << "tightbvh-bench: unknown mode '" << m << "' (first_hit, all_pairs)\n";
        return 2;
      }
    }
    std::vector<std::optional<tb::Scenario>> scenarios;  // nullopt = poses from the file
    if (!poses_file.empty()) {
      scenarios.push_back(std::nullopt);
    } else if (scenario_arg == "all") {
      scenarios = {tb::Scenario::overlap, tb::Scenario::near, tb::Scenario::separated};
    } else if (auto s = tb::parse_scenario(scenario_arg)) {
      scenarios.push_back(*s);
    } else {
      std::cerr << "tightbvh-bench: unknown scenario '" << scenario_arg << "' (overlap, near, separated, all)\n";
      return 2;
    }

    tb::Input input;
    input.name_a = std::filesystem::path(mesh_a).filename().string();
    input.name_b = std::filesystem::path(mesh_b).filename().string();
    input.a = tightbvh::load_mesh(mesh_a);
    input.b = tightbvh::load_mesh(mesh_b);
    input.scale = std::max(tightbvh::bounds_of(input.a.vertices).diagonal(), tightbvh::bounds_of(input.b.vertices).diagonal());
    const double tolerance = 1e-9 * input.scale;

    const Progress progress;
    progress.show("building the reference", 0);
    const tb::Reference reference(input);
    tb::RunInfo info{input.name_a, input.name_b, poses_file.empty() ? scenario_arg : "file", reference.description(),
                     input.a.triangles.size(), input.b.triangles.size(), poses, seed, tolerance, repetitions, {}};
    for (const auto& e : engines)
      if (!e.note.empty()) info.notes.push_back(e.name + ": " + e.note);

    std::map<std::string, std::unique_ptr<tb::Prepared>> built;
    std::set<std::string> failed;
    std::vector<tb::Row> rows;
    std::vector<Pose> written;
    for (const auto& scenario : scenarios) {
      const std::string sname = scenario ? std::string(tb::to_string(*scenario)) : "file";
      progress.show(sname + ": poses", 0);
      const std::vector<Pose> ps =
          scenario ? tb::generate_poses(input.a, input.b, *scenario, poses, seed,
                                        [&](const Pose& p) { return reference.collides(p); })
                   : tb::read_poses(poses_file);
      if (!scenario) info.poses = int(ps.size());
      if (!write_poses_file.empty()) written.insert(written.end(), ps.begin(), ps.end());
      std::vector<std::vector<tb::Pair>> ref_pairs(ps.size());
      for (std::size_t i = 0; i < ps.size(); ++i) {
        ref_pairs[i] = reference.pairs(ps[i]);
        progress.show(sname + ": reference", double(i + 1) / ps.size());
      }
      // Build (once per engine), then the checked warm-up pass of every engine and mode.
      struct Job {
        const tb::EngineInfo* info;
        tb::Prepared* engine;
        tb::Mode mode;
        tb::Answers answers;
        std::vector<double> times;
        double spent = 0;
        int inner = 1;  // passes per sample, so that a sample lasts >= kMinSample
      };
      std::vector<Job> jobs;
      for (const auto& e : engines) {
        if (failed.count(e.name)) continue;
        if (!built.count(e.name)) {
          progress.show(e.name + ": build", 0);
          try {
            built[e.name] = e.build(input);
          } catch (const std::exception& ex) {
            failed.insert(e.name);
            info.notes.push_back(e.name + ": NOT RUN, build failed: " + ex.what());
            continue;
          }
        }
        for (tb::Mode mode : modes) {
          if ((mode == tb::Mode::first_hit && !e.first_hit) || (mode == tb::Mode::all_pairs && !e.all_pairs)) continue;
          progress.show(sname + ": " + e.name + " " + tb::to_string(mode) + " (checked pass)", 0);
          jobs.push_back({&e, built[e.name].get(), mode, built[e.name]->answer(mode, ps), {}, 0, 1});
          // Calibration: a pass long enough already counts as the first sample.
          Job& job = jobs.back();
          const double once = job.engine->pass(mode, ps, 1);
          job.inner = std::clamp(int(std::ceil(kMinSample / std::max(once, 1e-9))), 1, 1000);
          if (job.inner == 1) {
            job.times.push_back(once);
            job.spent = once;
          }
        }
      }
      // Timed passes round-robin over the engines, so that load from elsewhere on the machine
      // hits every engine alike; an engine stops adding passes once its budget is spent.
      for (int r = 0; r < repetitions; ++r) {
        for (std::size_t j = 0; j < jobs.size(); ++j) {
          Job& job = jobs[j];
          if (int(job.times.size()) >= repetitions || (!job.times.empty() && job.spent > budget)) continue;
          progress.show(sname + ": timing", (double(r) * jobs.size() + j + 1) / (double(repetitions) * jobs.size()));
          const double dt = job.engine->pass(job.mode, ps, job.inner);
          job.times.push_back(dt);
          job.spent += dt * job.inner;
        }
      }
      for (Job& job : jobs) {
        tb::Row row{sname, job.info->name, job.mode, job.engine->build_seconds, ps.size(), tb::median(job.times),
                    int(job.times.size()), 0, 0, {}, {}};
        for (std::size_t i = 0; i < ps.size(); ++i) {
          row.hits += job.answers.hit[i];
          if (job.mode == tb::Mode::all_pairs) row.pairs += job.answers.pairs[i].size();
        }
        row.agreement = tb::compare(input, job.mode, job.answers, ref_pairs, ps, tolerance);
        rows.push_back(std::move(row));
      }
      // The reference itself, for the hit and pair counts every engine is compared to.
      tb::Row ref_row{sname, "reference", tb::Mode::all_pairs, 0, ps.size(), 0, 0, 0, 0, {}, {}};
      for (const auto& p : ref_pairs) {
        ref_row.hits += p.empty() ? 0 : 1;
        ref_row.pairs += p.size();
      }
      rows.push_back(ref_row);
    }
    progress.done();
    for (const auto& [name, engine] : built)
      if (auto st = engine->stats(); !st.empty()) info.notes.push_back(name + ": " + st);
    if (!write_poses_file.empty())
      tb::write_poses(write_poses_file, written,
                      "tightbvh-bench poses: A=" + input.name_a + " B=" + input.name_b + " scenario=" + scenario_arg +
                          " seed=" + std::to_string(seed));
    for (const std::string& f : {json_file, csv_file})
      if (!f.empty() && std::filesystem::path(f).has_parent_path())
        std::filesystem::create_directories(std::filesystem::path(f).parent_path());
    tb::fill_ratios(rows);
    tb::print_table(std::cout, info, rows);
    if (!json_file.empty()) tb::write_json(json_file, info, rows);
    if (!csv_file.empty()) tb::write_csv(csv_file, info, rows);
    if (!report_dir.empty()) tb::write_report(report_dir, info, rows, input);
  } catch (const tightbvh::InputError& e) {
    std::cerr << "tightbvh-bench: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "tightbvh-bench: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
