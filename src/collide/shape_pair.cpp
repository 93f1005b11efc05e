// Two posed primitive shapes: each a core (a point, a segment, a box, a cylinder or a convex hull)
// grown by a radius, their distance through tri_tri_distance on the cores (sphere, capsule, box)
// or GJK (any pair with a cylinder or a convex hull). See include/tightbvh/shape.hpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <variant>

#include "gjk.hpp"
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

// The support point (greatest d . x) of the shape's core, world frame: a sphere's center, a
// capsule's axis segment, the solid box, cylinder or hull.
[[nodiscard]] Vec3 core_support(const Shape& shape, const Pose& pose, const Vec3& d) {
  const Vec3 local = pose.rotation.transpose() * d;
  struct Support {
    const Vec3& d;
    Vec3 operator()(const Sphere&) const { return Vec3::Zero(); }
    Vec3 operator()(const Capsule& s) const { return Vec3(0.0, 0.0, d.z() >= 0.0 ? 0.5 * s.length : -0.5 * s.length); }
    Vec3 operator()(const Box& s) const {
      return Vec3(d.x() >= 0.0 ? 0.5 * s.size.x() : -0.5 * s.size.x(), d.y() >= 0.0 ? 0.5 * s.size.y() : -0.5 * s.size.y(),
                  d.z() >= 0.0 ? 0.5 * s.size.z() : -0.5 * s.size.z());
    }
    Vec3 operator()(const Cylinder& s) const {
      const double n = std::hypot(d.x(), d.y());
      const double z = d.z() >= 0.0 ? 0.5 * s.length : -0.5 * s.length;
      if (!(n > 0.0)) return Vec3(0.0, 0.0, z);
      return Vec3(s.radius * d.x() / n, s.radius * d.y() / n, z);
    }
    Vec3 operator()(const Convex& s) const {
      std::size_t best = 0;
      double top = -std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < s.vertices.size(); ++i) {
        const double p = d.dot(s.vertices[i]);
        if (p > top) top = p, best = i;
      }
      return s.vertices[best];
    }
  };
  return pose.apply(std::visit(Support{local}, shape));
}

[[nodiscard]] double core_radius(const Shape& shape) {
  if (const auto* s = std::get_if<Sphere>(&shape)) return s->radius;
  if (const auto* s = std::get_if<Capsule>(&shape)) return s->radius;
  return 0.0;
}

[[nodiscard]] bool needs_gjk(const Shape& shape) {
  return std::holds_alternative<Cylinder>(shape) || std::holds_alternative<Convex>(shape);
}

// A point of the shape's core, world frame.
[[nodiscard]] Vec3 core_point(const Shape& shape, const Pose& pose) {
  if (const auto* s = std::get_if<Convex>(&shape)) return pose.apply(s->vertices.front());
  return pose.translation;
}

// A strict order of posed shapes (kind, then pose, then box), for the canonical order of a pair.
[[nodiscard]] bool precedes(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  if (a.index() != b.index()) return a.index() < b.index();
  const auto key = [](const Shape& s, const Pose& p) {
    std::array<double, 15> k{};
    for (int i = 0; i < 3; ++i) k[i] = p.translation[i];
    for (int i = 0; i < 9; ++i) k[3 + i] = p.rotation(i / 3, i % 3);
    const Vec3 h = bounding_box(s).half_extents;
    for (int i = 0; i < 3; ++i) k[12 + i] = h[i];
    return k;
  };
  return key(a, pa) < key(b, pb);
}

// The scale of the pair's coordinates: the farthest reach of either bounding box from the origin.
[[nodiscard]] double pair_scale(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  const Obb ba = bounding_box(a), bb = bounding_box(b);
  return std::max(pa.apply(ba.center).cwiseAbs().maxCoeff() + ba.half_extents.norm(),
                  pb.apply(bb.center).cwiseAbs().maxCoeff() + bb.half_extents.norm());
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
    const char* operator()(const Cylinder&) const { return "cylinder"; }
    const char* operator()(const Convex&) const { return "convex"; }
  };
  return std::visit(Name{}, shape);
}

ShapePairDistance distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  require_valid_pose(pa, "shape distance", "the pose of A");
  require_valid_pose(pb, "shape distance", "the pose of B");
  TriangleDistance d;
  double ra = 0.0, rb = 0.0, tolerance = 0.0;
  if (needs_gjk(a) || needs_gjk(b)) {
    // GJK on the cores (Gilbert, Johnson & Keerthi 1988), to 1e-12 of the distance or the scale;
    // touching within kCylinderTolerance of the scale (shape.hpp).
    // Run in a canonical order of the two, so that swapping A and B gives the very same numbers
    // (a scene may ask for either order).
    const bool swap = precedes(b, pb, a, pa);
    const Shape& first = swap ? b : a;
    const Shape& second = swap ? a : b;
    const Pose& pf = swap ? pb : pa;
    const Pose& ps = swap ? pa : pb;
    const double scale = pair_scale(first, pf, second, ps);
    const gjk::Result g = gjk::distance([&](const Vec3& dir) { return core_support(first, pf, dir); },
                                        [&](const Vec3& dir) { return core_support(second, ps, dir); },
                                        core_point(first, pf), core_point(second, ps), 1e-12 * scale, 1e-12);
    d.distance = g.distance;
    d.point_p = swap ? g.point_b : g.point_a;
    d.point_q = swap ? g.point_a : g.point_b;
    ra = core_radius(a);
    rb = core_radius(b);
    tolerance = kCylinderTolerance * scale;
  } else {
    const auto core = [](const Shape& shape, const Pose& pose) {
      return std::visit(
          [&](const auto& s) -> Core {
            if constexpr (requires { core_of(s, pose); }) return core_of(s, pose);
            else return Core{};  // a cylinder or a hull: the GJK branch
          },
          shape);
    };
    const Core ca = core(a, pa), cb = core(b, pb);
    d = core_distance(ca, cb);
    ra = ca.radius;
    rb = cb.radius;
  }
  const double reach = ra + rb;
  if (d.distance <= reach + tolerance) {
    // Touching: the point that splits the cores' closest points by the radii lies in both.
    const Vec3 common = reach > 0.0 ? d.point_p + (d.point_q - d.point_p) * (ra / reach) : d.point_p;
    return {0.0, common, common};
  }
  const Vec3 direction = (d.point_q - d.point_p) / d.distance;
  return {d.distance - reach, d.point_p + ra * direction, d.point_q - rb * direction};
}

}  // namespace tightbvh
