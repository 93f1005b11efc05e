// Two posed primitive shapes: each a core (a point, a segment or a box) grown by a radius, their
// distance through tri_tri_distance on the cores. See include/tightbvh/shape.hpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <variant>

#include "tightbvh/scene.hpp"
#include "tightbvh/shape.hpp"
#include "tightbvh/tri_distance.hpp"

namespace tightbvh {
namespace {

// A shape in the world frame: the points within `radius` of its core. Points and segments are
// degenerate triangles (p, q, q); a box keeps its frame for the inside test.
struct Core {
  bool is_box = false;
  Vec3 p = Vec3::Zero(), q = Vec3::Zero();  // a point (p == q) or a segment
  Obb box;                                  // is_box: the solid box
  double radius = 0.0;
};

[[nodiscard]] Core core_of(const Sphere& s, const Pose& pose) { return {false, pose.translation, pose.translation, {}, s.radius}; }
[[nodiscard]] Core core_of(const Capsule& s, const Pose& pose) {
  return {false, pose.apply(Vec3(0.0, 0.0, -0.5 * s.length)), pose.apply(Vec3(0.0, 0.0, 0.5 * s.length)), {}, s.radius};
}
[[nodiscard]] Core core_of(const Box& s, const Pose& pose) {
  return {true, Vec3::Zero(), Vec3::Zero(), Obb{pose.translation, pose.rotation, 0.5 * s.size}, 0.0};
}

// The box's 8 corners, bit k of the index choosing the sign along axis k.
[[nodiscard]] std::array<Vec3, 8> corners(const Obb& box) {
  std::array<Vec3, 8> out;
  for (int i = 0; i < 8; ++i) {
    Vec3 local;
    for (int k = 0; k < 3; ++k) local[k] = (i >> k & 1) ? box.half_extents[k] : -box.half_extents[k];
    out[i] = box.center + box.axes * local;
  }
  return out;
}

// The box surface as 12 triangles of corner indices (two per face).
constexpr std::array<std::array<int, 3>, 12> kFaces{{{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}}};

[[nodiscard]] bool inside(const Obb& box, const Vec3& x) {
  const Vec3 local = box.to_local(x);
  return (local.cwiseAbs().array() <= box.half_extents.array()).all();
}

// The least tri_tri_distance from triangle (x0, x1, x2) to the box surface.
[[nodiscard]] TriangleDistance to_surface(const std::array<Vec3, 8>& c, const Vec3& x0, const Vec3& x1, const Vec3& x2) {
  TriangleDistance best;
  best.distance = std::numeric_limits<double>::infinity();
  for (const auto& f : kFaces) {
    const TriangleDistance d = tri_tri_distance(x0, x1, x2, c[f[0]], c[f[1]], c[f[2]]);
    if (d.distance < best.distance) best = d;
  }
  return best;
}

// The distance between two cores, with a closest point on each (point_p on a, point_q on b).
[[nodiscard]] TriangleDistance core_distance(const Core& a, const Core& b) {
  if (!a.is_box && !b.is_box) return tri_tri_distance(a.p, a.q, a.q, b.p, b.q, b.q);
  if (a.is_box && !b.is_box) {
    TriangleDistance d = core_distance(b, a);
    std::swap(d.point_p, d.point_q);
    return d;
  }
  if (!a.is_box) {  // a point or segment against box b
    for (const Vec3& x : {a.p, a.q})
      if (inside(b.box, x)) return {0.0, x, x};
    return to_surface(corners(b.box), a.p, a.q, a.q);
  }
  const std::array<Vec3, 8> ca = corners(a.box), cb = corners(b.box);
  for (const Vec3& x : cb)
    if (inside(a.box, x)) return {0.0, x, x};
  for (const Vec3& x : ca)
    if (inside(b.box, x)) return {0.0, x, x};
  TriangleDistance best;
  best.distance = std::numeric_limits<double>::infinity();
  for (const auto& f : kFaces) {
    const TriangleDistance d = to_surface(cb, ca[f[0]], ca[f[1]], ca[f[2]]);
    if (d.distance < best.distance) best = d;
  }
  return best;
}

}  // namespace

Obb bounding_box(const Shape& shape) {
  return std::visit([](const auto& s) { return bounding_box(s); }, shape);
}

const char* shape_name(const Shape& shape) {
  struct Name {
    const char* operator()(const Sphere&) const { return "sphere"; }
    const char* operator()(const Box&) const { return "box"; }
    const char* operator()(const Capsule&) const { return "capsule"; }
  };
  return std::visit(Name{}, shape);
}

ShapePairDistance distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  require_valid_pose(pa, "shape distance", "the pose of A");
  require_valid_pose(pb, "shape distance", "the pose of B");
  const Core ca = std::visit([&](const auto& s) { return core_of(s, pa); }, a);
  const Core cb = std::visit([&](const auto& s) { return core_of(s, pb); }, b);
  const TriangleDistance d = core_distance(ca, cb);
  const double reach = ca.radius + cb.radius;
  if (d.distance <= reach) {
    // Touching: the point that splits the cores' closest points by the radii lies in both.
    const Vec3 common = reach > 0.0 ? d.point_p + (d.point_q - d.point_p) * (ca.radius / reach) : d.point_p;
    return {0.0, common, common};
  }
  const Vec3 direction = (d.point_q - d.point_p) / d.distance;
  return {d.distance - reach, d.point_p + ca.radius * direction, d.point_q - cb.radius * direction};
}

}  // namespace tightbvh
