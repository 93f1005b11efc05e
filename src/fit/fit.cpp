#include "tightbvh/fit.hpp"

#include <array>
#include <string>

#include "tightbvh/mesh.hpp"

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
    if (!points[i].allFinite()) throw InputError("fit: point " + std::to_string(i) + " is not finite");
}

}  // namespace

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

Obb fit_points(std::span<const Vec3> points, const FitOptions& options) {
  check_finite(points);
  switch (options.method) {
    case FitMethod::aabb:
      return to_obb(bounds_of(points));
    default:
      throw std::logic_error("fit method not implemented yet: " + std::string(to_string(options.method)));
  }
}

Obb fit_triangles(std::span<const Vec3> corners, const FitOptions& options) {
  if (corners.size() % 3 != 0) throw InputError("fit: triangle corners must come in threes");
  return fit_points(corners, options);
}

}  // namespace tightbvh
