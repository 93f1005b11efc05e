// The cylinder and the convex hull as value types: their checks and bounds. Their per-triangle
// tests are in shape_convex.hpp (with shape_query.cpp's descent). See include/tightbvh/shape.hpp.
#include <cmath>
#include <sstream>
#include <string>

#include "tightbvh/error.hpp"
#include "tightbvh/hull.hpp"
#include "tightbvh/shape.hpp"

namespace tightbvh {
namespace {

[[nodiscard]] std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

void require_size(const char* field, double value) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw InputError(std::string("Cylinder: ") + field + " must be positive and finite, got " + number(value));
}

}  // namespace

Cylinder::Cylinder(double r, double l) : radius(r), length(l) {
  require_size("radius", r);
  require_size("length", l);
}

Convex::Convex(std::span<const Vec3> points) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("Convex: points[" + std::to_string(i) + "] is not finite (" + number(points[i].x()) + ", " +
                       number(points[i].y()) + ", " + number(points[i].z()) + ")");
  if (points.size() < 4)
    throw InputError("Convex: points: a solid hull needs at least 4 points, got " + std::to_string(points.size()));
  ConvexHull3 hull = convex_hull(points);
  if (hull.dimension < 3) {
    static const char* const kind[] = {"all one point", "collinear", "coplanar"};
    throw InputError("Convex: points: the hull is flat (affine dimension " + std::to_string(hull.dimension) +
                     ", the points are " + kind[hull.dimension] + "); a convex shape must be solid");
  }
  vertices = std::move(hull.vertices);
  faces = std::move(hull.faces);
  // Outward by (b - a) x (c - a), whatever order the hull keeps its faces in.
  for (std::size_t f = 0; f < faces.size(); ++f) {
    auto& t = faces[f];
    const Vec3 n = (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
    if (n.dot(hull.face_normals[f]) < 0.0) std::swap(t[1], t[2]);
  }
}

Obb bounding_box(const Cylinder& shape) {
  return {Vec3::Zero(), Mat3::Identity(), Vec3(shape.radius, shape.radius, 0.5 * shape.length)};
}

Obb bounding_box(const Convex& shape) {
  Vec3 lo = shape.vertices.front(), hi = lo;
  for (const Vec3& p : shape.vertices) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return {0.5 * (lo + hi), Mat3::Identity(), 0.5 * (hi - lo)};
}

}  // namespace tightbvh
