// Primitive shapes against meshes (shape.hpp): the submodule tightbvh.shapes (Sphere, Box,
// Capsule with FCL's conventions; tightbvh.Box is already the fitted box, hence the submodule),
// and collide_shape / distance_shape of a shape against a tightbvh.Model. A fitted tightbvh.Box is
// a shape too, posed where it was fitted. NumPy in and out; the GIL is released while querying.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "state.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/shape.hpp"

namespace tightbvh::python {
namespace {

// The shape argument of collide_shape / distance_shape: TypeError for anything but a shape.
[[nodiscard]] ShapeAt to_shape(py::handle object, py::handle pose_object) {
  if (auto s = shape_at(object, to_pose(pose_object, "shape_pose"))) return *s;
  throw py::type_error("shape must be a tightbvh.shapes.Sphere, Box, Capsule, Cylinder or Convex, or a fitted tightbvh.Box, got " +
                       py::str(py::type::of(object).attr("__name__")).cast<std::string>());
}

[[nodiscard]] std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// A shape's answer: hit, triangles (K,) int64 (sorted, unique with all_pairs), stats.
struct PyShapeResult {
  bool hit = false;
  py::array_t<std::int64_t> triangles;
  QueryStats stats;
};

PyShapeResult collide_shape_py(py::handle shape, py::handle shape_pose, const PyModel& model, py::handle model_pose,
                               bool all_pairs, double margin) {
  const ShapeAt s = to_shape(shape, shape_pose);
  const Pose pm = to_pose(model_pose, "model_pose");
  QueryOptions options;
  options.mode = all_pairs ? QueryMode::all_pairs : QueryMode::first_hit;
  options.margin = margin;
  ShapeQueryResult r;
  {
    const py::gil_scoped_release release;
    r = std::visit([&](const auto& typed) { return collide(typed, s.pose, *model.model, pm, options); }, s.shape);
  }
  py::array_t<std::int64_t> triangles(static_cast<py::ssize_t>(r.triangles.size()));
  auto t = triangles.mutable_unchecked<1>();
  for (std::size_t i = 0; i < r.triangles.size(); ++i) t(static_cast<py::ssize_t>(i)) = r.triangles[i];
  return {r.hit, triangles, r.stats};
}

ShapeDistanceResult distance_shape_py(py::handle shape, py::handle shape_pose, const PyModel& model,
                                      py::handle model_pose, double absolute_error, double relative_error,
                                      double upper_bound) {
  const ShapeAt s = to_shape(shape, shape_pose);
  const Pose pm = to_pose(model_pose, "model_pose");
  DistanceOptions options;
  options.absolute_error = absolute_error;
  options.relative_error = relative_error;
  options.upper_bound = upper_bound;
  const py::gil_scoped_release release;
  return std::visit([&](const auto& typed) { return distance(typed, s.pose, *model.model, pm, options); }, s.shape);
}

// A point of a distance answer: None beyond the upper bound.
py::object point_or_none(const ShapeDistanceResult& r, const Vec3& p) {
  if (r.beyond_upper_bound) return py::none();
  return to_array(p);
}

// States for pickling (state.hpp): every field, checked on the way back.
py::object shape_result_state(const PyShapeResult& r) {
  return py::make_tuple(r.hit, r.triangles.attr("copy")(), r.stats.box_tests, r.stats.triangle_tests);
}

PyShapeResult shape_result_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 4, "ShapeResult");
  const std::string what = "ShapeResult.__setstate__";
  PyShapeResult r;
  r.hit = state_bool(f[0], what + ": hit");
  if (!py::isinstance<py::array>(f[1])) throw py::type_error(what + ": triangles must be a NumPy array");
  const py::array triangles = py::reinterpret_borrow<py::array>(f[1]);
  if (triangles.dtype().kind() != 'i' || triangles.dtype().itemsize() != 8 || triangles.ndim() != 1)
    throw py::type_error(what + ": triangles must be a 1-D int64 array");
  r.triangles = py::array_t<std::int64_t>::ensure(triangles.attr("copy")());
  r.stats.box_tests = state_count(f[2], what + ": box_tests");
  r.stats.triangle_tests = state_count(f[3], what + ": triangle_tests");
  return r;
}

py::object shape_distance_state(const ShapeDistanceResult& r) {
  return py::make_tuple(r.distance, r.intersecting, r.beyond_upper_bound, r.triangle, vec3_state(r.point_shape),
                        vec3_state(r.point_mesh), r.stats.node_pairs, r.stats.triangle_pairs);
}

ShapeDistanceResult shape_distance_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 8, "ShapeDistance");
  const std::string what = "ShapeDistance.__setstate__";
  ShapeDistanceResult r;
  r.distance = state_real(f[0], what + ": distance");
  r.intersecting = state_bool(f[1], what + ": intersecting");
  r.beyond_upper_bound = state_bool(f[2], what + ": beyond_upper_bound");
  r.triangle = static_cast<std::uint32_t>(state_count(f[3], what + ": triangle", 0xFFFFFFFFu));
  r.point_shape = state_vec3(f[4], what + ": point_shape");
  r.point_mesh = state_vec3(f[5], what + ": point_mesh");
  r.stats.node_pairs = state_count(f[6], what + ": node_pairs");
  r.stats.triangle_pairs = state_count(f[7], what + ": triangle_pairs");
  return r;
}

}  // namespace

namespace {

// Three numbers (a NumPy array or any sequence); ValueError naming `name` otherwise.
[[nodiscard]] Vec3 vec3_of(py::handle object, const std::string& name) {
  const py::sequence values = py::reinterpret_borrow<py::sequence>(object);
  if (!py::isinstance<py::sequence>(object) || py::len(values) != 3) throw py::value_error(name + ": expected 3 numbers");
  return {py::float_(values[0]).cast<double>(), py::float_(values[1]).cast<double>(), py::float_(values[2]).cast<double>()};
}

// trimesh's primitives, kept exact rather than taken as their tessellated vertices and faces:
// trimesh.primitives.Sphere, Box, Capsule and Cylinder, read from the attributes of their
// `primitive` (radius, extents, height, transform; an older Sphere's center when it has no
// transform). Their conventions are FCL's: each centered in its frame, Box's extents its full side
// lengths, Capsule along z with height the distance of its caps' centers, Cylinder along z with
// height its full length. A primitive whose transform is
// not rigid (scaled) is left to be its mesh, as trimesh itself would collide it.
[[nodiscard]] std::optional<ShapeAt> trimesh_primitive(py::handle object, const Pose& pose) {
  const py::handle type = py::type::handle_of(object);
  if (!py::hasattr(type, "__module__") || py::str(type.attr("__module__")).cast<std::string>() != "trimesh.primitives")
    return std::nullopt;
  const std::string kind = py::str(type.attr("__name__"));
  if (kind != "Sphere" && kind != "Box" && kind != "Capsule" && kind != "Cylinder") return std::nullopt;
  const py::object p = object.attr("primitive");
  Pose local = Pose::identity();
  if (py::hasattr(p, "transform")) {
    try {
      local = to_pose(p.attr("transform"), "trimesh " + kind + " primitive.transform");
    } catch (const py::value_error&) {
      return std::nullopt;  // not rigid: its mesh stands for it
    }
  } else {
    local.translation = vec3_of(p.attr("center"), "trimesh " + kind + " primitive.center");
  }
  const Pose placed{pose.rotation * local.rotation, pose.apply(local.translation)};
  const auto size = [&](const char* field) { return py::float_(p.attr(field)).cast<double>(); };
  if (kind == "Sphere") return ShapeAt{Sphere(size("radius")), placed};
  if (kind == "Capsule") return ShapeAt{Capsule(size("radius"), size("height")), placed};
  if (kind == "Cylinder") return ShapeAt{Cylinder(size("radius"), size("height")), placed};
  return ShapeAt{Box(vec3_of(p.attr("extents"), "trimesh Box primitive.extents")), placed};
}

}  // namespace

std::optional<ShapeAt> shape_at(py::handle object, const Pose& pose) {
  if (auto primitive = trimesh_primitive(object, pose)) return primitive;
  if (py::isinstance<Sphere>(object)) return ShapeAt{object.cast<Sphere>(), pose};
  if (py::isinstance<Box>(object)) return ShapeAt{object.cast<Box>(), pose};
  if (py::isinstance<Capsule>(object)) return ShapeAt{object.cast<Capsule>(), pose};
  if (py::isinstance<Cylinder>(object)) return ShapeAt{object.cast<Cylinder>(), pose};
  if (py::isinstance<Convex>(object)) return ShapeAt{object.cast<Convex>(), pose};
  if (py::isinstance<Obb>(object)) {
    const Obb fitted = object.cast<Obb>();
    if (fitted.axes.determinant() < 0.0)
      throw py::value_error("shape: the fitted Box's axes are not right-handed (determinant < 0)");
    return ShapeAt{Box(2.0 * fitted.half_extents), Pose{pose.rotation * fitted.axes, pose.apply(fitted.center)}};
  }
  return std::nullopt;
}

void bind_shapes(py::module_& m) {
  py::module_ shapes = m.def_submodule(
      "shapes", "Primitive shapes for collide_shape and distance_shape, with FCL's conventions: each centered at "
                "the origin of its frame; Capsule along the local z axis.");
  py::class_<Sphere>(shapes, "Sphere", "A solid sphere centered at the origin of its frame (FCL's Sphere).")
      .def(py::init<double>(), py::arg("radius"), "ValueError unless radius is positive and finite.")
      .def_readonly("radius", &Sphere::radius)
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle([](const Sphere& s) -> py::object { return py::make_tuple(s.radius); },
                      [](const py::object& state) {
                        return Sphere(state_real(state_tuple(state, 1, "Sphere")[0], "Sphere.__setstate__: radius"));
                      }))
      .def("__repr__", [](const Sphere& s) { return "tightbvh.shapes.Sphere(radius=" + number(s.radius) + ")"; });

  py::class_<Box>(shapes, "Box",
                  "A solid box centered at the origin of its frame, faces normal to the local axes (FCL's Box(x, y, "
                  "z); trimesh's primitives.Box(extents)): full side lengths.")
      .def(py::init<double, double, double>(), py::arg("x"), py::arg("y"), py::arg("z"),
           "ValueError unless each side length is positive and finite.")
      .def(py::init([](const py::array_t<double, py::array::c_style | py::array::forcecast>& extents) {
             if (extents.ndim() != 1 || extents.shape(0) != 3)
               throw py::value_error("Box: extents must have shape (3,), got " + std::to_string(extents.size()) +
                                     " values in " + std::to_string(extents.ndim()) + " dimensions");
             return Box(Vec3(extents.at(0), extents.at(1), extents.at(2)));
           }),
           py::arg("extents"), "The box of these three side lengths ((3,) array-like).")
      .def_property_readonly("extents", [](const Box& b) { return to_array(b.size); },
                             "the full side lengths along x, y, z, (3,) float64")
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle([](const Box& b) -> py::object { return vec3_state(b.size); },
                      [](const py::object& state) { return Box(state_vec3(state, "Box.__setstate__: extents")); }))
      .def("__repr__", [](const Box& b) {
        return "tightbvh.shapes.Box(" + number(b.size.x()) + ", " + number(b.size.y()) + ", " + number(b.size.z()) + ")";
      });

  py::class_<Capsule>(shapes, "Capsule",
                      "A solid capsule: the points within radius of the segment from (0, 0, -length / 2) to (0, 0, "
                      "length / 2) of its frame (FCL's Capsule(radius, lz); trimesh calls the length height).")
      .def(py::init<double, double>(), py::arg("radius"), py::arg("length"),
           "ValueError unless both are positive and finite.")
      .def_readonly("radius", &Capsule::radius)
      .def_readonly("length", &Capsule::length)
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle([](const Capsule& c) -> py::object { return py::make_tuple(c.radius, c.length); },
                      [](const py::object& state) {
                        const py::tuple f = state_tuple(state, 2, "Capsule");
                        return Capsule(state_real(f[0], "Capsule.__setstate__: radius"),
                                       state_real(f[1], "Capsule.__setstate__: length"));
                      }))
      .def("__repr__", [](const Capsule& c) {
        return "tightbvh.shapes.Capsule(radius=" + number(c.radius) + ", length=" + number(c.length) + ")";
      });

  py::class_<Cylinder>(shapes, "Cylinder",
                       "A solid cylinder along the local z axis, centered, from z = -length / 2 to length / 2 (FCL's "
                       "Cylinder(radius, lz); trimesh's primitives.Cylinder(radius, height)).")
      .def(py::init<double, double>(), py::arg("radius"), py::arg("length"),
           "ValueError unless both are positive and finite.")
      .def_readonly("radius", &Cylinder::radius)
      .def_readonly("length", &Cylinder::length)
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle([](const Cylinder& c) -> py::object { return py::make_tuple(c.radius, c.length); },
                      [](const py::object& state) {
                        const py::tuple f = state_tuple(state, 2, "Cylinder");
                        return Cylinder(state_real(f[0], "Cylinder.__setstate__: radius"),
                                        state_real(f[1], "Cylinder.__setstate__: length"));
                      }))
      .def("__repr__", [](const Cylinder& c) {
        return "tightbvh.shapes.Cylinder(radius=" + number(c.radius) + ", length=" + number(c.length) + ")";
      });

  py::class_<Convex>(shapes, "Convex",
                     "A solid convex polyhedron: the convex hull of points given in its frame (FCL's Convex). Only the "
                     "hull is kept: vertices (V, 3) float64 and outward faces (F, 3) int64.")
      .def(py::init([](py::handle points) { return Convex(to_points(points, "Convex: points")); }), py::arg("points"),
           "The hull of (N, 3) points; ValueError for NaN or infinity, fewer than 4 points, or a flat hull.")
      .def_property_readonly("vertices", [](const Convex& c) { return to_array(std::span<const Vec3>(c.vertices)); },
                             "the hull's vertices (V, 3) float64 (a copy)")
      .def_property_readonly(
          "faces",
          [](const Convex& c) {
            py::array_t<std::int64_t> faces({static_cast<py::ssize_t>(c.faces.size()), py::ssize_t{3}});
            auto f = faces.mutable_unchecked<2>();
            for (std::size_t i = 0; i < c.faces.size(); ++i)
              for (int k = 0; k < 3; ++k) f(static_cast<py::ssize_t>(i), k) = c.faces[i][static_cast<std::size_t>(k)];
            return faces;
          },
          "the hull's faces (F, 3) int64, counter-clockwise seen from outside (a copy)")
      .def("__reduce_ex__", &reduce_ex)
      // Pickled as its hull's vertices: the hull of those is the same solid.
      .def(py::pickle([](const Convex& c) -> py::object { return py::make_tuple(to_array(std::span<const Vec3>(c.vertices))); },
                      [](const py::object& state) {
                        return Convex(to_points(state_tuple(state, 1, "Convex")[0], "Convex.__setstate__: vertices"));
                      }))
      .def("__repr__", [](const Convex& c) {
        return "tightbvh.shapes.Convex(<" + std::to_string(c.vertices.size()) + " vertices, " +
               std::to_string(c.faces.size()) + " faces>)";
      });

  py::class_<PyShapeResult>(m, "ShapeResult",
                            "collide_shape's answer: hit, triangles (K,) int64 (the mesh's triangles that touch the "
                            "shape: every one, sorted, with all_pairs; else the one found), stats")
      .def_readonly("hit", &PyShapeResult::hit)
      .def_readonly("triangles", &PyShapeResult::triangles)
      .def_property_readonly("stats",
                             [](const PyShapeResult& r) {
                               py::dict d;
                               d["box_tests"] = r.stats.box_tests;
                               d["triangle_tests"] = r.stats.triangle_tests;
                               return d;
                             })
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&shape_result_state, &shape_result_from_state))
      .def("__repr__", [](const PyShapeResult& r) {
        return "<tightbvh.ShapeResult hit=" + std::string(r.hit ? "True" : "False") +
               " triangles=" + std::to_string(r.triangles.size()) + ">";
      });

  py::class_<ShapeDistanceResult>(m, "ShapeDistance",
                                  "distance_shape's answer: distance (0 when touching), intersecting, "
                                  "beyond_upper_bound, triangle, point_shape and point_mesh (world frame), stats")
      .def_readonly("distance", &ShapeDistanceResult::distance)
      .def_readonly("intersecting", &ShapeDistanceResult::intersecting)
      .def_readonly("beyond_upper_bound", &ShapeDistanceResult::beyond_upper_bound)
      .def_property_readonly(
          "triangle",
          [](const ShapeDistanceResult& r) -> py::object {
            if (r.beyond_upper_bound) return py::none();
            return py::int_(r.triangle);
          },
          "the closest triangle's index, None beyond the upper bound")
      .def_property_readonly("point_shape", [](const ShapeDistanceResult& r) { return point_or_none(r, r.point_shape); },
                             "the closest point on the shape (world frame), None beyond the upper bound")
      .def_property_readonly("point_mesh", [](const ShapeDistanceResult& r) { return point_or_none(r, r.point_mesh); },
                             "the closest point on the mesh (world frame), None beyond the upper bound")
      .def_property_readonly("stats",
                             [](const ShapeDistanceResult& r) {
                               py::dict d;
                               d["node_pairs"] = r.stats.node_pairs;
                               d["triangle_pairs"] = r.stats.triangle_pairs;
                               return d;
                             })
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&shape_distance_state, &shape_distance_from_state))
      .def("__repr__", [](const ShapeDistanceResult& r) {
        return "<tightbvh.ShapeDistance distance=" + number(r.distance) + ">";
      });

  const double inf = std::numeric_limits<double>::infinity();
  m.def("collide_shape", &collide_shape_py, py::arg("shape"), py::arg("shape_pose"), py::arg("model"),
        py::arg("model_pose") = py::none(), py::arg("all_pairs") = false, py::arg("margin") = 0.0,
        "Which triangles of `model` (at model_pose, a 4x4 transform or None) touch `shape` (a tightbvh.shapes "
        "Sphere, Box, Capsule, Cylinder or Convex at shape_pose, or a fitted tightbvh.Box, where it was fitted, moved by shape_pose): the first found, or with all_pairs=True every one; with margin > 0 those within "
        "it. Touching is decided exactly for every shape but the cylinder (GJK, within 1e-9 of the scale). -> ShapeResult");
  m.def("distance_shape", &distance_shape_py, py::arg("shape"), py::arg("shape_pose"), py::arg("model"),
        py::arg("model_pose") = py::none(), py::arg("absolute_error") = 0.0, py::arg("relative_error") = 0.0,
        py::arg("upper_bound") = inf,
        "The minimum distance between `shape` (at shape_pose) and `model` (at model_pose), with the closest "
        "triangle and points (world frame); 0 when they touch. -> ShapeDistance");
}

}  // namespace tightbvh::python
