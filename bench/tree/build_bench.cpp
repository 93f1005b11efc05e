// tightbvh-build-bench: tree build time and tightness against FCL's own builders.
//
//   tightbvh-build-bench [MESH...] [--repeats R] [--json FILE]
//       per mesh, in one run: FCL BVHModel<OBB> and BVHModel<OBBRSS> builds (PCA boxes, mean
//       split), our pca / approx / auto builds (threads = 1 unless --threads; built in turn, R
//       rounds, so that approx / pca and auto / pca are medians of same-round ratios), median
//       times, sums of node volumes and bytes per triangle (--no-tight: pca vs FCL only). Times
//       of one-thread builds are CPU time of the thread (the machine is shared), two-thread
//       ones wall clock.
//   tightbvh-build-bench --splits [MESH...]      sum of volumes per split method
//   tightbvh-build-bench --auto-sweep [MESH...]  time and volume of auto per pair of thresholds
//   tightbvh-build-bench --thread-scaling [MESH...] [--fitter F] [--threads T] [--repeats R]
//       wall time of one build on 1 thread and on T (default 2), alternating, medians of R
//       (default 7), the speed-up, and whether the trees are the same bit for bit.
//   tightbvh-build-bench --scale MESH --triangles N --fitter F [--threads T]
//       subdivides MESH 1->4 until it has >= N triangles, builds once, prints the row
//       | mesh | fitter | threads | triangles | wall s | peak MiB before | after | tree MiB |
//       depth | validated | sum of node volumes | (getrusage; one fitter per process for its peak).
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBB.h>
#include <fcl/math/bv/OBBRSS.h>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "tightbvh/build.hpp"
#include "tightbvh/validate_tree.hpp"
#include "../thread_clock.hpp"

namespace {

using namespace tightbvh;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The median time of `repeats` calls: CPU time of this thread when `one_thread` (FCL's builds and
// ours with threads = 1 run on the calling thread; the machine is shared, see thread_clock.hpp),
// else wall-clock time (the two-thread builds).
template <class Fn>
double median_seconds(int repeats, Fn&& fn, bool one_thread = true) {
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r) {
    if (one_thread) {
      const double start = bench_support::thread_seconds();
      fn();
      times.push_back(bench_support::thread_seconds() - start);
      continue;
    }
    const auto start = Clock::now();
    fn();
    times.push_back(seconds_since(start));
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

bool available(FitMethod method) {
  const std::vector<Vec3> corners{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  try {
    (void)fit_triangles(corners, FitOptions{.method = method});
    return true;
  } catch (const std::logic_error&) {
    return false;
  }
}

struct FclMesh {
  std::vector<fcl::Vector3d> vertices;
  std::vector<fcl::Triangle> triangles;
};

FclMesh to_fcl_input(const Mesh& mesh) {
  FclMesh out;
  for (const Vec3& v : mesh.vertices) out.vertices.emplace_back(v.x(), v.y(), v.z());
  for (const Triangle& t : mesh.triangles) out.triangles.emplace_back(t[0], t[1], t[2]);
  return out;
}

template <class BV>
struct FclResult {
  double seconds = 0;
  double sum_volume = 0;
  std::size_t nodes = 0;
  std::size_t bytes = 0;
};

template <class BV>
FclResult<BV> fcl_build(const FclMesh& input, int repeats) {
  FclResult<BV> r;
  r.seconds = median_seconds(repeats, [&] {
    fcl::BVHModel<BV> model;
    model.beginModel(static_cast<int>(input.triangles.size()), static_cast<int>(input.vertices.size()));
    model.addSubModel(input.vertices, input.triangles);
    model.endModel();
    r.nodes = static_cast<std::size_t>(model.getNumBVs());
    r.sum_volume = 0;
    for (int i = 0; i < model.getNumBVs(); ++i) r.sum_volume += model.getBV(i).bv.volume();
  });
  // The tree proper: the node array and the primitive index array (vertices/triangles not counted).
  r.bytes = r.nodes * sizeof(fcl::BVNode<BV>) + input.triangles.size() * sizeof(unsigned int);
  return r;
}

struct OurResult {
  bool ok = false;
  double seconds = 0;
  TreeStats stats;
};

// Our single-thread builds of several fitters timed in rounds (each fitter once per round, in
// turn), so that a ratio between two of them is the median of ratios taken in the same round:
// this shared machine's speed drifts between seconds (pca builds of 5 ms swung by +-20% when each
// fitter's repeats ran back to back). Each result's `seconds` is still its own median.
struct Interleaved {
  std::vector<OurResult> results;
  std::vector<std::vector<double>> seconds;  // [fitter][round]
  // The median over rounds of fitter i's time over fitter j's (both available).
  [[nodiscard]] double ratio(std::size_t i, std::size_t j) const {
    std::vector<double> r;
    for (std::size_t k = 0; k < seconds[i].size(); ++k) r.push_back(seconds[i][k] / seconds[j][k]);
    std::sort(r.begin(), r.end());
    return r[r.size() / 2];
  }
};

// Whether this build's fitters exist in this build of the library (some need optional dependencies).
bool fitter_available(const BuildOptions& options) {
  if (const auto* m = std::get_if<FitMethod>(&options.fitter)) return available(*m);
  const AutoFit& a = std::get<AutoFit>(options.fitter);
  return available(a.tight) && available(a.medium) && available(a.cheap);
}

OurResult our_build(const Mesh& mesh, const BuildOptions& options, int repeats) {
  OurResult r;
  if (!fitter_available(options)) return r;
  Tree tree;
  r.seconds = median_seconds(repeats, [&] { tree = build(mesh, options); }, options.threads == 1);
  if (const TreeCheck check = validate(tree, mesh); !check.ok())
    throw std::runtime_error("invalid tree: " + check.errors[0]);
  r.stats = tree_stats(tree);
  r.ok = true;
  return r;
}

Interleaved interleaved_builds(const Mesh& mesh, const std::vector<BuildOptions>& options, int repeats) {
  Interleaved out;
  out.results.resize(options.size());
  out.seconds.resize(options.size());
  std::vector<Tree> trees(options.size());
  for (std::size_t i = 0; i < options.size(); ++i) out.results[i].ok = fitter_available(options[i]);
  for (int round = 0; round < repeats; ++round)
    for (std::size_t i = 0; i < options.size(); ++i) {
      if (!out.results[i].ok) continue;
      out.seconds[i].push_back(median_seconds(1, [&] { trees[i] = build(mesh, options[i]); }, options[i].threads == 1));
    }
  for (std::size_t i = 0; i < options.size(); ++i) {
    OurResult& r = out.results[i];
    if (!r.ok) continue;
    if (const TreeCheck check = validate(trees[i], mesh); !check.ok())
      throw std::runtime_error("invalid tree: " + check.errors[0]);
    r.stats = tree_stats(trees[i]);
    std::vector<double> sorted = out.seconds[i];
    std::sort(sorted.begin(), sorted.end());
    r.seconds = sorted[sorted.size() / 2];
  }
  return out;
}

BuildOptions options_for(const Fitter& fitter, unsigned threads, SplitMethod split = SplitMethod::rapid) {
  BuildOptions o;
  o.fitter = fitter;
  o.threads = threads;
  o.split = split;
  return o;
}

std::string fmt(double v, const char* f = "%.3g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string name_of(const std::filesystem::path& p) { return p.filename().string(); }

std::vector<std::filesystem::path> default_meshes() {
  const std::filesystem::path root = TIGHTBVH_SOURCE_DIR;
  std::vector<std::filesystem::path> out{root / "meshes/elephant.off", root / "meshes/knot1.off"};
  for (const char* name : {"cow.off", "ChineseDragon-10kv.off", "camel.off", "fandisk_large.off", "man.off",
                           "armadillo.off", "bunny00.off", "refined_elephant.off"}) {
    const auto p = root / "meshes/corpus/cgal" / name;
    if (std::filesystem::exists(p)) out.push_back(p);
  }
  return out;
}

// ------------------------------------------------------------------ main comparison

int compare(const std::vector<std::filesystem::path>& meshes, int repeats, unsigned threads, const std::string& json_out,
            bool tight) {
  nlohmann::json all = nlohmann::json::array();
  std::printf("threads = %u for our builds (FCL is single-threaded); times are medians of %d runs\n", threads, repeats);
  std::printf("pca, approx and auto are built in turn, %d rounds; approx / pca and auto / pca are medians of same-round ratios\n",
              repeats);
  const unsigned all_threads = std::max(1u, std::thread::hardware_concurrency());
  std::printf("pca T%u: our pca build with all %u hardware threads\n", all_threads, all_threads);
  std::printf("| mesh | triangles | FCL OBB s | FCL OBBRSS s | pca s | FCL OBB / pca | pca T%u s | FCL OBB / pca T%u | approx s |",
              all_threads, all_threads);
  std::printf(" approx / pca | auto s | "
              "auto / pca | vol approx/pca | vol auto/pca | gain auto/approx | vol FCL-OBB/pca | B/tri ours | "
              "B/tri FCL OBB |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& path : meshes) {
    const Mesh mesh = load_mesh(path);
    const FclMesh input = to_fcl_input(mesh);
    const auto obb = fcl_build<fcl::OBBd>(input, repeats);
    const auto obbrss = fcl_build<fcl::OBBRSSd>(input, repeats);
    // pca, approx and auto in rounds (Interleaved): their time ratios are medians of same-round ratios.
    std::vector<BuildOptions> in_turn{options_for(FitMethod::pca, threads)};
    if (tight) in_turn.push_back(options_for(FitMethod::approx, threads)), in_turn.push_back(options_for(AutoFit{}, threads));
    const Interleaved rounds = interleaved_builds(mesh, in_turn, repeats);
    const OurResult& pca = rounds.results[0];
    const OurResult pca_all = our_build(mesh, options_for(FitMethod::pca, all_threads), repeats);
    const OurResult approx = tight ? rounds.results[1] : OurResult{};
    const OurResult automatic = tight ? rounds.results[2] : OurResult{};
    const auto volume_ratio = [](const OurResult& a, double b) -> std::string {
      return a.ok ? fmt(a.stats.sum_volume / b, "%.3f") : std::string("n/a");
    };
    const auto time_ratio = [&](std::size_t i) -> std::string {
      return tight && rounds.results[i].ok ? fmt(rounds.ratio(i, 0), "%.3f") : std::string("n/a");
    };
    const auto secs = [](const OurResult& a) { return a.ok ? fmt(a.seconds, "%.4f") : std::string("n/a"); };
    // The measure of tightness: gain(f) = 1 - sum vol(f tree) / sum vol(pca tree).
    const std::string gain_ratio =
        approx.ok && automatic.ok
            ? fmt((1 - automatic.stats.sum_volume / pca.stats.sum_volume) / (1 - approx.stats.sum_volume / pca.stats.sum_volume),
                  "%.3f")
            : std::string("n/a");
    std::printf("| %s | %zu | %.4f | %.4f | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %.3f | %.1f | %.1f |\n",
                name_of(path).c_str(), mesh.triangles.size(), obb.seconds, obbrss.seconds, secs(pca).c_str(),
                fmt(obb.seconds / pca.seconds, "%.2f").c_str(), secs(pca_all).c_str(),
                fmt(obb.seconds / pca_all.seconds, "%.2f").c_str(), secs(approx).c_str(),
                time_ratio(1).c_str(), secs(automatic).c_str(), time_ratio(2).c_str(),
                volume_ratio(approx, pca.stats.sum_volume).c_str(), volume_ratio(automatic, pca.stats.sum_volume).c_str(),
                gain_ratio.c_str(), obb.sum_volume / pca.stats.sum_volume,
                pca.stats.bytes_per_triangle, static_cast<double>(obb.bytes) / mesh.triangles.size());
    std::fflush(stdout);
    const auto ours = [](const OurResult& r) -> nlohmann::json {
      if (!r.ok) return nullptr;
      return {{"seconds", r.seconds}, {"sum_volume", r.stats.sum_volume}, {"nodes", r.stats.nodes},
              {"depth_max", r.stats.depth_max}, {"bytes", r.stats.bytes}};
    };
    all.push_back({{"mesh", name_of(path)},
                   {"triangles", mesh.triangles.size()},
                   {"fcl_obb", {{"seconds", obb.seconds}, {"sum_volume", obb.sum_volume}, {"nodes", obb.nodes}, {"bytes", obb.bytes}}},
                   {"fcl_obbrss", {{"seconds", obbrss.seconds}, {"nodes", obbrss.nodes}, {"bytes", obbrss.bytes}}},
                   {"pca", ours(pca)},
                   {"pca_all_threads", ours(pca_all)},
                   {"approx", ours(approx)},
                   {"auto", ours(automatic)},
                   {"repeats", repeats},
                   {"threads", threads},
                   {"approx_over_pca_time", tight && approx.ok ? nlohmann::json(rounds.ratio(1, 0)) : nlohmann::json(nullptr)},
                   {"auto_over_pca_time", tight && automatic.ok ? nlohmann::json(rounds.ratio(2, 0)) : nlohmann::json(nullptr)}});
  }
  if (!json_out.empty()) std::ofstream(json_out) << all.dump(2) << '\n';
  return 0;
}

// ------------------------------------------------------------------ split methods

int splits(const std::vector<std::filesystem::path>& meshes, unsigned threads) {
  std::printf("sum of node volumes (and build seconds, max depth) per split; leaf size 1\n");
  std::printf("| mesh | fitter | rapid | median | binned | median/rapid | binned/rapid |\n|---|---|---|---|---|---|---|\n");
  for (const auto& path : meshes) {
    const Mesh mesh = load_mesh(path);
    for (const Fitter fitter : {Fitter{FitMethod::pca}, Fitter{AutoFit{}}}) {
      OurResult r[3];
      int i = 0;
      for (const SplitMethod split : {SplitMethod::rapid, SplitMethod::median, SplitMethod::binned})
        r[i++] = our_build(mesh, options_for(fitter, threads, split), 1);
      if (!r[0].ok) continue;
      const auto cell = [](const OurResult& x) {
        return fmt(x.stats.sum_volume, "%.4g") + " (" + fmt(x.seconds, "%.3f") + " s, d" +
               std::to_string(x.stats.depth_max) + ")";
      };
      std::printf("| %s | %s | %s | %s | %s | %.3f | %.3f |\n", name_of(path).c_str(), to_string(fitter).c_str(),
                  cell(r[0]).c_str(), cell(r[1]).c_str(), cell(r[2]).c_str(),
                  r[1].stats.sum_volume / r[0].stats.sum_volume, r[2].stats.sum_volume / r[0].stats.sum_volume);
      std::fflush(stdout);
    }
  }
  return 0;
}

// ------------------------------------------------------------------ auto threshold

int auto_sweep(const std::vector<std::filesystem::path>& meshes, unsigned threads, int repeats) {
  std::printf("auto = approx on nodes with >= T triangles, approx-kernel on nodes with >= M, normal-bopt below, the AABB\n"
              "where smaller; time relative to pca, gain = 1 - sum vol / sum vol(pca), relative to approx's gain\n");
  std::printf("| mesh | T | M | seconds | time / pca | volume / pca | gain / approx's |\n|---|---|---|---|---|---|---|\n");
  for (const auto& path : meshes) {
    const Mesh mesh = load_mesh(path);
    const OurResult pca = our_build(mesh, options_for(FitMethod::pca, threads), repeats);
    const OurResult approx = our_build(mesh, options_for(FitMethod::approx, threads), 1);
    const double approx_gain = 1 - approx.stats.sum_volume / pca.stats.sum_volume;
    for (const std::uint32_t t : {512u, 1024u, 2048u, 8192u, 1u << 30})
      for (const std::uint32_t m : {32u, 64u, 128u, 1u << 30}) {
        if (m > t) continue;
        const AutoFit policy{.tight_min_triangles = t, .medium_min_triangles = m};
        const OurResult r = our_build(mesh, options_for(policy, threads), repeats);
        const double volume = r.stats.sum_volume / pca.stats.sum_volume;
        std::printf("| %s | %u | %u | %.4f | %.2f | %.4f | %.3f |\n", name_of(path).c_str(), t, m, r.seconds,
                    r.seconds / pca.seconds, volume, (1 - volume) / approx_gain);
        std::fflush(stdout);
      }
  }
  return 0;
}

// ------------------------------------------------------------------ scale

double peak_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: KiB
}

int scale(const std::filesystem::path& path, std::size_t triangles, const std::string& fitter_name, unsigned threads,
          bool check) {
  const auto fitter = parse_fitter(fitter_name);
  if (!fitter) throw std::runtime_error("unknown fitter " + fitter_name);
  Mesh mesh = load_mesh(path);
  while (mesh.triangles.size() < triangles) mesh = subdivide_midpoints(mesh);
  const double before = peak_mib();
  const auto start = Clock::now();
  const Tree tree = build(mesh, options_for(*fitter, threads));
  const double seconds = seconds_since(start);
  const double after = peak_mib();
  const TreeStats s = tree_stats(tree);
  std::string valid = "not checked";
  if (check) valid = validate(tree, mesh).ok() ? "valid" : "INVALID";
  std::printf("| %s x%zu | %s | %u | %zu | %.2f | %.0f | %.0f | %.1f | %zu | %s | %.6g |\n", name_of(path).c_str(),
              mesh.triangles.size(), fitter_name.c_str(), threads, mesh.triangles.size(), seconds, before, after,
              static_cast<double>(s.bytes) / (1024.0 * 1024.0), s.depth_max, valid.c_str(), s.sum_volume);
  return 0;
}

int thread_scaling(const std::vector<std::filesystem::path>& meshes, const std::string& fitter_name,
                   unsigned threads, int repeats) {
  const auto fitter = parse_fitter(fitter_name);
  if (!fitter) throw std::runtime_error("unknown fitter " + fitter_name);
  std::printf("| mesh | triangles | fitter | 1 thread s | %u threads s | speed-up | same tree |\n|---|---|---|---|---|---|---|\n",
              threads);
  for (const auto& path : meshes) {
    const Mesh mesh = load_mesh(path.string());
    std::vector<double> one, many;
    bool same = true;
    for (int r = 0; r < repeats; ++r) {  // alternating, so a change of machine load hits both
      Tree trees[2];
      for (int k = 0; k < 2; ++k) {
        const auto start = Clock::now();
        trees[k] = build(mesh, {.fitter = *fitter, .threads = k == 0 ? 1u : threads});
        (k == 0 ? one : many).push_back(seconds_since(start));
      }
      same = same && trees[0].triangle_order == trees[1].triangle_order &&
             trees[0].nodes.size() == trees[1].nodes.size() &&
             std::memcmp(trees[0].nodes.data(), trees[1].nodes.data(), trees[0].nodes.size() * sizeof(Node)) == 0;
    }
    std::sort(one.begin(), one.end());
    std::sort(many.begin(), many.end());
    const double t1 = one[one.size() / 2], tn = many[many.size() / 2];
    std::printf("| %s | %zu | %s | %.4f | %.4f | %.2f | %s |\n", name_of(path).c_str(), mesh.triangles.size(),
                fitter_name.c_str(), t1, tn, t1 / tn, same ? "yes" : "NO");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<std::filesystem::path> meshes;
    std::string mode = "compare", json_out, fitter = "pca";
    int repeats = 3;
    unsigned threads = 1;
    std::size_t triangles = 1000000;
    bool check = false, tight = true, repeats_given = false, threads_given = false, fitter_given = false;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      const auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
        return argv[++i];
      };
      if (a == "--splits") mode = "splits";
      else if (a == "--auto-sweep") mode = "auto";
      else if (a == "--scale") mode = "scale";
      else if (a == "--thread-scaling") mode = "threads";
      else if (a == "--repeats") repeats = std::stoi(next()), repeats_given = true;
      else if (a == "--threads") threads = static_cast<unsigned>(std::stoul(next())), threads_given = true;
      else if (a == "--json") json_out = next();
      else if (a == "--fitter") fitter = next(), fitter_given = true;
      else if (a == "--triangles") triangles = std::stoul(next());
      else if (a == "--validate") check = true;
      else if (a == "--no-tight") tight = false;  // compare: skip the (slow) approx and auto builds
      else if (a.rfind("--", 0) == 0) throw std::runtime_error("unknown option " + a);
      else meshes.emplace_back(a);
    }
    if (meshes.empty()) meshes = default_meshes();
    if (mode == "splits") return splits(meshes, threads);
    if (mode == "auto") return auto_sweep(meshes, threads, repeats);
    if (mode == "scale") return scale(meshes.at(0), triangles, fitter, threads, check);
    if (mode == "threads") return thread_scaling(meshes, fitter_given ? fitter : "auto",
                                                 threads_given ? threads : 2, repeats_given ? repeats : 7);
    return compare(meshes, repeats, threads, json_out, tight);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tightbvh-build-bench: error: %s\n", e.what());
    return 1;
  }
}
