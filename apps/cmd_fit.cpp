// tightbvh fit MESH --method METHOD|all [--grid K] [--epsilon E] [--json]
// (METHOD: any name of fit_method_names(), fit.hpp)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <vector>

#include "commands.hpp"
#include "names.hpp"
#include "tightbvh/fit.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::cli {
namespace {

struct Args {
  std::string mesh;
  std::string method = "approx";
  int grid = FitOptions{}.grid;
  double epsilon = 0.0;
  bool json = false;
};

struct Row {
  FitMethod method;
  Obb box;
  std::size_t hull_vertices = 0;
  double seconds = 0.0;
};

[[nodiscard]] std::vector<FitMethod> parse_methods(const std::string& name) {
  if (name == "all") return {all_fit_methods().begin(), all_fit_methods().end()};
  if (const auto m = parse_fit_method(name)) return {*m};
  throw InputError("unknown fit method '" + name + "' (expected " + one_of(with(fit_method_names(), "all")) + ")");
}

[[nodiscard]] std::vector<Row> fit_mesh(const Mesh& mesh, const std::vector<FitMethod>& methods, FitOptions options) {
  const std::vector<Vec3> corners = triangle_corners(mesh);
  FitWorkspace workspace;
  std::vector<Row> rows;
  for (const FitMethod method : methods) {
    options.method = method;
    const auto start = std::chrono::steady_clock::now();
    // pca weights the triangles by area; every other method only needs the vertices.
    const Obb box = method == FitMethod::pca ? fit_triangles(corners, options, workspace)
                                             : fit_points(mesh.vertices, options, workspace);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    rows.push_back({method, box, workspace.last_hull_vertices(), seconds});
  }
  return rows;
}

void print_rows(const std::vector<Row>& rows, bool json) {
  if (json) {
    const auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
    nlohmann::json out = nlohmann::json::array();
    for (const Row& r : rows)
      out.push_back({{"method", std::string(to_string(r.method))},
                     {"volume", r.box.volume()},
                     {"center", vec(r.box.center)},
                     {"axes", {vec(r.box.axes.col(0)), vec(r.box.axes.col(1)), vec(r.box.axes.col(2))}},
                     {"half_extents", vec(r.box.half_extents)},
                     {"hull_vertices", r.hull_vertices},
                     {"seconds", r.seconds}});
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::printf("%-12s %14s %10s %6s  %s\n", "method", "volume", "seconds", "hull", "half extents");
  for (const Row& r : rows)
    std::printf("%-12s %14.8g %10.6f %6zu  %g %g %g\n", std::string(to_string(r.method)).c_str(), r.box.volume(),
                r.seconds, r.hull_vertices, r.box.half_extents.x(), r.box.half_extents.y(), r.box.half_extents.z());
}

}  // namespace

void add_fit_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("fit", "fit one bounding box to a whole mesh");
  auto args = std::make_shared<Args>();
  cmd->add_option("mesh", args->mesh, "mesh file (OBJ, OFF, STL, PLY, ...)")->required();
  cmd->add_option("--method", args->method, choices(with(fit_method_names(), "all")))->capture_default_str();
  auto* grid = cmd->add_option("--grid", args->grid, "approx: grid radius k (primitive directions with L-inf <= k)")
                   ->check(CLI::Range(1, 64))
                   ->capture_default_str();
  auto* eps = cmd->add_option("--epsilon", args->epsilon,
                              "approx: target (1+e) approximation (chooses k); approx-snap: snapping grid");
  grid->excludes(eps);
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->callback([args, eps] {
    // Checked here, before any output; CLI11's PositiveNumber would print DBL_MAX in full.
    if (eps->count() > 0 && !(args->epsilon > 0.0 && std::isfinite(args->epsilon)))
      throw InputError("--epsilon must be a positive finite number, got " + eps->as<std::string>());
    const std::vector<FitMethod> methods = parse_methods(args->method);
    const Mesh mesh = load_mesh(args->mesh);
    (void)check_mesh(mesh, args->mesh);
    FitOptions options;
    options.grid = args->grid;
    if (eps->count() > 0) options.epsilon = args->epsilon;
    print_rows(fit_mesh(mesh, methods, options), args->json);
  });
}

}  // namespace tightbvh::cli
