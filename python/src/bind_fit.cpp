// tightbvh.fit and what it returns: Box (every fit.hpp method), Ball, Ellipsoid and Dop (Sunday's
// other containers: ball.hpp, ellipsoid.hpp, dop.hpp).
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string_view>

#include "arrays.hpp"
#include "bindings.hpp"
#include "state.hpp"
#include "tightbvh/ball.hpp"
#include "tightbvh/dop.hpp"
#include "tightbvh/ellipsoid.hpp"
#include "tightbvh/fit.hpp"

namespace tightbvh::python {
namespace {

struct DopName {
  std::string_view name;
  DopKind kind;
};
constexpr std::array<DopName, 4> kDops{
    {{"diamond", DopKind::diamond}, {"dop14", DopKind::dop14}, {"dop18", DopKind::dop18}, {"dop26", DopKind::dop26}}};
constexpr std::array<std::string_view, 3> kRoundContainers{"ball", "fast-ball", "ellipsoid"};
constexpr double kDefaultEllipsoidEpsilon = 0.01;  // bounding_ellipsoid's default, as the CLI's

std::string_view dop_name(DopKind kind) {
  for (const DopName& d : kDops)
    if (d.kind == kind) return d.name;
  return "?";
}

// Box methods (fit_method_names()), then the containers: what `method` takes.
std::vector<std::string> method_names() {
  std::vector<std::string> names(fit_method_names().begin(), fit_method_names().end());
  for (const std::string_view name : kRoundContainers) names.emplace_back(name);
  for (const DopName& d : kDops) names.emplace_back(d.name);
  return names;
}

// What fit() works on: points, or a mesh's vertices (and triangle corners for pca, as the CLI).
struct FitInput {
  std::vector<Vec3> points;
  std::optional<std::vector<Vec3>> corners;
};

FitInput read_input(py::handle object) {
  if (py::isinstance<Mesh>(object) || (py::hasattr(object, "vertices") && py::hasattr(object, "faces"))) {
    const std::shared_ptr<const Mesh> mesh = to_mesh(object, "points");
    return {mesh->vertices, triangle_corners(*mesh)};
  }
  return {to_points(object, "points"), std::nullopt};
}

// Takes the options `method` accepts out of `options`; anything left over is a TypeError.
class Options {
 public:
  Options(py::kwargs options, std::string method) : options_(std::move(options)), method_(std::move(method)) {}

  std::optional<double> positive(const char* key) {
    if (!options_.contains(key)) return std::nullopt;
    const py::object value = options_.attr("pop")(key);
    if (value.is_none()) return std::nullopt;
    if (!py::isinstance<py::float_>(value) && !py::isinstance<py::int_>(value))
      throw py::type_error(std::string("fit: ") + key + " must be a number");
    const double x = value.cast<double>();
    if (!(x > 0.0) || !std::isfinite(x))
      throw py::value_error(std::string("fit: ") + key + " must be a positive finite number, got " +
                            py::repr(value).cast<std::string>());
    return x;
  }
  std::optional<int> grid() {
    if (!options_.contains("grid")) return std::nullopt;
    const py::object value = options_.attr("pop")("grid");
    if (py::isinstance<py::bool_>(value) || !py::isinstance<py::int_>(value))
      throw py::type_error("fit: grid must be an integer");
    const long long k = value.cast<long long>();
    if (k < 1 || k > 64) throw py::value_error("fit: grid must be in [1, 64], got " + std::to_string(k));
    return static_cast<int>(k);
  }
  std::optional<bool> flag(const char* key) {
    if (!options_.contains(key)) return std::nullopt;
    const py::object value = options_.attr("pop")(key);
    if (!py::isinstance<py::bool_>(value)) throw py::type_error(std::string("fit: ") + key + " must be True or False");
    return value.cast<bool>();
  }
  // Call after taking every accepted option.
  void finish(const char* accepted) const {
    if (py::len(options_) == 0) return;
    const std::string key = py::str((*options_.begin()).first).cast<std::string>();
    throw py::type_error("fit: method '" + method_ + "' takes no option '" + key + "' (it takes " + accepted + ")");
  }

 private:
  py::kwargs options_;
  std::string method_;
};

FitOptions box_options(FitMethod method, Options& options) {
  FitOptions fit;
  fit.method = method;
  const std::optional<int> grid = options.grid();
  fit.epsilon = options.positive("epsilon");
  if (grid && fit.epsilon) throw py::value_error("fit: grid and epsilon exclude each other (epsilon chooses grid)");
  fit.grid = grid.value_or(fit.grid);
  fit.improve = options.flag("improve").value_or(fit.improve);
  options.finish("grid, epsilon, improve");
  return fit;
}

py::object fit_box(const FitInput& input, FitMethod method, Options& options) {
  const FitOptions fit = box_options(method, options);
  Obb box;
  {
    const py::gil_scoped_release release;
    // pca weights the triangles by area; every other method needs only the points.
    box =
        method == FitMethod::pca && input.corners ? fit_triangles(*input.corners, fit) : fit_points(input.points, fit);
  }
  return py::cast(box);
}

py::object fit_container(const FitInput& input, const std::string& method, Options& options) {
  if (method == "ellipsoid") {
    const double epsilon = options.positive("epsilon").value_or(kDefaultEllipsoidEpsilon);
    options.finish("epsilon");
    Ellipsoid e;
    {
      const py::gil_scoped_release release;
      e = bounding_ellipsoid(input.points, epsilon);
    }
    return py::cast(e);
  }
  options.finish("no options");
  const auto dop = std::find_if(kDops.begin(), kDops.end(), [&](const DopName& d) { return d.name == method; });
  std::optional<Dop> dop_fit;
  Ball ball;
  {
    const py::gil_scoped_release release;
    if (dop != kDops.end())
      dop_fit = bounding_dop(input.points, dop->kind);
    else
      ball = method == "ball" ? bounding_ball(input.points) : fast_ball(input.points);
  }
  return dop_fit ? py::cast(*dop_fit) : py::cast(ball);
}

py::object fit(py::handle points, const std::string& method, py::kwargs kwargs) {
  const std::vector<std::string> names = method_names();
  if (std::find(names.begin(), names.end(), method) == names.end()) {
    std::string expected;
    for (std::size_t i = 0; i < names.size(); ++i)
      expected += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
    throw py::value_error("fit: unknown method '" + method + "' (expected " + expected + ")");
  }
  const FitInput input = read_input(points);
  Options options(std::move(kwargs), method);
  if (const auto box_method = parse_fit_method(method)) return fit_box(input, *box_method, options);
  return fit_container(input, method, options);
}

// contains(points, tolerance) for any container: a bool per point.
template <class Container>
py::array_t<bool> contains(const Container& c, py::handle points, double tolerance) {
  const std::vector<Vec3> p = to_points(points, "points");
  py::array_t<bool> inside(static_cast<py::ssize_t>(p.size()));
  auto out = inside.mutable_unchecked<1>();
  for (std::size_t i = 0; i < p.size(); ++i) out(i) = c.contains(p[i], tolerance);
  return inside;
}

// States: tuples of Python floats (Eigen's column-major order for the axes), bit for bit.
py::object box_state(const Obb& b) {
  return py::make_tuple(vec3_state(b.center), mat3_state(b.axes), vec3_state(b.half_extents));
}
Obb box_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 3, "Box");
  return {state_vec3(f[0], "Box.__setstate__: center"), state_mat3(f[1], "Box.__setstate__: axes"),
          state_vec3(f[2], "Box.__setstate__: half_extents")};
}

py::object ball_state(const Ball& b) { return py::make_tuple(vec3_state(b.center), b.radius); }
Ball ball_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 2, "Ball");
  return {state_vec3(f[0], "Ball.__setstate__: center"), state_real(f[1], "Ball.__setstate__: radius")};
}

py::object ellipsoid_state(const Ellipsoid& e) {
  return py::make_tuple(vec3_state(e.center), mat3_state(e.axes), vec3_state(e.radii));
}
Ellipsoid ellipsoid_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 3, "Ellipsoid");
  Ellipsoid e;
  e.center = state_vec3(f[0], "Ellipsoid.__setstate__: center");
  e.axes = state_mat3(f[1], "Ellipsoid.__setstate__: axes");
  e.radii = state_vec3(f[2], "Ellipsoid.__setstate__: radii");
  return e;
}

// All max_axes slabs, the unused ones too, so the copy is the same object bit for bit.
py::object dop_state(const Dop& d) {
  return py::make_tuple(std::string(dop_name(d.kind)), reals_state(d.min.data(), Dop::max_axes),
                        reals_state(d.max.data(), Dop::max_axes));
}
Dop dop_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 3, "Dop");
  const std::string kind = state_string(f[0], "Dop.__setstate__: kind");
  const auto found = std::find_if(kDops.begin(), kDops.end(), [&](const DopName& d) { return d.name == kind; });
  if (found == kDops.end()) throw py::value_error("Dop.__setstate__: unknown kind '" + kind + "'");
  Dop d;
  d.kind = found->kind;
  state_reals(f[1], d.min.data(), Dop::max_axes, "Dop.__setstate__: min");
  state_reals(f[2], d.max.data(), Dop::max_axes, "Dop.__setstate__: max");
  return d;
}

void bind_box(py::module_& m) {
  py::class_<Obb>(m, "Box", "An oriented box: center (3,), axes (3, 3) with the box axes as columns, half_extents (3,)")
      .def_property_readonly("center", [](const Obb& b) { return to_array(b.center); })
      .def_property_readonly("axes", [](const Obb& b) { return to_array(b.axes); })
      .def_property_readonly("half_extents", [](const Obb& b) { return to_array(b.half_extents); })
      .def_property_readonly("volume", &Obb::volume)
      .def(
          "corners", [](const Obb& b) { return to_array(std::span<const Vec3>(b.corners())); },
          "(8, 3): corner i has sign (-1)^(1 + bit k of i) along axis k")
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&box_state, &box_from_state))
      .def("contains", &contains<Obb>, py::arg("points"), py::arg("tolerance") = 0.0,
           "bool per point: inside the closed box, with an absolute tolerance")
      .def("__repr__", [](const Obb& b) { return "<tightbvh.Box volume=" + std::to_string(b.volume()) + ">"; });
}

void bind_containers(py::module_& m) {
  py::class_<Ball>(m, "Ball", "A ball: center (3,), radius")
      .def_property_readonly("center", [](const Ball& b) { return to_array(b.center); })
      .def_readonly("radius", &Ball::radius)
      .def_property_readonly("volume", &Ball::volume)
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&ball_state, &ball_from_state))
      .def("contains", &contains<Ball>, py::arg("points"), py::arg("tolerance") = 0.0)
      .def("__repr__", [](const Ball& b) { return "<tightbvh.Ball radius=" + std::to_string(b.radius) + ">"; });
  py::class_<Ellipsoid>(m, "Ellipsoid", "An ellipsoid: center (3,), axes (3, 3) as columns, radii (3,)")
      .def_property_readonly("center", [](const Ellipsoid& e) { return to_array(e.center); })
      .def_property_readonly("axes", [](const Ellipsoid& e) { return to_array(e.axes); })
      .def_property_readonly("radii", [](const Ellipsoid& e) { return to_array(e.radii); })
      .def_property_readonly("volume", &Ellipsoid::volume)
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&ellipsoid_state, &ellipsoid_from_state))
      .def("contains", &contains<Ellipsoid>, py::arg("points"), py::arg("tolerance") = 0.0)
      .def("__repr__",
           [](const Ellipsoid& e) { return "<tightbvh.Ellipsoid volume=" + std::to_string(e.volume()) + ">"; });
  py::class_<Dop>(m, "Dop", "A k-DOP: slab i is min[i] <= directions[i] . x <= max[i]")
      .def_property_readonly("kind", [](const Dop& d) { return std::string(dop_name(d.kind)); })
      .def_property_readonly("directions",
                             [](const Dop& d) {
                               std::vector<Vec3> directions;
                               for (int i = 0; i < d.axes(); ++i) directions.push_back(dop_direction(d.kind, i));
                               return to_array(std::span<const Vec3>(directions));
                             })
      .def_property_readonly("min", [](const Dop& d) { return py::array_t<double>(d.axes(), d.min.data()); })
      .def_property_readonly("max", [](const Dop& d) { return py::array_t<double>(d.axes(), d.max.data()); })
      .def_property_readonly("volume", &Dop::volume)
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&dop_state, &dop_from_state))
      .def("contains", &contains<Dop>, py::arg("points"), py::arg("tolerance") = 0.0)
      .def("__repr__", [](const Dop& d) {
        return "<tightbvh.Dop " + std::string(dop_name(d.kind)) + " volume=" + std::to_string(d.volume()) + ">";
      });
}

}  // namespace

void bind_fit(py::module_& m) {
  bind_box(m);
  bind_containers(m);
  m.def("fit", &fit, py::arg("points"), py::arg("method") = "approx",
        "Fits a container to points (N, 3) or to a mesh's vertices (pca on a mesh weights its triangles by "
        "area, as `tightbvh fit`). Box methods (fit_method_names()) return a Box and take grid (1..64), "
        "epsilon (> 0; chooses grid) and improve (bool); 'ball' and 'fast-ball' return a Ball, 'ellipsoid' an "
        "Ellipsoid (option epsilon, default 0.01), 'diamond', 'dop14', 'dop18', 'dop26' a Dop.");
  m.def("fit_methods", &method_names, "Every name fit() takes: the box methods, then the containers.");
}

}  // namespace tightbvh::python
