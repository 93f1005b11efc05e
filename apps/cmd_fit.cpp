// tightbvh fit MESH --method METHOD|all [--grid K] [--epsilon E] [--json]
// (METHOD: any name of fit_method_names(), fit.hpp, or a container: ball, fast-ball, ellipsoid,
// diamond, dop14, dop18, dop26). "all" fits every one and, as Sunday's comparison, prints each
// volume relative to the exact box.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <nlohmann/json.hpp>
#include <vector>

#include "commands.hpp"
#include "names.hpp"
#include "tightbvh/ball.hpp"
#include "tightbvh/dop.hpp"
#include "tightbvh/ellipsoid.hpp"
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

// One fitted container: its volume, fit time, hull size (hull-based box fitters) and its
// parameters, as a short text and as JSON.
struct Row {
  std::string method;
  double volume = 0.0;
  double seconds = 0.0;
  std::size_t hull_vertices = 0;
  std::string summary;
  nlohmann::json params;
};

nlohmann::json vec_json(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

std::string vec_text(const Vec3& v) {
  char text[96];
  std::snprintf(text, sizeof text, "%g %g %g", v.x(), v.y(), v.z());
  return text;
}

// Sunday's other containers (ball.hpp, dop.hpp, ellipsoid.hpp), fitted to the mesh's vertices.
struct Container {
  std::string_view name;
  Row (*fit)(std::span<const Vec3> points);
};

Row ball_row(const Ball& b) {
  return {"", b.volume(), 0.0, 0, "radius " + std::to_string(b.radius),
          {{"center", vec_json(b.center)}, {"radius", b.radius}}};
}

Row dop_row(const Dop& d) {
  nlohmann::json slabs = nlohmann::json::array();
  for (int i = 0; i < d.axes(); ++i)
    slabs.push_back({{"direction", vec_json(dop_direction(d.kind, i))}, {"min", d.min[i]}, {"max", d.max[i]}});
  return {"", d.volume(), 0.0, 0, std::to_string(2 * d.axes()) + " planes", {{"slabs", slabs}}};
}

constexpr std::array<Container, 7> kContainers{{
    {"ball", [](std::span<const Vec3> p) { return ball_row(bounding_ball(p)); }},
    {"fast-ball", [](std::span<const Vec3> p) { return ball_row(fast_ball(p)); }},
    {"ellipsoid",
     [](std::span<const Vec3> p) {
       const Ellipsoid e = bounding_ellipsoid(p);
       return Row{"", e.volume(), 0.0, 0, "radii " + vec_text(e.radii),
                  {{"center", vec_json(e.center)},
                   {"axes", {vec_json(e.axes.col(0)), vec_json(e.axes.col(1)), vec_json(e.axes.col(2))}},
                   {"radii", vec_json(e.radii)},
                   {"epsilon", 0.01}}};
     }},
    {"diamond", [](std::span<const Vec3> p) { return dop_row(bounding_dop(p, DopKind::diamond)); }},
    {"dop14", [](std::span<const Vec3> p) { return dop_row(bounding_dop(p, DopKind::dop14)); }},
    {"dop18", [](std::span<const Vec3> p) { return dop_row(bounding_dop(p, DopKind::dop18)); }},
    {"dop26", [](std::span<const Vec3> p) { return dop_row(bounding_dop(p, DopKind::dop26)); }},
}};

// Every name --method takes: the box fitters of fit_method_names(), the containers, "all".
std::vector<std::string_view> method_names() {
  std::vector<std::string_view> names(fit_method_names().begin(), fit_method_names().end());
  for (const Container& c : kContainers) names.push_back(c.name);
  names.push_back("all");
  return names;
}

[[nodiscard]] std::vector<std::string> parse_methods(const std::string& name) {
  const std::vector<std::string_view> names = method_names();
  if (name == "all") return {names.begin(), names.end() - 1};
  if (std::find(names.begin(), names.end() - 1, name) != names.end() - 1) return {name};
  throw InputError("--method: unknown fit method '" + name + "' (expected " + one_of(names) + ")");
}

template <class Fit>
Row timed(const std::string& method, Fit&& fit) {
  const auto start = std::chrono::steady_clock::now();
  Row row = fit();
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  row.method = method;
  return row;
}

Row box_row(const Obb& box, std::size_t hull_vertices) {
  return {"", box.volume(), 0.0, hull_vertices, vec_text(box.half_extents),
          {{"center", vec_json(box.center)},
           {"axes", {vec_json(box.axes.col(0)), vec_json(box.axes.col(1)), vec_json(box.axes.col(2))}},
           {"half_extents", vec_json(box.half_extents)}}};
}

[[nodiscard]] std::vector<Row> fit_mesh(const Mesh& mesh, const std::vector<std::string>& methods, FitOptions options) {
  const std::vector<Vec3> corners = triangle_corners(mesh);
  FitWorkspace workspace;
  std::vector<Row> rows;
  for (const std::string& name : methods) {
    if (const auto method = parse_fit_method(name)) {
      options.method = *method;
      rows.push_back(timed(name, [&] {
        // pca weights the triangles by area; every other method only needs the vertices.
        const Obb box = *method == FitMethod::pca ? fit_triangles(corners, options, workspace)
                                                  : fit_points(mesh.vertices, options, workspace);
        return box_row(box, workspace.last_hull_vertices());
      }));
      continue;
    }
    for (const Container& c : kContainers)
      if (c.name == name) rows.push_back(timed(name, [&] { return c.fit(mesh.vertices); }));
  }
  return rows;
}

// Sunday's comparison: each volume relative to the exact box's, when exact is among the rows.
std::optional<double> exact_volume(const std::vector<Row>& rows) {
  for (const Row& r : rows)
    if (r.method == "exact") return r.volume;
  return std::nullopt;
}

void print_rows(const std::vector<Row>& rows, bool json) {
  const std::optional<double> exact = exact_volume(rows);
  const auto relative = [&](const Row& r) { return exact && *exact > 0.0 ? r.volume / *exact : 0.0; };
  if (json) {
    nlohmann::json out = nlohmann::json::array();
    for (const Row& r : rows) {
      nlohmann::json j = {{"method", r.method}, {"volume", r.volume}, {"hull_vertices", r.hull_vertices},
                          {"seconds", r.seconds}};
      j.update(r.params);
      if (exact && *exact > 0.0) j["volume_vs_exact"] = relative(r);
      out.push_back(std::move(j));
    }
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::printf("%-12s %14s %10s %6s  %s\n", "method", "volume", "seconds", "hull",
              exact ? "vs exact  parameters (boxes: half extents)" : "parameters (boxes: half extents)");
  for (const Row& r : rows) {
    std::printf("%-12s %14.8g %10.6f %6zu  ", r.method.c_str(), r.volume, r.seconds, r.hull_vertices);
    if (exact) std::printf("%8.4f  ", relative(r));
    std::printf("%s\n", r.summary.c_str());
  }
}

}  // namespace

void add_fit_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("fit", "fit one bounding box (or ball, ellipsoid, k-DOP) to a whole mesh");
  auto args = std::make_shared<Args>();
  cmd->add_option("mesh", args->mesh, "mesh file (OBJ, OFF, STL, PLY, ...)")->required();
  cmd->add_option("--method", args->method, choices(method_names()))->capture_default_str();
  auto* grid = cmd->add_option("--grid", args->grid, "approx: grid radius k (primitive directions with L-inf <= k)")
                   ->check(CLI::Range(1, 64))
                   ->capture_default_str();
  auto* eps = cmd->add_option("--epsilon", args->epsilon,
                              "approx: target (1+e) approximation (chooses k); approx-snap: snapping grid");
  grid->excludes(eps);
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->footer("Example:\n  tightbvh fit meshes/knot1.off --method approx --epsilon 0.05");
  cmd->callback([args, eps] {
    // Checked here, before any output; CLI11's PositiveNumber would print DBL_MAX in full.
    if (eps->count() > 0 && !(args->epsilon > 0.0 && std::isfinite(args->epsilon)))
      throw InputError("--epsilon must be a positive finite number, got " + eps->as<std::string>());
    const std::vector<std::string> methods = parse_methods(args->method);
    const Mesh mesh = load_mesh(args->mesh);
    (void)check_mesh(mesh, args->mesh);
    FitOptions options;
    options.grid = args->grid;
    if (eps->count() > 0) options.epsilon = args->epsilon;
    print_rows(fit_mesh(mesh, methods, options), args->json);
  });
}

}  // namespace tightbvh::cli
