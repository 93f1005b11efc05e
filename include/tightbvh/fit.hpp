#pragma once
/// @file
/// Box fitters: functions from points (or a triangle soup) to an Obb that contains them.
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string_view>

#include "tightbvh/obb.hpp"

namespace tightbvh {

/// A box fitter: the algorithm that fits one node's box (the names are fit_method_names()).
enum class FitMethod {
  aabb,         ///< axis-aligned box
  pca,          ///< RAPID/OBBTree: area-weighted covariance of the triangles
  pca_vertex,   ///< FCL: unweighted covariance of the triangle corners
  diameter,     ///< B*(S), Barequet & Har-Peled Lemma 6.3.1 (7-approximation, O(n))
  approx,       ///< GridSearchMinVolBbx (Section 6.4) + local improvement
  approx_snap,  ///< ApproxMinVolBbx (Section 6.3)
  exact,        ///< minimum-volume box (O'Rourke's theorem)
  eberly2015,   ///< Eberly 2015: face-flush and orthogonal-edge-triple boxes (misses some minima)
  approx_kernel,  ///< approx's grid scan on an extreme-point kernel of the set (O(n), see fit.cpp)
  normal_bopt,    ///< Bopt along the thinnest of the triangles' area-weighted and own normals (see fit.cpp)
  dito,           ///< DiTO-14, Larsson & Källberg 2011: frames of a ditetrahedron of extreme points (O(n), dito.cpp)
};

/// Which fitter, and the parameters of the hull-based ones.
struct FitOptions {
  FitMethod method = FitMethod::approx;  ///< The fitter.
  int grid = 2;                    ///< k: primitive grid directions with L-inf norm <= k (docs/algorithms.md, "approx")
  std::optional<double> epsilon;   ///< when set, chooses k from epsilon (see grid_for_epsilon)
  bool improve = true;             ///< local improvement step (the "(Improved)" rows)
};

/// The method named `name` (such as "approx-kernel"); nullopt for an unknown name. The one table of
/// method names (fit.cpp): parsing, printing, listing and help texts use it.
[[nodiscard]] std::optional<FitMethod> parse_fit_method(std::string_view name);
/// The name of `method` that parse_fit_method() accepts.
[[nodiscard]] std::string_view to_string(FitMethod method);
/// Every method, in declaration order ("aabb", "pca", "pca-vertex", ..., "eberly2015", "approx-kernel", "normal-bopt", "dito").
[[nodiscard]] std::span<const FitMethod> all_fit_methods();
[[nodiscard]] std::span<const std::string_view> fit_method_names();  ///< same order

/// The grid radius k used for a requested epsilon (documented in fit.cpp and in docs/algorithms.md,
/// "approx").
[[nodiscard]] int grid_for_epsilon(double epsilon);

/// Reusable scratch memory for the fitters (hull, projections, 2D hull, ...). Fitting many
/// nodes with one workspace allocates only while the buffers grow. Not thread-safe: use one
/// workspace per thread.
class FitWorkspace {
 public:
  FitWorkspace();
  ~FitWorkspace();
  FitWorkspace(FitWorkspace&&) noexcept;             ///< Takes over the other's buffers.
  FitWorkspace& operator=(FitWorkspace&&) noexcept;  ///< Takes over the other's buffers.
  FitWorkspace(const FitWorkspace&) = delete;
  FitWorkspace& operator=(const FitWorkspace&) = delete;

  /// Number of convex-hull vertices used by the last fit (0 when the method needs no hull; for
  /// the small sets that skip the hull, see kSmallSet in fit.cpp: the distinct input points).
  [[nodiscard]] std::size_t last_hull_vertices() const;

  struct Scratch;
  /// The buffers, for the fitters (src/fit/); opaque to users.
  [[nodiscard]] Scratch& scratch() { return *scratch_; }

 private:
  std::unique_ptr<Scratch> scratch_;
};

/// Fits a box to a point set. `pca` (which needs triangles) falls back to `pca_vertex` here.
/// Throws InputError on NaN/Inf input or an empty set.
[[nodiscard]] Obb fit_points(std::span<const Vec3> points, const FitOptions& options);
/// The same box, with caller-owned scratch (allocates only while the workspace grows).
[[nodiscard]] Obb fit_points(std::span<const Vec3> points, const FitOptions& options, FitWorkspace& workspace);

/// Fits a box to a triangle soup given as corners, three per triangle (size % 3 == 0). Throws
/// InputError as fit_points() does.
[[nodiscard]] Obb fit_triangles(std::span<const Vec3> corners, const FitOptions& options);
/// The same box, with caller-owned scratch.
[[nodiscard]] Obb fit_triangles(std::span<const Vec3> corners, const FitOptions& options,
                                FitWorkspace& workspace);
/// The same, given also `vertices`: the distinct points among the corners (for example the mesh vertices
/// the triangles use; the caller guarantees they are the same point set). The hull, the kernel and
/// the extents are computed from `vertices`, the triangle covariance of pca from `corners`: on a
/// mesh every vertex is a corner of about six triangles, so hull-based fitters get ~6x fewer points.
[[nodiscard]] Obb fit_triangles(std::span<const Vec3> corners, std::span<const Vec3> vertices,
                                const FitOptions& options, FitWorkspace& workspace);

}  // namespace tightbvh
