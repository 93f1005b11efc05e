#pragma once
/// @file
/// Convex hulls: the 3D hull of a point set (with the edge/face graph the fitters walk), and
/// the 2D hull of a planar point set (Andrew's monotone chain).
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "tightbvh/aabb.hpp"
#include "tightbvh/math.hpp"

namespace tightbvh {

/// An edge of a 3D hull: its two end vertices and the two faces that share it.
struct HullEdge {
  std::array<std::uint32_t, 2> vertex{};  ///< Indices into ConvexHull3::vertices.
  std::array<std::uint32_t, 2> face{};    ///< Indices into ConvexHull3::faces.
};

/// The convex hull of a 3D point set. `dimension` is the affine dimension of the input
/// (0 point, 1 segment, 2 planar, 3 solid). For dimension 3 the hull is a triangulated
/// closed polyhedron (coplanar facets are split into triangles, which share one normal);
/// for lower dimensions only `vertices` is filled (for dimension 2: the polygon, in order;
/// for 1: the two end points; for 0: one point) and `plane_normal` is set for dimension 2.
struct ConvexHull3 {
  int dimension = 0;  ///< The affine dimension of the input: 0, 1, 2 or 3.
  std::vector<Vec3> vertices;                        ///< copies of input points
  std::vector<std::uint32_t> input_index;            ///< vertices[i] == points[input_index[i]]
  std::vector<std::array<std::uint32_t, 3>> faces;   ///< vertex indices
  std::vector<Vec3> face_normals;                    ///< unit, outward
  std::vector<HullEdge> edges;                       ///< dimension 3: every edge once
  /// CSR vertex adjacency: the neighbors of vertex v are
  /// neighbors[neighbor_offsets[v] .. neighbor_offsets[v + 1]).
  std::vector<std::uint32_t> neighbor_offsets;
  std::vector<std::uint32_t> neighbors;              ///< See neighbor_offsets.
  Vec3 plane_normal = Vec3::UnitZ();                 ///< dimension 2 only

  /// Empties every array (keeping their memory) and sets dimension 0.
  void clear();
};

/// Reusable state of the hull computation (Quickhull's faces and outside sets): once its buffers
/// have grown, hulls of sets up to the same size allocate nothing. One per thread.
class HullWorkspace {
 public:
  HullWorkspace();
  ~HullWorkspace();
  HullWorkspace(HullWorkspace&&) noexcept;             ///< Takes over the other's buffers.
  HullWorkspace& operator=(HullWorkspace&&) noexcept;  ///< Takes over the other's buffers.
  struct State;
  /// The buffers, for the hull code (src/geometry/); opaque to users.
  [[nodiscard]] State& state() { return *state_; }

 private:
  std::unique_ptr<State> state_;
};

/// The convex hull of finite points (duplicates, coplanar and collinear sets are fine). Solid
/// sets: Quickhull (Barber, Dobkin & Huhdanpaa 1996) with exact orientation predicates, so the
/// vertices are exactly the strictly extreme points (a point inside a face or an edge is not a
/// vertex, one copy of duplicates is) and every input point is on or below every face plane.
/// The dimension is affine_dimension()'s. Throws InputError on an empty set or a non-finite point.
[[nodiscard]] ConvexHull3 convex_hull(std::span<const Vec3> points);
/// The same hull into `out` (its contents replaced, its memory reused), with caller-owned scratch.
void convex_hull(std::span<const Vec3> points, ConvexHull3& out, HullWorkspace& workspace);

/// The relative distance (times the set's length) within which affine_dimension() calls a set
/// collinear or coplanar.
inline constexpr double kFlatTolerance = 1e-13;
/// The answer of affine_dimension().
struct AffineDimension {
  int dimension = 0;                       ///< 0 point, 1 segment, 2 planar, 3 solid
  std::array<std::uint32_t, 4> simplex{};  ///< dimension + 1 of them are meaningful
  Vec3 direction = Vec3::UnitX();          ///< unit: the line (dimension >= 1)
  Vec3 normal = Vec3::UnitZ();             ///< unit: the plane (dimension >= 2)
  Aabb bounds;                             ///< of all the points
};
/// The affine dimension of a finite point set, decided once for every path that needs it (the
/// hull, and the fitters that skip the hull on small sets), so that they agree:
/// - 0 when the extreme pair along the longest bounding-box axis is within rounding of the
///   coordinates (1e-15 of their magnitude);
/// - 1 when no point is farther than kFlatTolerance * length from the line through that pair;
/// - 2 when no point is farther than kFlatTolerance * length from the plane through that pair
///   and the point farthest from their line, or when the four extreme points are exactly
///   coplanar (orient3d == 0);
/// - 3 otherwise: `simplex` is then an exactly non-degenerate tetrahedron of input points.
/// Sets below the tolerances are handled as flat (their boxes still take the thickness from the
/// points, so they contain them); sets above are solid for every caller, however thin.
/// Throws InputError naming the first non-finite point, or on an empty set.
[[nodiscard]] AffineDimension affine_dimension(std::span<const Vec3> points);

/// The answer of farthest_from_line().
struct FarthestFromLine {
  std::size_t index = 0;           ///< Index into the points.
  double squared_distance = -1.0;  ///< Its squared distance to the line (-1 for no points).
};
/// The point of `points` farthest from the line through `through` with unit direction `dir`
/// (the first of equals): its index and squared distance. Probes the affine dimension of a set.
[[nodiscard]] FarthestFromLine farthest_from_line(std::span<const Vec3> points, const Vec3& through,
                                                  const Vec3& dir);

/// Andrew's monotone chain: reorders the first entries of `points` into the convex hull in
/// counter-clockwise order, without collinear points, and returns their number (0 for an
/// empty input, 1 when all points coincide, 2 for collinear points).
[[nodiscard]] std::size_t convex_hull_2d(std::span<Vec2> points);
/// The same, with `chain` as scratch (any content): allocates nothing once it has grown.
[[nodiscard]] std::size_t convex_hull_2d(std::span<Vec2> points, std::vector<Vec2>& chain);

}  // namespace tightbvh
