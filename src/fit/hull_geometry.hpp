#pragma once
// Internal: the hull as every fitter sees it (HullGeometry), the box they all return (AxisBox)
// and the scans and walks over the hull's vertices that they share (hull_geometry.cpp).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "tightbvh/hull.hpp"

namespace tightbvh::fit_detail {

// A solid (dimension 3) hull seen from a local origin: vertices are relative to `origin`
// so that sets far from the coordinate origin keep their precision.
// Without a hull (`hull == nullptr`, see reset_points) `local` holds a small point set whose
// hull was never computed: Bopt then projects every point instead of the silhouette. That is
// still exact for the direction (the 2D hull of the projection is the projection of the 3D
// hull), and for a dozen points cheaper than building the hull (see kSmallSetApprox in fit.cpp).
struct HullGeometry {
  const ConvexHull3* hull = nullptr;
  Vec3 origin = Vec3::Zero();
  std::vector<Vec3> local;  // hull->vertices[i] - origin
  // Hulls of at least kWalkFaces faces (reset): by face, the face across each edge (slot k: the
  // edge from vertex k + 1 to vertex k + 2, as Quickhull's faces), and by vertex one face holding
  // it. Bopt then walks the silhouette on these instead of classifying every edge.
  static constexpr std::size_t kWalkFaces = 48;
  std::vector<std::array<std::uint32_t, 3>> face_adjacent;
  std::vector<std::uint32_t> vertex_face;
  // Bopt's silhouette walk: where its last climb to the vertex farthest along u ended (reset with
  // the geometry, so the walks of one fit depend only on that fit's own calls).
  mutable std::uint32_t walk_hint = 0;

  void reset(const ConvexHull3& h, const Vec3& o);
  void reset_points(std::span<const Vec3> points, const Vec3& o);
  [[nodiscard]] std::size_t size() const { return local.size(); }
};

// The vertex maximising dir . p, by hill climbing on the hull's vertex graph from `start`
// (a local maximum of a linear function over a convex polytope's graph is global).
[[nodiscard]] std::uint32_t extreme_vertex(const HullGeometry& g, const Vec3& dir, std::uint32_t start);

// min and max of v . p over the geometry's points (a scan: see bopt() for why not hill climbing).
struct Extent {
  double lo, hi;
};
[[nodiscard]] Extent extent_along(const HullGeometry& g, const Vec3& v);

// A box given by orthonormal right-handed axes and its extents along them (local frame).
struct AxisBox {
  Mat3 axes = Mat3::Identity();
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Zero();
  [[nodiscard]] double volume() const { return (hi - lo).prod(); }
};

// The extents of the hull along given axes (exact, by scanning all hull vertices).
[[nodiscard]] AxisBox box_of_hull(const HullGeometry& g, const Mat3& axes);

}  // namespace tightbvh::fit_detail
