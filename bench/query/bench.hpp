#pragma once
// tightbvh-bench internals: the engine-agnostic harness. Each engine is a plain adapter type
// with two member functions; the timed loops are templates over that type, so no virtual call
// (nor std::function) sits on the timed path. Engines are type-erased only around whole runs.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "../thread_clock.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/pose.hpp"

namespace tightbvh::bench {

// A touching triangle pair: (triangle of A, triangle of B), original mesh indices.
using Pair = std::pair<std::uint32_t, std::uint32_t>;

// margin: all_pairs with a safety margin of 1% of Input::scale (pairs at distance <= margin).
// solid: first_hit with QueryOptions::solid (closed meshes: also a hit when one is inside the other).
enum class Mode { first_hit, all_pairs, distance, margin, solid };
[[nodiscard]] inline const char* to_string(Mode m) {
  switch (m) {
    case Mode::first_hit: return "first_hit";
    case Mode::all_pairs: return "all_pairs";
    case Mode::distance: return "distance";
    case Mode::margin: return "margin";
    case Mode::solid: return "solid";
  }
  return "?";
}
// Pair-set modes: answers are pair sets compared with the reference's.
[[nodiscard]] inline bool reports_pairs(Mode m) { return m == Mode::all_pairs || m == Mode::margin; }
inline constexpr double kMarginOfScale = 0.01;

struct Input {
  std::string name_a, name_b;
  Mesh a, b;
  double scale = 1.0;  // the larger AABB diagonal of the two meshes: tolerances are relative to it
};

struct TimingOptions {
  int repetitions = 5;         // timed passes over all poses; the median is reported
  double budget_seconds = 1.0; // stop adding repetitions (after the first) once this is spent
};

// What one engine answered for every pose of a scenario, in one mode.
struct Answers {
  std::vector<std::uint8_t> hit;          // per pose
  std::vector<std::vector<Pair>> pairs;   // per pose, sorted; empty in first_hit mode
  std::vector<double> distance;           // per pose, distance mode only
};

// An adapter A provides:
//   bool first_hit(const Pose& b_in_a);                       // any touching pair?
//   void all_pairs(const Pose& b_in_a, std::vector<Pair>& out); // appends every pair found
// and, for engines with EngineInfo::distance,
//   double distance(const Pose& b_in_a);                      // minimum distance (0: touching)
// and, for engines with EngineInfo::margin,
//   void margin_pairs(const Pose& b_in_a, std::vector<Pair>& out); // pairs within the margin
// and, for engines with EngineInfo::solid,
//   bool solid_hit(const Pose& b_in_a);                       // touching, or one inside the other
// Pose = the rigid transform applied to B's vertices in A's frame (A at identity).

// The untimed pass whose answers are checked (it is also the warm-up).
// The distance of an adapter that has one (only called for engines with EngineInfo::distance).
template <class A>
[[nodiscard]] double distance_of(A& adapter, const Pose& pose) {
  if constexpr (requires { adapter.distance(pose); }) return adapter.distance(pose);
  else return -1.0;
}

// The margin pairs of an adapter that has them (only called for engines with EngineInfo::margin).
template <class A>
void margin_pairs_of(A& adapter, const Pose& pose, std::vector<Pair>& out) {
  if constexpr (requires { adapter.margin_pairs(pose, out); }) adapter.margin_pairs(pose, out);
}

// The solid first hit of an adapter that has one (only called for engines with EngineInfo::solid).
template <class A>
[[nodiscard]] bool solid_hit_of(A& adapter, const Pose& pose) {
  if constexpr (requires { adapter.solid_hit(pose); }) return adapter.solid_hit(pose);
  else return false;
}

template <class A>
[[nodiscard]] Answers answer_all(A& adapter, Mode mode, std::span<const Pose> poses) {
  Answers out;
  out.hit.resize(poses.size());
  if (reports_pairs(mode)) out.pairs.resize(poses.size());
  if (mode == Mode::distance) out.distance.resize(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (mode == Mode::distance) {
      out.distance[i] = distance_of(adapter, poses[i]);
      out.hit[i] = out.distance[i] == 0.0 ? 1 : 0;
    } else if (mode == Mode::first_hit) {
      out.hit[i] = adapter.first_hit(poses[i]) ? 1 : 0;
    } else if (mode == Mode::solid) {
      out.hit[i] = solid_hit_of(adapter, poses[i]) ? 1 : 0;
    } else {
      auto& pairs = out.pairs[i];
      if (mode == Mode::margin)
        margin_pairs_of(adapter, poses[i], pairs);
      else
        adapter.all_pairs(poses[i], pairs);
      std::sort(pairs.begin(), pairs.end());
      pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
      out.hit[i] = pairs.empty() ? 0 : 1;
    }
  }
  return out;
}

// Every engine here is single-threaded: timed by the CPU time of the calling thread.
using tightbvh::bench_support::thread_seconds;

// One timed sample: `inner` passes over all poses; returns CPU seconds per pass.
template <class A>
[[nodiscard]] double timed_pass(A& adapter, Mode mode, std::span<const Pose> poses, int inner,
                                std::vector<Pair>& scratch) {
  std::size_t sink = 0;  // keeps the optimiser from dropping the queries
  const double t0 = thread_seconds();
  for (int k = 0; k < inner; ++k) {
    if (mode == Mode::distance) {
      for (const Pose& p : poses) sink += distance_of(adapter, p) > 0.0 ? 1 : 0;
    } else if (mode == Mode::first_hit) {
      for (const Pose& p : poses) sink += adapter.first_hit(p) ? 1 : 0;
    } else if (mode == Mode::solid) {
      for (const Pose& p : poses) sink += solid_hit_of(adapter, p) ? 1 : 0;
    } else {
      for (const Pose& p : poses) {
        scratch.clear();
        if (mode == Mode::margin)
          margin_pairs_of(adapter, p, scratch);
        else
          adapter.all_pairs(p, scratch);
        sink += scratch.size();
      }
    }
  }
  const double dt = (thread_seconds() - t0) / inner;
  volatile std::size_t keep = sink;
  (void)keep;
  return dt;
}

[[nodiscard]] inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A built engine, type-erased for the driver (one virtual call per whole measurement).
class Prepared {
 public:
  virtual ~Prepared() = default;
  [[nodiscard]] virtual Answers answer(Mode mode, std::span<const Pose> poses) = 0;
  [[nodiscard]] virtual double pass(Mode mode, std::span<const Pose> poses, int inner) = 0;
  // Engine-specific counts worth reporting (e.g. contacts without a triangle pair).
  [[nodiscard]] virtual std::string stats() const { return {}; }
  double build_seconds = 0;
};

template <class A>
class PreparedAdapter final : public Prepared {
 public:
  explicit PreparedAdapter(std::unique_ptr<A> adapter) : adapter_(std::move(adapter)) {}
  Answers answer(Mode mode, std::span<const Pose> poses) override { return answer_all(*adapter_, mode, poses); }
  double pass(Mode mode, std::span<const Pose> poses, int inner) override {
    return timed_pass(*adapter_, mode, poses, inner, scratch_);
  }
  std::string stats() const override {
    if constexpr (requires(const A& a) { a.stats(); }) return adapter_->stats();
    else return {};
  }

 private:
  std::unique_ptr<A> adapter_;
  std::vector<Pair> scratch_;
};

// Runs `make` (which builds both trees and returns std::unique_ptr<Adapter>), timing it (CPU).
template <class Make>
[[nodiscard]] std::unique_ptr<Prepared> prepare(Make&& make) {
  const double t0 = thread_seconds();  // every build here is single-threaded
  auto adapter = make();
  using A = typename decltype(adapter)::element_type;
  const double dt = thread_seconds() - t0;
  auto p = std::make_unique<PreparedAdapter<A>>(std::move(adapter));
  p->build_seconds = dt;
  return p;
}

struct EngineInfo {
  std::string name;
  bool first_hit = true;   // supports first_hit natively (early exit)
  bool all_pairs = true;   // reports triangle pairs
  std::string note;        // what the engine cannot do, shown by --list-engines and in the run's notes
  std::function<std::unique_ptr<Prepared>(const Input&)> build;
  bool distance = false;   // answers minimum-distance queries
  bool margin = false;     // reports the pairs within a safety margin
  bool solid = false;      // first_hit on solids (one inside the other counts)
  // Front tracking across poses (QueryCache, BVHFrontList): only worth running on coherent
  // sequences, so `--engines all` includes it only with the trajectory scenario.
  bool coherent = false;
};

// Engine registries, one per translation unit.
[[nodiscard]] std::vector<EngineInfo> tightbvh_engines();
[[nodiscard]] std::vector<EngineInfo> fcl_engines();
[[nodiscard]] std::vector<EngineInfo> bullet_engines();
[[nodiscard]] std::vector<EngineInfo> ode_engines();

// Our exact all-pairs query on a tree built once (the reference and the `near` pose search).
class Reference {
 public:
  explicit Reference(const Input& input);
  ~Reference();
  [[nodiscard]] bool collides(const Pose& b_in_a) const;
  [[nodiscard]] std::vector<Pair> pairs(const Pose& b_in_a) const;  // sorted
  [[nodiscard]] double distance(const Pose& b_in_a) const;
  [[nodiscard]] double brute_force_distance(const Pose& b_in_a) const;  // every triangle pair
  [[nodiscard]] std::vector<Pair> margin_pairs(const Pose& b_in_a) const;  // sorted
  // Solids (both meshes must be closed: else InputError): a hit, touching or one inside the other;
  // and "one inside the other without touching".
  [[nodiscard]] bool solid_collides(const Pose& b_in_a) const;
  [[nodiscard]] bool contained(const Pose& b_in_a) const;
  [[nodiscard]] std::string description() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tightbvh::bench
