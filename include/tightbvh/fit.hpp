#pragma once
// Box fitters: functions from points (or a triangle soup) to an Obb that contains them.
#include <optional>
#include <span>
#include <string_view>

#include "tightbvh/obb.hpp"

namespace tightbvh {

enum class FitMethod {
  aabb,         // axis-aligned box
  pca,          // RAPID/OBBTree: area-weighted covariance of the triangles
  pca_vertex,   // FCL: unweighted covariance of the triangle corners
  diameter,     // B*(S), Barequet & Har-Peled Lemma 6.3.1 (7-approximation, O(n))
  approx,       // GridSearchMinVolBbx (Section 6.4) + local improvement
  approx_snap,  // ApproxMinVolBbx (Section 6.3)
  exact,        // minimum-volume box (O'Rourke's theorem)
};

struct FitOptions {
  FitMethod method = FitMethod::approx;
  int grid = 3;                    // k: primitive grid directions with L-inf norm <= k
  std::optional<double> epsilon;   // when set, chooses k from epsilon (see fit.cpp)
  bool improve = true;             // local improvement step (the "(Improved)" rows)
};

[[nodiscard]] std::optional<FitMethod> parse_fit_method(std::string_view name);
[[nodiscard]] std::string_view to_string(FitMethod method);

// Fits a box to a point set. `pca` (which needs triangles) falls back to `pca_vertex` here.
// Throws InputError on NaN/Inf input or an empty set.
[[nodiscard]] Obb fit_points(std::span<const Vec3> points, const FitOptions& options);

// Fits a box to a triangle soup given as corners, three per triangle (size % 3 == 0).
[[nodiscard]] Obb fit_triangles(std::span<const Vec3> corners, const FitOptions& options);

}  // namespace tightbvh
