// Point queries on tightbvh.Model (point_query.hpp): closest_points, signed_distance and contains,
// with the names and return shapes of trimesh.proximity.closest_point, signed_distance and
// Trimesh.contains (the sign is the opposite of trimesh's: negative inside, see docs/python.md).
// NumPy in and out; the GIL is released while querying.
#include <pybind11/numpy.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "tightbvh/point_query.hpp"

namespace tightbvh::python {
namespace {

struct Query {
  std::vector<Vec3> points;
  Pose pose;
  PointQueryOptions options;
};

Query query(py::handle points, py::handle transform, double max_distance, py::handle threads) {
  return {to_points(points, "points"), to_pose(transform, "transform"),
          PointQueryOptions{max_distance, thread_count(threads, "threads")}};
}

// (closest (N, 3), distance (N,), triangle_id (N,) int64[, barycentric (N, 3)]); beyond the
// max_distance: the query point, max_distance, -1 and zeros.
py::tuple closest_arrays(const std::vector<ClosestPoint>& results, bool return_barycentric) {
  const auto n = static_cast<py::ssize_t>(results.size());
  py::array_t<double> closest({n, py::ssize_t{3}}), distance(n), barycentric({n, py::ssize_t{3}});
  py::array_t<std::int64_t> triangle(n);
  auto c = closest.mutable_unchecked<2>();
  auto d = distance.mutable_unchecked<1>();
  auto b = barycentric.mutable_unchecked<2>();
  auto t = triangle.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const ClosestPoint& r = results[static_cast<std::size_t>(i)];
    for (int k = 0; k < 3; ++k) c(i, k) = r.point[k], b(i, k) = r.barycentric[k];
    d(i) = r.distance;
    t(i) = r.beyond_max_distance ? -1 : static_cast<std::int64_t>(r.triangle);
  }
  if (return_barycentric) return py::make_tuple(closest, distance, triangle, barycentric);
  return py::make_tuple(closest, distance, triangle);
}

py::tuple closest_points_py(const PyModel& self, py::handle points, py::handle transform, double max_distance,
                            py::handle threads, bool return_barycentric) {
  const Query q = query(points, transform, max_distance, threads);
  std::vector<ClosestPoint> results;
  {
    const py::gil_scoped_release release;
    results = closest_points(*self.model, q.pose, q.points, q.options);
  }
  return closest_arrays(results, return_barycentric);
}

py::array_t<double> signed_distance_py(const PyModel& self, py::handle points, py::handle transform,
                                       double max_distance, py::handle threads) {
  const Query q = query(points, transform, max_distance, threads);
  std::vector<ClosestPoint> results;
  {
    const py::gil_scoped_release release;
    results = signed_distance(*self.model, q.pose, q.points, q.options);
  }
  py::array_t<double> out(static_cast<py::ssize_t>(results.size()));
  auto d = out.mutable_unchecked<1>();
  for (std::size_t i = 0; i < results.size(); ++i) d(static_cast<py::ssize_t>(i)) = results[i].distance;
  return out;
}

py::object contains_py(const PyModel& self, py::handle points, py::handle transform, py::handle threads,
                       bool return_on_surface) {
  const Query q = query(points, transform, std::numeric_limits<double>::infinity(), threads);
  std::vector<Containment> results;
  {
    const py::gil_scoped_release release;
    results = contains(*self.model, q.pose, q.points, q.options.threads);
  }
  const auto n = static_cast<py::ssize_t>(results.size());
  py::array_t<bool> inside(n), on_surface(n);
  auto in = inside.mutable_unchecked<1>();
  auto on = on_surface.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    in(i) = results[static_cast<std::size_t>(i)] == Containment::inside;
    on(i) = results[static_cast<std::size_t>(i)] == Containment::on_surface;
  }
  if (return_on_surface) return py::make_tuple(inside, on_surface);
  return inside;
}

}  // namespace

void bind_points(py::module_& m) {
  auto model = py::reinterpret_borrow<py::class_<PyModel>>(m.attr("Model"));
  const double inf = std::numeric_limits<double>::infinity();
  model
      .def("closest_points", &closest_points_py, py::arg("points"), py::arg("transform") = py::none(),
           py::arg("max_distance") = inf, py::arg("threads") = 0, py::arg("return_barycentric") = false,
           "The closest point on the surface of each of `points` ((N, 3), world frame; the model at `transform`): "
           "(closest (N, 3), distance (N,), triangle_id (N,) int64) as trimesh.proximity.closest_point, and with "
           "return_barycentric=True also barycentric (N, 3): closest = u a + v b + w c of the triangle's corners in "
           "index order. Points with no triangle closer than max_distance get their own coordinates, max_distance "
           "and -1 (barycentric 0). threads=0: all cores.")
      .def("signed_distance", &signed_distance_py, py::arg("points"), py::arg("transform") = py::none(),
           py::arg("max_distance") = inf, py::arg("threads") = 0,
           "The distance of each of `points` to the surface, NEGATIVE INSIDE (the opposite of trimesh's "
           "proximity.signed_distance), 0 on the surface; (N,) float64. The sign is exact (ray parity with exact "
           "predicates). ValueError when the mesh is not closed.")
      .def("contains", &contains_py, py::arg("points"), py::arg("transform") = py::none(), py::arg("threads") = 0,
           py::arg("return_on_surface") = false,
           "Whether each of `points` is strictly inside the solid (N,) bool, exact; with return_on_surface=True, "
           "(inside, on_surface). ValueError when the mesh is not closed.");
}

}  // namespace tightbvh::python
