#pragma once
// Results of a benchmark run and their table / JSON / CSV forms.
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "check.hpp"

namespace tightbvh::bench {

struct Row {
  std::string scenario;
  std::string engine;
  Mode mode = Mode::first_hit;
  double build_seconds = 0;
  std::size_t queries = 0;   // poses per timed pass
  double seconds = 0;        // median time of one pass
  int repetitions = 0;
  std::size_t hits = 0;      // poses answered "touching"
  std::size_t pairs = 0;     // sum of pair-set sizes (all_pairs)
  Agreement agreement;
  std::optional<double> ratio;  // qps / qps of fcl-obb, same scenario and mode

  [[nodiscard]] double qps() const { return seconds > 0 ? double(queries) / seconds : 0.0; }
};

struct RunInfo {
  std::string mesh_a, mesh_b, scenario, reference;
  std::size_t triangles_a = 0, triangles_b = 0;
  int poses = 0;           // per scenario
  std::uint64_t seed = 0;
  double tolerance = 0;
  int repetitions = 0;
  std::vector<std::string> notes;  // per-engine limitations
};

void fill_ratios(std::vector<Row>& rows);
void print_table(std::ostream& out, const RunInfo& info, const std::vector<Row>& rows);
void write_json(const std::filesystem::path& path, const RunInfo& info, const std::vector<Row>& rows);
void write_csv(const std::filesystem::path& path, const RunInfo& info, const std::vector<Row>& rows);
[[nodiscard]] std::string agreement_text(const Row& row);

}  // namespace tightbvh::bench
