// tightbvh-bench: whole tree-vs-tree collision queries of tightbvh against FCL, Bullet and ODE
// on the same poses, every answer checked against our exact reference.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include <CLI/CLI.hpp>

#include "bench.hpp"
#include "check.hpp"
#include "output.hpp"
#include "poses.hpp"
#include "report.hpp"
#include "../scene/scene_vs_peers.hpp"

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

// ------------------------------------------------------------------------ option parsing
struct Options {
  std::string mesh_a = default_mesh("elephant.off"), mesh_b = default_mesh("knot1.off");
  std::string engines_arg = "all", scenario_arg = "all", modes_arg = "first_hit,all_pairs";
  std::string poses_file, write_poses_file, json_file, csv_file, report_dir;
  int poses = 100, repetitions = 5, brute_check = 0;
  std::uint64_t seed = 1;
  double budget = 1.0, scale_b = 1.0;
  bool list = false;
};

void add_options(CLI::App& app, Options& o) {
  // A later occurrence of an option overrides an earlier one, so scripts/run can pass defaults
  // and let its own arguments override them.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--mesh-a", o.mesh_a, "mesh A (stays at identity)")->capture_default_str();
  app.add_option("--mesh-b", o.mesh_b, "mesh B (moved by each pose)")->capture_default_str();
  app.add_option("--scale-b", o.scale_b, "scale B about its box center first (e.g. 0.1 for the inside scenario)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--engines", o.engines_arg, "comma-separated engines, or 'all' (see --list-engines)")
      ->capture_default_str();
  app.add_option("--poses", o.poses, "poses per scenario")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--seed", o.seed, "random seed of the generated poses")->capture_default_str();
  app.add_option("--scenario", o.scenario_arg,
                 "comma-separated: overlap, near, separated, gap, trajectory, inside, all (all: the first three)")
      ->capture_default_str();
  app.add_option("--poses-file", o.poses_file, "read poses (12 numbers a line) instead of generating them");
  app.add_option("--write-poses", o.write_poses_file, "save the generated poses");
  app.add_option("--modes", o.modes_arg,
                 "comma-separated: first_hit, all_pairs, distance, margin (1% of the scale), solid (first_hit on "
                 "closed meshes, containment included)")
      ->capture_default_str();
  app.add_option("--repetitions", o.repetitions, "timed passes (median reported)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--budget", o.budget, "seconds after which no further timed pass starts")->capture_default_str();
  app.add_option("--json", o.json_file, "write results as JSON");
  app.add_option("--csv", o.csv_file, "write results as CSV");
  app.add_option("--report", o.report_dir, "write an HTML report (index.html) into this folder");
  app.add_flag("--list-engines", o.list, "list the engines and what they support");
  app.add_option("--brute-check", o.brute_check,
                 "distance mode: also check the reference against brute force on the first N poses per scenario")
      ->capture_default_str();
}

// What to run: engines, modes, scenarios (nullopt = poses from the file).
struct Selection {
  std::vector<tb::EngineInfo> engines;
  std::vector<tb::Mode> modes;
  std::vector<std::optional<tb::Scenario>> scenarios;
};

// The selection named by the options; nullopt after printing the error for an unknown name
// (unknown names are an error, not silently skipped).
std::optional<Selection> parse_selection(const Options& o, std::vector<tb::EngineInfo> engines) {
  Selection sel;
  if (o.engines_arg != "all") {
    for (const auto& name : split_list(o.engines_arg)) {
      auto it = std::find_if(engines.begin(), engines.end(), [&](const auto& e) { return e.name == name; });
      if (it == engines.end()) {
        std::string known;
        for (const auto& e : engines) known += " " + e.name;
        std::cerr << "tightbvh-bench: unknown engine '" << name << "'; known:" << known << "\n";
        return std::nullopt;
      }
      sel.engines.push_back(*it);
    }
  } else {
    sel.engines = std::move(engines);
  }
  for (const auto& m : split_list(o.modes_arg)) {
    if (m == "first_hit") sel.modes.push_back(tb::Mode::first_hit);
    else if (m == "all_pairs") sel.modes.push_back(tb::Mode::all_pairs);
    else if (m == "distance") sel.modes.push_back(tb::Mode::distance);
    else if (m == "margin") sel.modes.push_back(tb::Mode::margin);
    else if (m == "solid") sel.modes.push_back(tb::Mode::solid);
    else {
      std::cerr << "tightbvh-bench: unknown mode '" << m << "' (first_hit, all_pairs, distance, margin, solid)\n";
      return std::nullopt;
    }
  }
  if (!o.poses_file.empty()) {
    sel.scenarios.push_back(std::nullopt);
  } else {
    for (const auto& name : split_list(o.scenario_arg)) {
      if (name == "all") {
        for (const tb::Scenario s : {tb::Scenario::overlap, tb::Scenario::near, tb::Scenario::separated})
          sel.scenarios.push_back(s);
      } else if (auto s = tb::parse_scenario(name)) {
        sel.scenarios.push_back(*s);
      } else {
        std::cerr << "tightbvh-bench: unknown scenario '" << name
                  << "' (overlap, near, separated, gap, trajectory, inside, all)\n";
        return std::nullopt;
      }
    }
  }
  // "all" engines: the front-tracking ones only where poses are coherent (on unrelated poses they
  // only cost: FCL's front list grows without bound, 3.7 queries/s in deep overlap).
  const bool coherent = std::find(sel.scenarios.begin(), sel.scenarios.end(), tb::Scenario::trajectory) !=
                        sel.scenarios.end();
  if (o.engines_arg == "all" && !coherent)
    std::erase_if(sel.engines, [](const tb::EngineInfo& e) { return e.coherent; });
  return sel;
}

// ------------------------------------------------------------------------ loading
tb::Input load_input(const Options& o) {
  tb::Input input;
  input.name_a = std::filesystem::path(o.mesh_a).filename().string();
  input.name_b = std::filesystem::path(o.mesh_b).filename().string();
  input.a = tightbvh::load_mesh(o.mesh_a);
  input.b = tightbvh::load_mesh(o.mesh_b);
  if (o.scale_b != 1.0) {
    const tightbvh::Vec3 center = tightbvh::bounds_of(input.b.vertices).center();
    for (tightbvh::Vec3& v : input.b.vertices) v = center + o.scale_b * (v - center);
    std::ostringstream name;
    name << input.name_b << " x" << o.scale_b;
    input.name_b = name.str();
  }
  input.scale = std::max(tightbvh::bounds_of(input.a.vertices).diagonal(), tightbvh::bounds_of(input.b.vertices).diagonal());
  return input;
}

// ------------------------------------------------------------------------ running
// One engine in one mode on one scenario's poses.
struct Job {
  const tb::EngineInfo* info;
  tb::Prepared* engine;
  tb::Mode mode;
  tb::Answers answers;
  std::vector<double> times;
  double spent = 0;
  int inner = 1;  // passes per sample, so that a sample lasts >= kMinSample
};

// All scenarios of one run; engines are built once and kept across scenarios.
class Run {
 public:
  Run(const Options& o, const Selection& sel, const tb::Input& input, const tb::Reference& reference,
      const Progress& progress, tb::RunInfo& info)
      : o_(o), sel_(sel), input_(input), reference_(reference), progress_(progress), info_(info) {}

  void scenario(const std::optional<tb::Scenario>& scenario) {
    const std::string sname = scenario ? std::string(tb::to_string(*scenario)) : "file";
    progress_.show(sname + ": poses", 0);
    const std::vector<Pose> ps =
        scenario ? tb::generate_poses(input_.a, input_.b, *scenario, o_.poses, o_.seed,
                                      [&](const Pose& p) { return reference_.collides(p); },
                                      [&](const Pose& p) { return reference_.distance(p); },
                                      [&](const Pose& p) { return reference_.contained(p); })
                 : tb::read_poses(o_.poses_file);
    if (!scenario) info_.poses = int(ps.size());
    if (!o_.write_poses_file.empty()) written.insert(written.end(), ps.begin(), ps.end());
    const auto wants = [&](tb::Mode m) { return std::count(sel_.modes.begin(), sel_.modes.end(), m) > 0; };
    const bool want_distance = wants(tb::Mode::distance), want_margin = wants(tb::Mode::margin);
    const bool want_solid = wants(tb::Mode::solid);
    const bool want_pairs = wants(tb::Mode::first_hit) || wants(tb::Mode::all_pairs);
    std::vector<std::vector<tb::Pair>> ref_pairs(ps.size());
    std::vector<double> ref_distance(want_distance ? ps.size() : 0);
    std::vector<std::vector<tb::Pair>> ref_margin(want_margin ? ps.size() : 0);
    std::vector<std::uint8_t> ref_solid(want_solid ? ps.size() : 0);
    for (std::size_t i = 0; i < ps.size(); ++i) {
      if (want_pairs) ref_pairs[i] = reference_.pairs(ps[i]);
      if (want_distance) ref_distance[i] = reference_.distance(ps[i]);
      if (want_margin) ref_margin[i] = reference_.margin_pairs(ps[i]);
      if (want_solid) ref_solid[i] = reference_.solid_collides(ps[i]) ? 1 : 0;
      progress_.show(sname + ": reference", double(i + 1) / ps.size());
    }
    if (want_distance) brute_check(sname, ps, ref_distance);
    if (!ps.empty() && !o_.report_dir.empty())
      pictures.push_back(tb::typical_pose(sname, ps, want_pairs ? ref_pairs : std::vector<std::vector<tb::Pair>>{},
                                          [&](const Pose& p) { return reference_.pairs(p); }));
    std::vector<Job> jobs = prepare(sname, ps);
    time_passes(sname, ps, jobs);
    add_rows(sname, ps, jobs, ref_pairs, ref_distance, ref_margin, ref_solid);
  }

  std::map<std::string, std::unique_ptr<tb::Prepared>> built;
  std::vector<tb::Row> rows;
  std::vector<Pose> written;
  std::vector<tb::PosePicture> pictures;  // one typical pose per scenario, for the report

 private:
  // The distance reference against every triangle pair on the first --brute-check poses.
  void brute_check(const std::string& sname, const std::vector<Pose>& ps, const std::vector<double>& ref) {
    const std::size_t n = std::min<std::size_t>(std::max(o_.brute_check, 0), ps.size());
    if (n == 0) return;
    int differ = 0;
    double largest = 0;
    for (std::size_t i = 0; i < n; ++i) {
      progress_.show(sname + ": brute force", double(i + 1) / n);
      const double error = std::abs(reference_.brute_force_distance(ps[i]) - ref[i]);
      largest = std::max(largest, error);
      if (!(error <= 1e-9 * ref[i] + 1e-12 * input_.scale)) ++differ;
    }
    char text[160];
    std::snprintf(text, sizeof text,
                  "distance reference vs brute force on %zu poses: %d differ (largest difference %.3g)", n, differ,
                  largest);
    info_.notes.push_back(sname + ": " + text);
  }

  // Build (once per engine), then the checked warm-up pass of every engine and mode.
  std::vector<Job> prepare(const std::string& sname, const std::vector<Pose>& ps) {
    std::vector<Job> jobs;
    for (const auto& e : sel_.engines) {
      const auto supported = [&](tb::Mode m) { return supports(e, m); };
      if (failed_.count(e.name) || std::none_of(sel_.modes.begin(), sel_.modes.end(), supported)) continue;
      if (!built.count(e.name)) {
        progress_.show(e.name + ": build", 0);
        try {
          built[e.name] = e.build(input_);
        } catch (const std::exception& ex) {
          failed_.insert(e.name);
          info_.notes.push_back(e.name + ": NOT RUN, build failed: " + ex.what());
          continue;
        }
      }
      for (tb::Mode mode : sel_.modes) {
        if (!supports(e, mode)) continue;
        progress_.show(sname + ": " + e.name + " " + tb::to_string(mode) + " (checked pass)", 0);
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
    return jobs;
  }

  // Timed passes round-robin over the engines, so that load from elsewhere on the machine
  // hits every engine alike; an engine stops adding passes once its budget is spent.
  void time_passes(const std::string& sname, const std::vector<Pose>& ps, std::vector<Job>& jobs) const {
    const int repetitions = o_.repetitions;
    for (int r = 0; r < repetitions; ++r) {
      for (std::size_t j = 0; j < jobs.size(); ++j) {
        Job& job = jobs[j];
        if (int(job.times.size()) >= repetitions || (!job.times.empty() && job.spent > o_.budget)) continue;
        progress_.show(sname + ": timing", (double(r) * jobs.size() + j + 1) / (double(repetitions) * jobs.size()));
        const double dt = job.engine->pass(job.mode, ps, job.inner);
        job.times.push_back(dt);
        job.spent += dt * job.inner;
      }
    }
  }

  [[nodiscard]] static bool supports(const tb::EngineInfo& e, tb::Mode mode) {
    switch (mode) {
      case tb::Mode::first_hit: return e.first_hit;
      case tb::Mode::all_pairs: return e.all_pairs;
      case tb::Mode::distance: return e.distance;
      case tb::Mode::margin: return e.margin;
      case tb::Mode::solid: return e.solid;
    }
    return false;
  }

  void add_rows(const std::string& sname, const std::vector<Pose>& ps, const std::vector<Job>& jobs,
                const std::vector<std::vector<tb::Pair>>& ref_pairs, const std::vector<double>& ref_distance,
                const std::vector<std::vector<tb::Pair>>& ref_margin, const std::vector<std::uint8_t>& ref_solid) {
    for (const Job& job : jobs) {
      tb::Row row{sname, job.info->name, job.mode, job.engine->build_seconds, ps.size(), tb::median(job.times),
                  int(job.times.size()), 0, 0, {}, {}};
      for (std::size_t i = 0; i < ps.size(); ++i) {
        row.hits += job.answers.hit[i];
        if (tb::reports_pairs(job.mode)) row.pairs += job.answers.pairs[i].size();
      }
      if (job.mode == tb::Mode::distance)
        row.agreement = tb::compare_distances(job.answers, ref_distance, input_.scale);
      else if (job.mode == tb::Mode::margin)
        row.agreement = tb::compare_exact_pairs(job.answers, ref_margin);
      else if (job.mode == tb::Mode::solid)
        row.agreement = tb::compare_hits(job.answers, ref_solid);
      else
        row.agreement = tb::compare(input_, job.mode, job.answers, ref_pairs, ps, info_.tolerance);
      rows.push_back(std::move(row));
    }
    if (!ref_margin.empty()) {
      tb::Row ref_row{sname, "reference", tb::Mode::margin, 0, ps.size(), 0, 0, 0, 0, {}, {}};
      for (const auto& p : ref_margin) {
        ref_row.hits += p.empty() ? 0 : 1;
        ref_row.pairs += p.size();
      }
      rows.push_back(ref_row);
    }
    if (!ref_solid.empty()) {
      tb::Row ref_row{sname, "reference", tb::Mode::solid, 0, ps.size(), 0, 0, 0, 0, {}, {}};
      for (const std::uint8_t h : ref_solid) ref_row.hits += h;
      rows.push_back(ref_row);
    }
    if (!ref_distance.empty()) {
      tb::Row ref_row{sname, "reference", tb::Mode::distance, 0, ps.size(), 0, 0, 0, 0, {}, {}};
      for (const double d : ref_distance) ref_row.hits += d == 0.0 ? 1 : 0;
      rows.push_back(ref_row);
    }
    // The reference itself, for the hit and pair counts every engine is compared to.
    if (std::count(sel_.modes.begin(), sel_.modes.end(), tb::Mode::first_hit) +
            std::count(sel_.modes.begin(), sel_.modes.end(), tb::Mode::all_pairs) >
        0) {
      tb::Row ref_row{sname, "reference", tb::Mode::all_pairs, 0, ps.size(), 0, 0, 0, 0, {}, {}};
      for (const auto& p : ref_pairs) {
        ref_row.hits += p.empty() ? 0 : 1;
        ref_row.pairs += p.size();
      }
      rows.push_back(ref_row);
    }
  }

  const Options& o_;
  const Selection& sel_;
  const tb::Input& input_;
  const tb::Reference& reference_;
  const Progress& progress_;
  tb::RunInfo& info_;
  std::set<std::string> failed_;
};

// ------------------------------------------------------------------------ output
void write_outputs(const Options& o, const tb::Input& input, const tb::RunInfo& info, Run& run) {
  if (!o.write_poses_file.empty())
    tb::write_poses(o.write_poses_file, run.written,
                    "tightbvh-bench poses: A=" + input.name_a + " B=" + input.name_b + " scenario=" + o.scenario_arg +
                        " seed=" + std::to_string(o.seed));
  for (const std::string& f : {o.json_file, o.csv_file})
    if (!f.empty() && std::filesystem::path(f).has_parent_path())
      std::filesystem::create_directories(std::filesystem::path(f).parent_path());
  tb::fill_ratios(run.rows);
  tb::print_table(std::cout, info, run.rows);
  if (!o.json_file.empty()) tb::write_json(o.json_file, info, run.rows);
  if (!o.csv_file.empty()) tb::write_csv(o.csv_file, info, run.rows);
  if (!o.report_dir.empty()) tb::write_report(o.report_dir, info, run.rows, input, run.pictures);
}

}  // namespace

int main(int argc, char** argv) {
  // Whole scenes are another benchmark with its own options (bench/scene/scene_vs_peers.cpp).
  for (int i = 1; i < argc; ++i)
    if (std::string_view(argv[i]) == "--scene" || std::string_view(argv[i]).starts_with("--scene="))
      return tightbvh::bench::run_scene_bench(argc, argv);
  CLI::App app{"tightbvh-bench: tree-vs-tree collision queries, tightbvh vs FCL, Bullet and ODE\n"
               "(tightbvh-bench --scene SCENE.json [--json OUT]: whole scenes; --scene FILE --help for its options)"};
  Options o;
  add_options(app, o);
  CLI11_PARSE(app, argc, argv);

  try {
    auto engines = all_engines();
    if (o.list) {
      for (const auto& e : engines)
        std::printf("%-18s first_hit:%-3s all_pairs:%-3s distance:%-3s margin:%-3s solid:%-3s %s\n", e.name.c_str(),
                    e.first_hit ? "yes" : "no", e.all_pairs ? "yes" : "no", e.distance ? "yes" : "no",
                    e.margin ? "yes" : "no", e.solid ? "yes" : "no", e.note.c_str());
      return 0;
    }
    const std::optional<Selection> sel = parse_selection(o, std::move(engines));
    if (!sel) return 2;

    const tb::Input input = load_input(o);
    const double tolerance = 1e-9 * input.scale;
    const Progress progress;
    progress.show("building the reference", 0);
    const tb::Reference reference(input);
    tb::RunInfo info{input.name_a, input.name_b, o.poses_file.empty() ? o.scenario_arg : "file", reference.description(),
                     input.a.triangles.size(), input.b.triangles.size(), o.poses, o.seed, tolerance, o.repetitions, {}};
    for (const auto& e : sel->engines)
      if (!e.note.empty()) info.notes.push_back(e.name + ": " + e.note);

    Run run(o, *sel, input, reference, progress, info);
    for (const auto& scenario : sel->scenarios) run.scenario(scenario);
    progress.done();
    for (const auto& [name, engine] : run.built)
      if (auto st = engine->stats(); !st.empty()) info.notes.push_back(name + ": " + st);
    write_outputs(o, input, info, run);
  } catch (const tightbvh::InputError& e) {
    std::cerr << "tightbvh-bench: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "tightbvh-bench: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
