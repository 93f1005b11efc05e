#pragma once
/// @file
/// Primitive shapes (sphere, box, capsule, cylinder, convex hull) against a posed triangle mesh: which triangles touch
/// the shape (collide) and how far apart they are (distance), without tessellating the shape.
///
/// Conventions are FCL's: Sphere{radius} centered at the origin of its frame; Box{x, y, z} with
/// full side lengths, centered, faces normal to the local axes; Capsule{radius, length} along the
/// local z axis, centered, `length` the length of its axis segment (FCL's lz), so it reaches
/// length / 2 + radius from the center along z; Cylinder{radius, length} along the local z axis,
/// centered, `length` its full height (FCL's lz); Convex{points} the convex hull of the points in
/// its frame. The shapes are solid: a triangle inside a box touches it.
///
/// Frames: the shape's pose is mapped into the mesh frame once per query, relative_pose(pm, ps)
/// (collide.hpp), and every triangle test runs there, in the queries and in their brute-force
/// references alike (so both see the same numbers). The box maps each triangle into its own
/// frame instead (the inverse of that pose), where it is axis-aligned.
///
/// Per triangle (docs/algorithms.md, "Shapes against meshes"):
///  - Sphere: d = |c - closest_point_on_triangle(c)| (Ericson §5.1.5, point_query.hpp); touching
///    iff d <= radius; the distance is d - radius otherwise.
///  - Capsule: d = the distance of its axis segment and the triangle: from the segment's end points
///    and the triangle's edges when the segment is strictly on one side of the plane, else
///    tri_tri_distance of the degenerate triangle (p, q, q) (tri_distance.hpp; exactly 0 iff they
///    touch); touching iff d <= radius; the distance is d - radius otherwise.
///  - Box: touching decided exactly on the triangle's box-frame coordinates: a corner inside the
///    closed box, or the triangle touching one of the box's 12 surface triangles (tri_tri_overlap,
///    exact predicates). The 13-axis separating-axis test of Akenine-Möller (2001, "Fast 3D
///    triangle-box overlap testing") rejects first, only when an axis separates by more than its
///    rounding allowance. The distance of a disjoint triangle: the least over its corners against
///    the box, and the corners and edges of the box's faces it is outside of against the
///    triangle (the same as the least tri_tri_distance to the 12 surface triangles).
///  - Convex: exact, as the box, on the triangle's coordinates in the hull's frame: a hull face
///    plane with every corner strictly outside rejects (orient3d, exact); else a corner inside the
///    closed hull (orient3d against every face) or the triangle touching a face (tri_tri_overlap)
///    touches. The distance is GJK's when its bounds prove it within 1e-13 relative, else the
///    least tri_tri_distance to the faces that some corner is strictly outside of (the closest
///    point of the hull lies on one of them).
///  - Cylinder: GJK (Gilbert, Johnson & Keerthi 1988) between the triangle and the cylinder, in
///    the cylinder's frame; touching iff the GJK distance is at most kCylinderTolerance times the
///    scale (the largest of the radius, half the length and the triangle's coordinates in that
///    frame); the distance otherwise from GJK's point of the triangle to the cylinder's exact
///    closest point (within 1e-12 relative of the true one, or 1e-12 of the scale). Not exact: within that tolerance of the boundary the
///    decision may go either way.
/// So for every shape the distance is exactly 0 iff the triangle touches, and a margin query
/// reports the triangles at distance <= margin, the same distance distance() reports.
///
/// Traversal: collide culls nodes with a lower bound of the distance to the node's box (sphere,
/// capsule) or the shape's bounding box (bounding_box(), mapped into the mesh frame) against it
/// (box, cylinder, convex); distance searches best first with that lower bound per node (the
/// sphere's center and the capsule's axis segment against the node's box, less the radius; the
/// others' box against it),
/// and rules triangles out by their bounding box's and plane's gaps before measuring them. Each
/// bound allows for rounding, the float boxes' axes and a pose's rotation that is orthonormal only
/// within kRotationTolerance (scene.hpp). docs/algorithms.md, "Shapes against meshes", has the
/// details.
#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <variant>
#include <vector>

#include "tightbvh/collide.hpp"
#include "tightbvh/distance.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/obb.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh {

/// A solid sphere centered at the origin of its frame (FCL's Sphere).
struct Sphere {
  /// The sphere of this radius; InputError unless it is positive and finite.
  explicit Sphere(double radius);
  double radius;  ///< > 0, finite.
};

/// A solid box centered at the origin of its frame, its faces normal to the local axes (FCL's Box).
struct Box {
  /// The box of these full side lengths along x, y and z; InputError unless each is positive
  /// and finite.
  Box(double x, double y, double z);
  /// The same, the side lengths as a vector.
  explicit Box(const Vec3& size);
  Vec3 size;  ///< Full side lengths along the local x, y, z axes (each > 0, finite).
};

/// A solid capsule: the points within `radius` of the segment from (0, 0, -length / 2) to
/// (0, 0, length / 2) of its frame (FCL's Capsule, `length` its lz).
struct Capsule {
  /// The capsule of this radius and axis length; InputError unless both are positive and finite.
  Capsule(double radius, double length);
  double radius;  ///< > 0, finite.
  double length;  ///< The axis segment's length (> 0, finite), not counting the caps.
};

/// A solid cylinder along the local z axis, centered at the origin: the points with x^2 + y^2 <=
/// radius^2 and |z| <= length / 2 (FCL's Cylinder, `length` its lz).
struct Cylinder {
  /// The cylinder of this radius and full height; InputError unless both are positive and finite.
  Cylinder(double radius, double length);
  double radius;  ///< > 0, finite.
  double length;  ///< The full height along z (> 0, finite).
};

/// A solid convex polyhedron: the convex hull of points given in its frame (FCL's Convex). Only
/// the hull is kept (convex_hull(), hull.hpp): its vertices and its triangular faces.
struct Convex {
  /// The convex hull of `points`; InputError for a NaN or infinite coordinate, fewer than 4
  /// points, or points whose hull is flat (affine dimension below 3, hull.hpp).
  explicit Convex(std::span<const Vec3> points);
  /// The same, the points as a vector.
  explicit Convex(const std::vector<Vec3>& points) : Convex(std::span<const Vec3>(points)) {}
  std::vector<Vec3> vertices;  ///< The hull's vertices (each an input point, strictly extreme).
  /// The hull's faces as indices into `vertices`, counter-clockwise seen from outside:
  /// (b - a) x (c - a) points out of the solid.
  std::vector<std::array<std::uint32_t, 3>> faces;
};

/// Touching tolerance of a cylinder against a triangle or another shape (GJK): they touch when
/// the GJK distance is at most this times the scale of the coordinates (the largest of the radius,
/// half the length and the other shape's coordinates in the cylinder's frame). GJK stops within
/// about 1e-12 of that scale, and the coordinates carry rounding of about 1e-16 of it; 1e-9 is far
/// above both, and far below any gap a caller means (docs/algorithms.md, "Cylinder: GJK").
inline constexpr double kCylinderTolerance = 1e-9;

/// The shape's box in its own frame: centered at the origin, identity axes.
[[nodiscard]] Obb bounding_box(const Sphere& shape);
/// The shape's box in its own frame: centered at the origin, identity axes, half the side lengths.
[[nodiscard]] Obb bounding_box(const Box& shape);
/// The shape's box in its own frame: half extents (radius, radius, length / 2 + radius).
[[nodiscard]] Obb bounding_box(const Capsule& shape);
/// The shape's box in its own frame: half extents (radius, radius, length / 2).
[[nodiscard]] Obb bounding_box(const Cylinder& shape);
/// The shape's box in its own frame: the axis-aligned box of its vertices.
[[nodiscard]] Obb bounding_box(const Convex& shape);

/// Any one of the shapes: a scene object's shape (scene.hpp).
using Shape = std::variant<Sphere, Box, Capsule, Cylinder, Convex>;
/// The shape's box in its own frame (the bounding_box() of the shape it holds).
[[nodiscard]] Obb bounding_box(const Shape& shape);
/// "sphere", "box", "capsule", "cylinder" or "convex": the scene file's names.
[[nodiscard]] const char* shape_name(const Shape& shape);

/// The distance between two posed shapes (solids).
struct ShapePairDistance {
  double distance = 0.0;           ///< >= 0; 0 when the solids touch or overlap
  Vec3 point_a = Vec3::Zero();     ///< the closest point of A (world frame); a common point when touching
  Vec3 point_b = Vec3::Zero();     ///< the closest point of B (world frame); equal to point_a when touching
};

/// The distance between shape `a` at pose `pa` and shape `b` at pose `pb` (shape frames to
/// world), as solids. Each shape is a core grown by a radius: a sphere its center, a capsule its
/// axis segment, a box itself (radius 0). The cores' distance comes from tri_tri_distance
/// (points and segments as degenerate triangles; a box as its 12 surface triangles, after an
/// exact point-in-box test of the other's endpoints or corners, so a core inside a box is at 0),
/// less the two radii. A pair with a cylinder or a convex hull goes through GJK on the two
/// solids (support functions; a sphere or capsule as its core, the radii subtracted after), at 0
/// when the GJK distance is within kCylinderTolerance of the scale of the coordinates.
/// InputError for a pose that is not a finite proper rotation.
[[nodiscard]] ShapePairDistance distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb);

/// The answer of collide() of a shape and a mesh.
struct ShapeQueryResult {
  /// Some triangle touches the shape (or is within the margin).
  bool hit = false;
  /// The indices (into Mesh::triangles) of the triangles found: all_pairs, every one, sorted and
  /// unique; first_hit, the one found, if any.
  std::vector<std::uint32_t> triangles;
  /// box_tests: node boxes tested against the shape's box; triangle_tests: triangles tested.
  QueryStats stats;
};

/// The answer of distance() of a shape and a mesh.
struct ShapeDistanceResult {
  /// The minimum distance (within the options' error), exactly 0 when the shape touches the mesh;
  /// options.upper_bound when beyond_upper_bound; +infinity for an empty tree.
  double distance = std::numeric_limits<double>::infinity();
  /// The shape and the mesh are at least options.upper_bound apart (then `triangle` and the
  /// points are not set).
  bool beyond_upper_bound = false;
  /// The shape touches the mesh (distance 0); both points are then one point of the triangle that
  /// lies in the shape.
  bool intersecting = false;
  std::uint32_t triangle = 0;        ///< The closest triangle's index (into Mesh::triangles).
  Vec3 point_shape = Vec3::Zero();  ///< The closest point on the shape, world frame.
  Vec3 point_mesh = Vec3::Zero();   ///< The closest point on the triangle, world frame.
  /// node_pairs: node boxes bounded or box-tested; triangle_pairs: triangles measured.
  DistanceStats stats;
};

/// The triangles of `mesh` (at pose `pm`, mesh frame to world) that touch the sphere at pose `ps`
/// (shape frame to world), as options.mode says; with options.margin, those within it.
/// `tree` built over `mesh`. InputError for a mismatched tree, a pose that is not a finite proper
/// rotation (kRotationTolerance), an invalid shape, a negative, NaN or infinite margin, and for
/// options.solid or options.contacts (not available for shapes). An empty tree never hits.
[[nodiscard]] ShapeQueryResult collide(const Sphere& shape, const Pose& ps, const Tree& tree, const Mesh& mesh,
                                       const Pose& pm, const QueryOptions& options = {});
/// The same for a box.
[[nodiscard]] ShapeQueryResult collide(const Box& shape, const Pose& ps, const Tree& tree, const Mesh& mesh,
                                       const Pose& pm, const QueryOptions& options = {});
/// The same for a capsule.
[[nodiscard]] ShapeQueryResult collide(const Capsule& shape, const Pose& ps, const Tree& tree, const Mesh& mesh,
                                       const Pose& pm, const QueryOptions& options = {});
/// The same for a cylinder.
[[nodiscard]] ShapeQueryResult collide(const Cylinder& shape, const Pose& ps, const Tree& tree, const Mesh& mesh,
                                       const Pose& pm, const QueryOptions& options = {});
/// The same for a convex hull.
[[nodiscard]] ShapeQueryResult collide(const Convex& shape, const Pose& ps, const Tree& tree, const Mesh& mesh,
                                       const Pose& pm, const QueryOptions& options = {});
/// collide() of a sphere and a model's tree and mesh.
[[nodiscard]] ShapeQueryResult collide(const Sphere& shape, const Pose& ps, const Model& model, const Pose& pm,
                                       const QueryOptions& options = {});
/// collide() of a box and a model's tree and mesh.
[[nodiscard]] ShapeQueryResult collide(const Box& shape, const Pose& ps, const Model& model, const Pose& pm,
                                       const QueryOptions& options = {});
/// collide() of a capsule and a model's tree and mesh.
[[nodiscard]] ShapeQueryResult collide(const Capsule& shape, const Pose& ps, const Model& model, const Pose& pm,
                                       const QueryOptions& options = {});
/// collide() of a cylinder and a model's tree and mesh.
[[nodiscard]] ShapeQueryResult collide(const Cylinder& shape, const Pose& ps, const Model& model, const Pose& pm,
                                       const QueryOptions& options = {});
/// collide() of a convex hull and a model's tree and mesh.
[[nodiscard]] ShapeQueryResult collide(const Convex& shape, const Pose& ps, const Model& model, const Pose& pm,
                                       const QueryOptions& options = {});

/// The minimum distance between the sphere at pose `ps` and `mesh` at pose `pm`, with the closest
/// triangle and points (world frame); 0 when they touch. Of the options, absolute_error,
/// relative_error and upper_bound are used as for meshes (distance.hpp); InputError for negative
/// or NaN ones, for solid or signed_distance (not available for shapes), and as collide().
[[nodiscard]] ShapeDistanceResult distance(const Sphere& shape, const Pose& ps, const Tree& tree, const Mesh& mesh,
                                           const Pose& pm, const DistanceOptions& options = {});
/// The same for a box.
[[nodiscard]] ShapeDistanceResult distance(const Box& shape, const Pose& ps, const Tree& tree, const Mesh& mesh,
                                           const Pose& pm, const DistanceOptions& options = {});
/// The same for a capsule.
[[nodiscard]] ShapeDistanceResult distance(const Capsule& shape, const Pose& ps, const Tree& tree, const Mesh& mesh,
                                           const Pose& pm, const DistanceOptions& options = {});
/// The same for a cylinder.
[[nodiscard]] ShapeDistanceResult distance(const Cylinder& shape, const Pose& ps, const Tree& tree, const Mesh& mesh,
                                           const Pose& pm, const DistanceOptions& options = {});
/// The same for a convex hull.
[[nodiscard]] ShapeDistanceResult distance(const Convex& shape, const Pose& ps, const Tree& tree, const Mesh& mesh,
                                           const Pose& pm, const DistanceOptions& options = {});
/// distance() of a sphere and a model's tree and mesh.
[[nodiscard]] ShapeDistanceResult distance(const Sphere& shape, const Pose& ps, const Model& model, const Pose& pm,
                                           const DistanceOptions& options = {});
/// distance() of a box and a model's tree and mesh.
[[nodiscard]] ShapeDistanceResult distance(const Box& shape, const Pose& ps, const Model& model, const Pose& pm,
                                           const DistanceOptions& options = {});
/// distance() of a capsule and a model's tree and mesh.
[[nodiscard]] ShapeDistanceResult distance(const Capsule& shape, const Pose& ps, const Model& model, const Pose& pm,
                                           const DistanceOptions& options = {});
/// distance() of a cylinder and a model's tree and mesh.
[[nodiscard]] ShapeDistanceResult distance(const Cylinder& shape, const Pose& ps, const Model& model, const Pose& pm,
                                           const DistanceOptions& options = {});
/// distance() of a convex hull and a model's tree and mesh.
[[nodiscard]] ShapeDistanceResult distance(const Convex& shape, const Pose& ps, const Model& model, const Pose& pm,
                                           const DistanceOptions& options = {});

/// Reference: every triangle in index order, the same per-triangle test and frames as collide();
/// first_hit stops at the first touching triangle. stats.box_tests == 0.
[[nodiscard]] ShapeQueryResult collide_brute_force(const Sphere& shape, const Pose& ps, const Mesh& mesh,
                                                   const Pose& pm, const QueryOptions& options = {});
/// The same for a box.
[[nodiscard]] ShapeQueryResult collide_brute_force(const Box& shape, const Pose& ps, const Mesh& mesh,
                                                   const Pose& pm, const QueryOptions& options = {});
/// The same for a capsule.
[[nodiscard]] ShapeQueryResult collide_brute_force(const Capsule& shape, const Pose& ps, const Mesh& mesh,
                                                   const Pose& pm, const QueryOptions& options = {});
/// The same for a cylinder.
[[nodiscard]] ShapeQueryResult collide_brute_force(const Cylinder& shape, const Pose& ps, const Mesh& mesh,
                                                   const Pose& pm, const QueryOptions& options = {});
/// The same for a convex hull.
[[nodiscard]] ShapeQueryResult collide_brute_force(const Convex& shape, const Pose& ps, const Mesh& mesh,
                                                   const Pose& pm, const QueryOptions& options = {});

/// Reference: every triangle, the same per-triangle distance and frames as distance(); the first
/// triangle (in index order) at the minimum. Exact: the error options and upper_bound are not used.
[[nodiscard]] ShapeDistanceResult distance_brute_force(const Sphere& shape, const Pose& ps, const Mesh& mesh,
                                                       const Pose& pm, const DistanceOptions& options = {});
/// The same for a box.
[[nodiscard]] ShapeDistanceResult distance_brute_force(const Box& shape, const Pose& ps, const Mesh& mesh,
                                                       const Pose& pm, const DistanceOptions& options = {});
/// The same for a capsule.
[[nodiscard]] ShapeDistanceResult distance_brute_force(const Capsule& shape, const Pose& ps, const Mesh& mesh,
                                                       const Pose& pm, const DistanceOptions& options = {});
/// The same for a cylinder.
[[nodiscard]] ShapeDistanceResult distance_brute_force(const Cylinder& shape, const Pose& ps, const Mesh& mesh,
                                                       const Pose& pm, const DistanceOptions& options = {});
/// The same for a convex hull.
[[nodiscard]] ShapeDistanceResult distance_brute_force(const Convex& shape, const Pose& ps, const Mesh& mesh,
                                                       const Pose& pm, const DistanceOptions& options = {});

}  // namespace tightbvh
