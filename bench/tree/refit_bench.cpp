// tightbvh-refit-bench: refit of deforming meshes against FCL's refit, and what refit vs rebuild
// does to query speed.
//
//   tightbvh-refit-bench [MESH...] [--frames F] [--repeats R] [--poses N] [--no-queries] [--json FILE]
//       per mesh and deformation (a travelling sine wave and a bend, amplitude growing over F
//       frames): median time per refit of ours (pca fast path, threads 1 and 2) and of FCL's
//       BVHModel<OBB> / <OBBRSS> (beginUpdateModel, updateVertex per vertex, endUpdateModel with
//       bottomup true and false), and the sums of node volumes at the last frame. Then, at the
//       last frame, first_hit and all_pairs queries/s (one thread) of the deformed mesh against
//       the undeformed one, "near" poses, on (a) fresh builds and (b) refitted trees. --json:
//       both tables' numbers (seconds, not ms) in FILE as well.
//   tightbvh-refit-bench --fitters [MESH...] [--frames F] [--repeats R]
//       time and sum of volumes of refit with pca, pca-vertex, aabb and auto at the last frame,
//       against rebuilding with pca and auto (the choice of the default refit fitter).
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBB.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/math/bv/utility.h>  // fit(), used by BVHModel::refitTree_bottomup

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "../query/poses.hpp"
#include "../thread_clock.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/refit.hpp"
#include "tightbvh/tree_stats.hpp"
#include "tightbvh/validate_tree.hpp"

namespace {

using namespace tightbvh;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// ------------------------------------------------------------------
// deformations

enum class Kind { sine, bend };
const char* name_of(Kind k) { return k == Kind::sine ? "sine wave" : "bend"; }

// Frame f of `frames` (amplitude growing linearly to its maximum at the last frame):
//   sine: y += a sin(2 pi (2 x / extent - f / frames)), a up to 15% of the x
//   extent (travelling); bend: around the z axis, x becoming an arc of up to
//   270 degrees.
Mesh deformed(const Mesh& rest, Kind kind, int f, int frames) {
  Mesh mesh = rest;
  const Aabb bounds = bounds_of(rest.vertices);
  const double length = bounds.max.x() - bounds.min.x();
  const double t = static_cast<double>(f + 1) / frames;
  if (kind == Kind::sine) {
    const double amplitude = 0.15 * length * t;
    for (Vec3& v : mesh.vertices)
      v.y() += amplitude * std::sin(2.0 * std::numbers::pi * (2.0 * (v.x() - bounds.min.x()) / length - t));
    return mesh;
  }
  const double radius = length / (1.5 * std::numbers::pi * t);
  const Vec3 c = bounds.center();
  for (Vec3& v : mesh.vertices) {
    const double theta = (v.x() - c.x()) / radius;
    const double r = radius - (v.y() - c.y());
    v = Vec3(c.x() + r * std::sin(theta), c.y() + radius - r * std::cos(theta), v.z());
  }
  return mesh;
}

// ------------------------------------------------------------------ FCL

template <class BV>
struct FclModel {
  fcl::BVHModel<BV> model;

  explicit FclModel(const Mesh& mesh) {
    std::vector<fcl::Vector3d> vertices;
    std::vector<fcl::Triangle> triangles;
    for (const Vec3& v : mesh.vertices) vertices.emplace_back(v.x(), v.y(), v.z());
    for (const Triangle& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
    model.beginModel(static_cast<int>(triangles.size()), static_cast<int>(vertices.size()));
    model.addSubModel(vertices, triangles);
    model.endModel();
  }

  void refit(const Mesh& mesh, bool bottomup) {
    model.beginUpdateModel();
    for (const Vec3& v : mesh.vertices) model.updateVertex(fcl::Vector3d(v.x(), v.y(), v.z()));
    model.endUpdateModel(true, bottomup);
  }

  [[nodiscard]] static const fcl::OBBd& obb(const fcl::OBBd& bv) { return bv; }
  [[nodiscard]] static const fcl::OBBd& obb(const fcl::OBBRSSd& bv) { return bv.obb; }

  [[nodiscard]] double sum_volume() const {
    double sum = 0;
    for (int i = 0; i < model.getNumBVs(); ++i) sum += 8.0 * obb(model.getBV(i).bv).extent.prod();
    return sum;
  }

  // Nodes whose OBB misses a corner of one of their triangles (relative tolerance 1e-9).
  [[nodiscard]] std::size_t nodes_not_containing(const Mesh& mesh) const {
    std::size_t bad = 0;
    std::vector<std::uint32_t> triangles;
    for (int i = 0; i < model.getNumBVs(); ++i) {
      triangles.clear();
      collect(i, triangles);
      const fcl::OBBd& box = obb(model.getBV(i).bv);
      const double tolerance = 1e-9 * (1.0 + box.extent.norm() + box.To.norm());
      bool ok = true;
      for (const std::uint32_t t : triangles)
        for (const Vec3& p : mesh.corners(t))
          ok = ok && ((box.axis.transpose() * (p - box.To)).cwiseAbs() - box.extent).maxCoeff() <= tolerance;
      bad += !ok;
    }
    return bad;
  }

 private:
  void collect(int i, std::vector<std::uint32_t>& out) const {
    const auto& node = model.getBV(i);
    if (node.isLeaf()) return out.push_back(static_cast<std::uint32_t>(-(node.first_child + 1)));
    collect(node.leftChild(), out);
    collect(node.rightChild(), out);
  }
};

// ------------------------------------------------------------------ refit timing

struct Timings {
  std::vector<double> ours_t1, ours_t2, obb_up, obb_down, obbrss_up, obbrss_down;
};

struct LastFrame {
  double ours = 0, obb_up = 0, obb_down = 0, obbrss_up = 0, fresh_pca = 0, fresh_auto = 0;
  std::size_t obb_up_bad = 0, obb_down_bad = 0, obbrss_up_bad = 0;
  bool ours_valid = false;
};

// Best of `repeats` runs in CPU time of this thread (the machine is shared: wall-clock time would
// charge other processes' load to the refit); `wall` for the multi-threaded runs.
template <class Fn>
double best_of(int repeats, Fn&& fn, bool wall = false) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto start = Clock::now();
    const double cpu_start = bench_support::thread_seconds();
    fn();
    best = std::min(best, wall ? seconds_since(start) : bench_support::thread_seconds() - cpu_start);
  }
  return best;
}

// FCL's refit fits previous and current vertices together (a swept box, for continuous collision);
// the volumes are read after a second, untimed update with the same vertices, so both libraries'
// boxes bound the same frame.
template <class BV>
void fcl_frame(FclModel<BV>& model, const Mesh& mesh, bool bottomup, int repeats, std::vector<double>& times) {
  times.push_back(best_of(repeats, [&] { model.refit(mesh, bottomup); }));
  model.refit(mesh, bottomup);
}

LastFrame run_frames(const Mesh& rest, Kind kind, int frames, int repeats, Tree& tree, Timings& t) {
  FclModel<fcl::OBBd> obb_up(rest), obb_down(rest);
  FclModel<fcl::OBBRSSd> obbrss_up(rest), obbrss_down(rest);
  LastFrame last;
  for (int f = 0; f < frames; ++f) {
    const Mesh mesh = deformed(rest, kind, f, frames);
    t.ours_t2.push_back(best_of(
        repeats, [&] { refit(tree, mesh, {.threads = 2}); }, true));
    t.ours_t1.push_back(best_of(repeats, [&] { refit(tree, mesh, {.threads = 1}); }));
    fcl_frame(obb_up, mesh, true, repeats, t.obb_up);
    fcl_frame(obb_down, mesh, false, repeats, t.obb_down);
    fcl_frame(obbrss_up, mesh, true, repeats, t.obbrss_up);
    fcl_frame(obbrss_down, mesh, false, repeats, t.obbrss_down);
    if (f + 1 < frames) continue;
    last.ours = tree_stats(tree).sum_volume;
    last.ours_valid = validate(tree, mesh).ok();
    last.obb_up = obb_up.sum_volume();
    last.obb_down = obb_down.sum_volume();
    last.obbrss_up = obbrss_up.sum_volume();
    last.obb_up_bad = obb_up.nodes_not_containing(mesh);
    last.obb_down_bad = obb_down.nodes_not_containing(mesh);
    last.obbrss_up_bad = obbrss_up.nodes_not_containing(mesh);
    last.fresh_pca = tree_stats(build(mesh, {.fitter = FitMethod::pca, .threads = 1})).sum_volume;
    last.fresh_auto = tree_stats(build(mesh, {.threads = 1})).sum_volume;
  }
  return last;
}

// ------------------------------------------------------------------ queries after the deformation

struct QueryRow {
  std::string tree;
  double seconds = 0;  // build or refit
  double sum_volume = 0;
  double first_hit_qps = 0, all_pairs_qps = 0, first_hit_boxes = 0, all_pairs_boxes = 0;
};

QueryRow query_row(std::string name, double seconds, const Tree& a, const Mesh& ma, const Tree& b, const Mesh& mb,
                   const std::vector<Pose>& poses) {
  QueryRow row{std::move(name), seconds, tree_stats(a).sum_volume};
  for (const QueryMode mode : {QueryMode::first_hit, QueryMode::all_pairs}) {
    std::vector<QueryResult> results;
    const double s = best_of(3, [&] { results = collide_batch(a, ma, Pose{}, b, mb, poses, {.mode = mode}, 1); });
    double boxes = 0;
    for (const QueryResult& r : results) boxes += static_cast<double>(r.stats.box_tests);
    (mode == QueryMode::first_hit ? row.first_hit_qps : row.all_pairs_qps) = static_cast<double>(poses.size()) / s;
    (mode == QueryMode::first_hit ? row.first_hit_boxes : row.all_pairs_boxes) = boxes / poses.size();
  }
  return row;
}

nlohmann::json queries(const std::string& mesh_name, const Mesh& rest, Kind kind, int frames, int count) {
  const Mesh mesh = deformed(rest, kind, frames - 1, frames);
  const Tree b = build(rest, {.threads = 1});  // the other object: the undeformed mesh, default tree
  const Tree fresh_auto = build(mesh, {.threads = 1});
  const auto collides = [&](const Pose& pose) { return collide(fresh_auto, mesh, Pose{}, b, rest, pose).hit; };
  const std::vector<Pose> poses = bench::generate_poses(mesh, rest, bench::Scenario::near, count, 11, collides);
  std::vector<QueryRow> rows;
  for (const Fitter& fitter : {Fitter{AutoFit{}}, Fitter{FitMethod::pca}}) {
    Tree fresh;
    const double s = best_of(1, [&] { fresh = build(mesh, {.fitter = fitter, .threads = 1}); });
    rows.push_back(query_row("rebuild " + to_string(fitter), s, fresh, mesh, b, rest, poses));
  }
  for (const Fitter& fitter : {Fitter{AutoFit{}}, Fitter{FitMethod::pca}}) {
    Tree tree = build(rest, {.fitter = fitter, .threads = 1});
    const double s = best_of(3, [&] { refit(tree, mesh, {.threads = 1}); });
    rows.push_back(query_row("refit pca of a rest " + to_string(fitter) + " tree", s, tree, mesh, b, rest, poses));
  }
  for (const QueryRow& r : rows)
    std::printf("| %s | %s | %s | %.1f | %.4g | %.0f | %.0f | %.0f | %.0f |\n", mesh_name.c_str(), name_of(kind),
                r.tree.c_str(), 1e3 * r.seconds, r.sum_volume, r.first_hit_qps, r.first_hit_boxes, r.all_pairs_qps,
                r.all_pairs_boxes);
  std::fflush(stdout);
  nlohmann::json out = nlohmann::json::array();
  for (const QueryRow& r : rows)
    out.push_back({{"mesh", mesh_name},
                   {"deformation", name_of(kind)},
                   {"tree", r.tree},
                   {"poses", poses.size()},
                   {"seconds", r.seconds},
                   {"sum_volume", r.sum_volume},
                   {"first_hit_qps", r.first_hit_qps},
                   {"first_hit_box_tests", r.first_hit_boxes},
                   {"all_pairs_qps", r.all_pairs_qps},
                   {"all_pairs_box_tests", r.all_pairs_boxes}});
  return out;
}

// The refit fitter: CPU time and sum of volumes of refit with each cheap-to-tight fitter, at the
// last frame, against rebuilding with pca and auto.
void fitters(const std::string& mesh_name, const Mesh& rest, Kind kind, int frames, int repeats) {
  const Mesh mesh = deformed(rest, kind, frames - 1, frames);
  const Tree rest_tree = build(rest, {.threads = 1});
  for (const Fitter& fitter :
       {Fitter{FitMethod::pca}, Fitter{FitMethod::pca_vertex}, Fitter{FitMethod::aabb}, Fitter{AutoFit{}}}) {
    Tree tree = rest_tree;
    const double s = best_of(repeats, [&] { refit(tree, mesh, {.fitter = fitter, .threads = 1}); });
    std::printf("| %s | %s | refit %s | %.1f | %.4g |\n", mesh_name.c_str(), name_of(kind), to_string(fitter).c_str(),
                1e3 * s, tree_stats(tree).sum_volume);
  }
  for (const Fitter& fitter : {Fitter{FitMethod::pca}, Fitter{AutoFit{}}}) {
    Tree tree;
    const double s = best_of(repeats, [&] { tree = build(mesh, {.fitter = fitter, .threads = 1}); });
    std::printf("| %s | %s | rebuild %s | %.1f | %.4g |\n", mesh_name.c_str(), name_of(kind), to_string(fitter).c_str(),
                1e3 * s, tree_stats(tree).sum_volume);
  }
  std::fflush(stdout);
}

std::vector<std::filesystem::path> default_meshes() {
  const std::filesystem::path root = TIGHTBVH_SOURCE_DIR;
  std::vector<std::filesystem::path> out;
  for (const char* name : {"armadillo.off", "bunny00.off", "camel.off"}) {
    const auto p = root / "meshes/corpus/cgal" / name;
    if (std::filesystem::exists(p)) out.push_back(p);
  }
  if (out.empty()) out = {root / "meshes/camel.off", root / "meshes/elephant.off"};
  return out;
}

struct Options {
  std::vector<std::filesystem::path> meshes;
  int frames = 20, repeats = 3, poses = 200;
  std::string json;  // --json FILE
  bool queries = true;
  bool fitters = false;  // only the table of refit fitters
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--json") {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      o.json = argv[++i];
      continue;
    }
    const auto next = [&]() -> int {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      const int value = std::stoi(argv[++i]);
      if (value < 1) throw std::runtime_error(a + " must be at least 1");
      return value;
    };
    if (a == "--frames")
      o.frames = next();
    else if (a == "--repeats")
      o.repeats = next();
    else if (a == "--poses")
      o.poses = next();
    else if (a == "--no-queries")
      o.queries = false;
    else if (a == "--fitters")
      o.fitters = true;
    else if (a.rfind("--", 0) == 0)
      throw std::runtime_error("unknown option " + a);
    else
      o.meshes.emplace_back(a);
  }
  if (o.meshes.empty()) o.meshes = default_meshes();
  return o;
}

}  // namespace

int main(int argc, char** argv) try {
  const Options o = parse(argc, argv);
  std::vector<std::pair<std::string, Mesh>> meshes;
  for (const auto& path : o.meshes) meshes.emplace_back(path.filename().string(), load_mesh(path));
  if (o.fitters) {
    std::printf("refit fitters at the last frame (rest-pose default tree), CPU ms of one thread, best of %d\n\n",
                o.repeats);
    std::printf("| mesh | deformation | what | ms | sum vol |\n|---|---|---|---|---|\n");
    for (const auto& [name, rest] : meshes)
      for (const Kind kind : {Kind::sine, Kind::bend}) fitters(name, rest, kind, o.frames, o.repeats);
    return 0;
  }
  std::printf(
      "refit: median over %d frames of the best of %d runs, CPU time of the thread (T2: wall clock, 2 threads); "
      "ours = refit(tree, mesh), default pca fitter, of a rest-pose default (auto) tree; FCL: beginUpdateModel, "
      "updateVertex per vertex, endUpdateModel(true, bottomup: up / down); volumes at the last frame; 'bad' = nodes "
      "whose box misses a corner of their triangles\n\n",
      o.frames, o.repeats);
  std::printf(
      "| mesh | triangles | deformation | ours T1 ms | ours T2 ms (wall) | FCL OBB up ms | FCL OBB down ms "
      "| FCL OBBRSS up ms | FCL OBBRSS down ms | FCL OBB up / ours T1 | vol ours | vol FCL OBB up / ours "
      "| vol FCL OBB down / ours | vol rebuild pca / ours | vol rebuild auto / ours "
      "| bad FCL OBB up / down / OBBRSS up | ours valid |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  nlohmann::json refits = nlohmann::json::array(), after = nlohmann::json::array();
  const auto write_json = [&] {
    if (o.json.empty()) return;
    std::ofstream out(o.json);
    out << nlohmann::json{{"frames", o.frames}, {"repeats", o.repeats}, {"poses", o.queries ? o.poses : 0},
                          {"refit", refits}, {"queries", after}}
               .dump(2)
        << '\n';
    if (!out) throw std::runtime_error(o.json + ": write failed");
  };
  for (const auto& [name, rest] : meshes)
    for (const Kind kind : {Kind::sine, Kind::bend}) {
      Tree tree = build(rest, {.threads = 1});
      Timings t;
      const LastFrame l = run_frames(rest, kind, o.frames, o.repeats, tree, t);
      const double ours = median(t.ours_t1);
      std::printf(
          "| %s | %zu | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | "
          "%.2f | %.4g | %.3f | %.3f | %.3f | %.3f | "
          "%zu / %zu / %zu | %s |\n",
          name.c_str(), rest.triangles.size(), name_of(kind), 1e3 * ours, 1e3 * median(t.ours_t2),
          1e3 * median(t.obb_up), 1e3 * median(t.obb_down), 1e3 * median(t.obbrss_up), 1e3 * median(t.obbrss_down),
          median(t.obb_up) / ours, l.ours, l.obb_up / l.ours, l.obb_down / l.ours, l.fresh_pca / l.ours,
          l.fresh_auto / l.ours, l.obb_up_bad, l.obb_down_bad, l.obbrss_up_bad, l.ours_valid ? "yes" : "NO");
      std::fflush(stdout);
      refits.push_back({{"mesh", name},
                        {"triangles", rest.triangles.size()},
                        {"deformation", name_of(kind)},
                        {"ours_t1_seconds", ours},
                        {"ours_t2_wall_seconds", median(t.ours_t2)},
                        {"fcl_obb_up_seconds", median(t.obb_up)},
                        {"fcl_obb_down_seconds", median(t.obb_down)},
                        {"fcl_obbrss_up_seconds", median(t.obbrss_up)},
                        {"fcl_obbrss_down_seconds", median(t.obbrss_down)},
                        {"volume_ours", l.ours},
                        {"volume_fcl_obb_up", l.obb_up},
                        {"volume_fcl_obb_down", l.obb_down},
                        {"volume_fcl_obbrss_up", l.obbrss_up},
                        {"volume_rebuild_pca", l.fresh_pca},
                        {"volume_rebuild_auto", l.fresh_auto},
                        {"bad_fcl_obb_up", l.obb_up_bad},
                        {"bad_fcl_obb_down", l.obb_down_bad},
                        {"bad_fcl_obbrss_up", l.obbrss_up_bad},
                        {"ours_valid", l.ours_valid}});
    }
  if (!o.queries) {
    write_json();
    return 0;
  }
  std::printf(
      "\nqueries at the last frame: deformed mesh (tree below) vs the "
      "undeformed mesh (default tree), %d near "
      "poses, one thread; ms = build or refit time\n\n",
      o.poses);
  std::printf(
      "| mesh | deformation | tree of the deformed mesh | ms | sum vol "
      "| first_hit q/s | box tests | all_pairs "
      "q/s | box tests |\n|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [name, rest] : meshes)
    for (const Kind kind : {Kind::sine, Kind::bend})
      for (auto& row : queries(name, rest, kind, o.frames, o.poses)) after.push_back(std::move(row));
  write_json();
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "tightbvh-refit-bench: error: %s\n", e.what());
  return 1;
}
