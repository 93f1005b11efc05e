// tightbvh fit MESH --method aabb|pca|pca-vertex|diameter|approx|approx-snap|exact|all
//                   [--grid K] [--epsilon E] [--json]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <vector>

#include "commands.hpp"
#include "tightbvh/fit.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::cli {

void add_fit_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("fit", "fit one bounding box to a whole mesh");
  struct Args {
    std::string mesh;
    std::string method = "approx";
    int grid = FitOptions{}.grid;
    double epsilon = 0.0;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("mesh", args->mesh, "mesh file (OBJ, OFF, STL, PLY, ...)")->required();
  cmd->add_option("--method", args->method,
                  "aabb | pca | pca-vertex | diameter | approx | approx-snap | exact | all")
      ->capture_default_str();
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
    std::vector<FitMethod> methods;
    if (args->method == "all") {
      methods = {FitMethod::aabb,   FitMethod::pca,         FitMethod::pca_vertex, FitMethod::diameter,
                 FitMethod::approx, FitMethod::approx_snap, FitMethod::exact};
    } else if (const auto m = parse_fit_method(args->method)) {
      methods = {*m};
    } else {
      throw InputError("unknown fit method '" + args->method +
                       "' (expected aabb, pca, pca-vertex, diameter, approx, approx-snap, exact or all)");
    }
    const Mesh mesh = load_mesh(args->mesh);
    (void)check_mesh(mesh, args->mesh);
    std::vector<Vec3> corners;
    corners.reserve(mesh.triangles.size() * 3);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      for (const Vec3& c : mesh.corners(t)) corners.push_back(c);

    nlohmann::json out = nlohmann::json::array();
    FitWorkspace workspace;
    const auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
    if (!args->json) std::printf("%-12s %14s %10s %6s  %s\n", "method", "volume", "seconds", "hull", "half extents");
    for (FitMethod method : methods) {
      FitOptions options;
      options.method = method;
      options.grid = args->grid;
      if (eps->count() > 0) options.epsilon = args->epsilon;
      const auto start = std::chrono::steady_clock::now();
      // pca weights the triangles by area; every other method only needs the vertices.
      const Obb box = method == FitMethod::pca ? fit_triangles(corners, options, workspace)
                                               : fit_points(mesh.vertices, options, workspace);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (args->json) {
        out.push_back({{"method", std::string(to_string(method))},
                       {"volume", box.volume()},
                       {"center", vec(box.center)},
                       {"axes", {vec(box.axes.col(0)), vec(box.axes.col(1)), vec(box.axes.col(2))}},
                       {"half_extents", vec(box.half_extents)},
                       {"hull_vertices", workspace.last_hull_vertices()},
                       {"seconds", seconds}});
      } else {
        std::printf("%-12s %14.8g %10.6f %6zu  %g %g %g\n", std::string(to_string(method)).c_str(), box.volume(),
                    seconds, workspace.last_hull_vertices(), box.half_extents.x(), box.half_extents.y(),
                    box.half_extents.z());
      }
    }
    if (args->json) std::cout << out.dump(2) << '\n';
  });
}

}  // namespace tightbvh::cli
