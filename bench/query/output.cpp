#include "output.hpp"

#include <cstdio>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "tightbvh/mesh.hpp"

namespace tightbvh::bench {

void fill_ratios(std::vector<Row>& rows) {
  std::map<std::pair<std::string, Mode>, double> base;
  for (const Row& r : rows)
    if (r.engine == "fcl-obb") base[{r.scenario, r.mode}] = r.qps();
  for (Row& r : rows)
    if (auto it = base.find({r.scenario, r.mode}); it != base.end() && it->second > 0) r.ratio = r.qps() / it->second;
}

std::string agreement_text(const Row& r) {
  const Agreement& a = r.agreement;
  std::string s;
  char buf[160];
  if (a.mismatches() == 0) {
    s = "ok";
  } else {
    std::snprintf(buf, sizeof buf, "MISMATCH yes/no %d", a.yes_no);
    s = buf;
    if (r.mode == Mode::all_pairs) {
      std::snprintf(buf, sizeof buf, ", pairs -%ld +%ld in %d poses", a.missing, a.extra, a.pair_sets);
      s += buf;
      if (a.extra > 0) {
        std::snprintf(buf, sizeof buf, " (extra up to %.3g apart)", a.max_extra_distance);
        s += buf;
      }
    }
  }
  if (a.near_touching() > 0) {
    std::snprintf(buf, sizeof buf, "; near-touching %ld", a.near_touching());
    s += buf;
  }
  return s;
}

void print_table(std::ostream& out, const RunInfo& info, const std::vector<Row>& rows) {
  char line[512];
  out << "tightbvh-bench: A = " << info.mesh_a << " (" << info.triangles_a << " triangles), B = " << info.mesh_b
      << " (" << info.triangles_b << " triangles), " << info.poses << " poses per scenario, seed " << info.seed
      << "\nreference: " << info.reference << "\n";
  std::string scenario;
  for (const Row& r : rows) {
    if (r.scenario != scenario) {
      scenario = r.scenario;
      std::snprintf(line, sizeof line, "\n[%s]\n%-18s %-9s %9s %12s %8s %6s %9s  %s\n", scenario.c_str(), "engine",
                    "mode", "build s", "queries/s", "vs fcl", "hits", "pairs", "agreement");
      out << line;
    }
    if (r.engine == "reference") {
      std::snprintf(line, sizeof line, "%-18s %-9s %9s %12s %8s %6zu %9zu  %s\n", "(reference)", "all_pairs", "-", "-",
                    "-", r.hits, r.pairs, "what every engine is checked against");
      out << line;
      continue;
    }
    char ratio[32] = "-";
    if (r.ratio) std::snprintf(ratio, sizeof ratio, "%.2fx", *r.ratio);
    std::snprintf(line, sizeof line, "%-18s %-9s %9.3f %12.1f %8s %6zu %9s  %s\n", r.engine.c_str(),
                  to_string(r.mode), r.build_seconds, r.qps(), ratio, r.hits,
                  r.mode == Mode::all_pairs ? std::to_string(r.pairs).c_str() : "-", agreement_text(r).c_str());
    out << line;
  }
  if (!info.notes.empty()) {
    out << "\nnotes:\n";
    for (const auto& n : info.notes) out << "  " << n << "\n";
  }
}

void write_json(const std::filesystem::path& path, const RunInfo& info, const std::vector<Row>& rows) {
  nlohmann::json engines = nlohmann::json::array();
  nlohmann::json reference = nlohmann::json::object();
  for (const Row& r : rows) {
    const Agreement& a = r.agreement;
    if (r.engine == "reference") {
      reference[r.scenario] = {{"hits", r.hits}, {"pairs", r.pairs}};
      continue;
    }
    engines.push_back({{"name", r.engine},
                       {"scenario", r.scenario},
                       {"mode", to_string(r.mode)},
                       {"build_seconds", r.build_seconds},
                       {"queries", r.queries},
                       {"seconds", r.seconds},
                       {"repetitions", r.repetitions},
                       {"qps", r.qps()},
                       {"ratio_vs_fcl_obb", r.ratio ? nlohmann::json(*r.ratio) : nlohmann::json(nullptr)},
                       {"hits", r.hits},
                       {"pairs", r.pairs},
                       {"mismatches", a.mismatches()},
                       {"yes_no_mismatches", a.yes_no},
                       {"missing_pairs", a.missing},
                       {"extra_pairs", a.extra},
                       {"pair_set_mismatch_poses", a.pair_sets},
                       {"near_touching", a.near_touching()},
                       {"max_extra_pair_distance", a.max_extra_distance}});
  }
  const nlohmann::json doc{{"mesh_a", info.mesh_a}, {"mesh_b", info.mesh_b},       {"scenario", info.scenario},
                           {"poses", info.poses},   {"seed", info.seed},           {"reference", info.reference},
                           {"notes", info.notes},   {"reference_counts", reference},
                           {"engines", std::move(engines)}};
  std::ofstream out(path);
  out << doc.dump(2) << "\n";
  if (!out) throw InputError(path.string() + ": write failed");
}

void write_csv(const std::filesystem::path& path, const RunInfo& info, const std::vector<Row>& rows) {
  std::ofstream out(path);
  out << "mesh_a,mesh_b,scenario,poses,name,mode,build_seconds,queries,seconds,qps,ratio_vs_fcl_obb,hits,pairs,"
         "mismatches,yes_no_mismatches,missing_pairs,extra_pairs,near_touching\n";
  for (const Row& r : rows) {
    const Agreement& a = r.agreement;
    if (r.engine == "reference") continue;
    out << info.mesh_a << ',' << info.mesh_b << ',' << r.scenario << ',' << r.queries << ',' << r.engine << ','
        << to_string(r.mode) << ',' << r.build_seconds << ',' << r.queries << ',' << r.seconds << ',' << r.qps()
        << ',' << (r.ratio ? std::to_string(*r.ratio) : "") << ',' << r.hits << ',' << r.pairs << ','
        << a.mismatches() << ',' << a.yes_no << ',' << a.missing << ',' << a.extra << ',' << a.near_touching()
        << '\n';
  }
  if (!out) throw InputError(path.string() + ": write failed");
}

}  // namespace tightbvh::bench
