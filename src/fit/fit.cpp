#include "tightbvh/fit.hpp"

#include <array>
#include <cmath>
#include <string>

#include "frame.hpp"
#include "pca.hpp"
#include "tightbvh/mesh.hpp"
#include "workspace.hpp"

namespace tightbvh {
namespace {

constexpr std::array<std::pair<FitMethod, std::string_view>, 7> kNames{{
    {FitMethod::aabb, "aabb"},
    {FitMethod::pca, "pca"},
    {FitMethod::pca_vertex, "pca-vertex"},
    {FitMethod::diameter, "diameter"},
    {FitMethod::approx, "approx"},
    {FitMethod::approx_snap, "approx-snap"},
    {FitMethod::exact, "exact"},
}};

void check_finite(std::span<const Vec3> points) {
  if (points.empty()) throw InputError("fit: empty point set");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("fit: point " + std::to_string(i) + " is not finite (NaN or Inf coordinate)");
}

Obb fit_checked(std::span<const Vec3> points, std::span<const Vec3> triangle_corners, const FitOptions& options,
                FitWorkspace& workspace) {
  auto& scratch = workspace.scratch();
  scratch.last_hull_vertices = 0;
  const Vec3 origin = fit_detail::local_origin(points);
  switch (options.method) {
    case FitMethod::aabb:
      return to_obb(bounds_of(points));
    case FitMethod::pca:
      if (!triangle_corners.empty())
        return fit_detail::box_with_axes(points, fit_detail::pca_triangle_axes(triangle_corners, origin), origin);
      [[fallthrough]];
    case FitMethod::pca_vertex:
      return fit_detail::box_with_axes(points, fit_detail::pca_vertex_axes(points, origin), origin);
    default:
      throw std::logic_error("fit method not implemented yet: " + std::string(to_string(options.method)));
  }
}

}  // namespace

FitWorkspace::FitWorkspace() : scratch_(std::make_unique<Scratch>()) {}
FitWorkspace::~FitWorkspace() = default;
FitWorkspace::FitWorkspace(FitWorkspace&&) noexcept = default;
FitWorkspace& FitWorkspace::operator=(FitWorkspace&&) noexcept = default;
std::size_t FitWorkspace::last_hull_vertices() const { return scratch_->last_hull_vertices; }

std::optional<FitMethod> parse_fit_method(std::string_view name) {
  for (const auto& [method, text] : kNames)
    if (text == name) return method;
  return std::nullopt;
}

std::string_view to_string(FitMethod method) {
  for (const auto& [m, text] : kNames)
    if (m == method) return text;
  return "unknown";
}

int grid_for_epsilon(double epsilon) {
  if (!(epsilon > 0.0) || !std::isfinite(epsilon)) throw InputError("fit: epsilon must be a positive number");
  return 3;  // placeholder until approx lands
}

Obb fit_points(std::span<const Vec3> points, const FitOptions& options) {
  FitWorkspace workspace;
  return fit_points(points, options, workspace);
}

Obb fit_points(std::span<const Vec3> points, const FitOptions& options, FitWorkspace& workspace) {
  check_finite(points);
  return fit_checked(points, {}, options, workspace);
}

Obb fit_triangles(std::span<const Vec3> corners, const FitOptions& options) {
  FitWorkspace workspace;
  return fit_triangles(corners, options, workspace);
}

Obb fit_triangles(std::span<const Vec3> corners, const FitOptions& options, FitWorkspace& workspace) {
  if (corners.size() % 3 != 0) throw InputError("fit: triangle corners must come in threes");
  check_finite(corners);
  return fit_checked(corners, corners, options, workspace);
}

}  // namespace tightbvh
