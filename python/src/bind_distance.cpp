// tightbvh.distance (on trees and meshes, or on two Models), distance_batch, distance_brute_force,
// refit and Distance (the answer).
#include <pybind11/stl.h>

#include <limits>
#include <utility>

#include "arrays.hpp"
#include "bindings.hpp"
#include "state.hpp"
#include "tightbvh/distance.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/refit.hpp"

namespace tightbvh::python {
namespace {

DistanceOptions distance_options(double absolute_error, double relative_error, double upper_bound, bool solid,
                                 bool signed_distance) {
  DistanceOptions options;
  options.signed_distance = signed_distance;
  options.absolute_error = absolute_error;  // checked by the query (InputError -> ValueError)
  options.relative_error = relative_error;
  options.upper_bound = upper_bound;
  options.solid = solid;
  return options;
}

// Whether the answer has a triangle pair: not beyond the upper bound, not a solid's containment,
// not a penetration (signed_distance's deepest vertex).
bool has_pair(const DistanceResult& r) {
  return !r.beyond_upper_bound && r.inside == Inside::none && r.deepest == Inside::none;
}

// The triangle pair, or None when no pair is the answer.
py::object triangles(const DistanceResult& r) {
  if (!has_pair(r)) return py::none();
  return py::make_tuple(r.pair.a, r.pair.b);
}

// A point of the answer, or None beyond the upper bound (no point was found).
py::object point(const DistanceResult& r, const Vec3& p) {
  if (r.beyond_upper_bound) return py::none();
  return to_array(p);
}

// State: (distance, beyond_upper_bound, (triangle of A, triangle of B), point_a, point_b,
// point_a_local, point_b_local, node_pairs, triangle_pairs, inside, deepest, deepest_vertex,
// penetration_lower_bound_is_zero, curve_length): every field, set or not.
py::object distance_state(const DistanceResult& r) {
  return py::make_tuple(r.distance, r.beyond_upper_bound, py::make_tuple(r.pair.a, r.pair.b), vec3_state(r.point_a),
                        vec3_state(r.point_b), vec3_state(r.point_a_local), vec3_state(r.point_b_local),
                        r.stats.node_pairs, r.stats.triangle_pairs, to_string(r.inside), to_string(r.deepest),
                        r.deepest_vertex, r.penetration_lower_bound_is_zero, r.curve_length);
}

DistanceResult distance_from_state(const py::object& state) {
  // 14 fields; a state of 10 (the fields before deepest) reads as an unsigned answer, one of 13
  // (without curve_length) as a curve length of 0.
  const std::size_t fields = py::isinstance<py::tuple>(state) ? py::len(state) : 0;
  const bool has_penetration = fields == 13 || fields == 14;
  const py::tuple f = state_tuple(state, has_penetration ? fields : 10, "Distance");
  const std::string what = "Distance.__setstate__";
  DistanceResult r;
  r.distance = state_real(f[0], what + ": distance");
  r.beyond_upper_bound = state_bool(f[1], what + ": beyond_upper_bound");
  const py::tuple pair = state_tuple(f[2], 2, "Distance triangles");
  r.pair.a = static_cast<std::uint32_t>(state_count(pair[0], what + ": triangles", 0xFFFFFFFFu));
  r.pair.b = static_cast<std::uint32_t>(state_count(pair[1], what + ": triangles", 0xFFFFFFFFu));
  r.point_a = state_vec3(f[3], what + ": point_a");
  r.point_b = state_vec3(f[4], what + ": point_b");
  r.point_a_local = state_vec3(f[5], what + ": point_a_local");
  r.point_b_local = state_vec3(f[6], what + ": point_b_local");
  r.stats.node_pairs = state_count(f[7], what + ": node_pairs");
  r.stats.triangle_pairs = state_count(f[8], what + ": triangle_pairs");
  r.inside = state_inside(f[9], what + ": inside");
  if (!has_penetration) return r;
  r.deepest = state_inside(f[10], what + ": deepest");
  r.deepest_vertex = static_cast<std::uint32_t>(state_count(f[11], what + ": deepest_vertex", 0xFFFFFFFFu));
  r.penetration_lower_bound_is_zero = state_bool(f[12], what + ": penetration_lower_bound_is_zero");
  if (fields == 14) r.curve_length = state_real(f[13], what + ": curve_length");
  return r;
}

DistanceResult distance_py(const PyTree& tree_a, py::handle mesh_a, py::handle pose_a, const PyTree& tree_b,
                           py::handle mesh_b, py::handle pose_b, double absolute_error, double relative_error,
                           double upper_bound, bool solid, bool signed_distance) {
  const std::shared_ptr<const Mesh> ma = mesh_for(tree_a, mesh_a, "mesh_a");
  const std::shared_ptr<const Mesh> mb = mesh_for(tree_b, mesh_b, "mesh_b");
  const Pose pa = to_pose(pose_a, "pose_a");
  const Pose pb = to_pose(pose_b, "pose_b");
  const DistanceOptions options =
      distance_options(absolute_error, relative_error, upper_bound, solid, signed_distance);
  const py::gil_scoped_release release;
  return distance(tree_a.tree, *ma, pa, tree_b.tree, *mb, pb, options);
}

// distance() on two Models (model.hpp): the same answer as on their trees.
DistanceResult distance_models_py(const PyModel& model_a, py::handle pose_a, const PyModel& model_b,
                                  py::handle pose_b, double absolute_error, double relative_error, double upper_bound,
                                  bool solid, bool signed_distance) {
  if (!model_a.model || !model_b.model) throw py::value_error("distance: a Model without a mesh");
  const Pose pa = to_pose(pose_a, "pose_a");
  const Pose pb = to_pose(pose_b, "pose_b");
  const DistanceOptions options =
      distance_options(absolute_error, relative_error, upper_bound, solid, signed_distance);
  const py::gil_scoped_release release;
  return distance(*model_a.model, pa, *model_b.model, pb, options);
}

// (distances (N,), triangles (N, 2) int64 with -1 where no pair is the answer, points_a and
// points_b (N, 3) world, NaN beyond the upper bound).
py::tuple distance_batch_py(const PyTree& tree_a, py::handle mesh_a, py::handle pose_a, const PyTree& tree_b,
                            py::handle mesh_b, py::handle poses_b, double absolute_error, double relative_error,
                            double upper_bound, bool solid, bool signed_distance, py::handle threads_object) {
  const std::shared_ptr<const Mesh> ma = mesh_for(tree_a, mesh_a, "mesh_a");
  const std::shared_ptr<const Mesh> mb = mesh_for(tree_b, mesh_b, "mesh_b");
  const Pose pa = to_pose(pose_a, "pose_a");
  const std::vector<Pose> poses = to_poses(poses_b, "poses");
  const unsigned threads = thread_count(threads_object, "threads");
  const DistanceOptions options =
      distance_options(absolute_error, relative_error, upper_bound, solid, signed_distance);
  std::vector<DistanceResult> results;
  {
    const py::gil_scoped_release release;
    results = distance_batch(tree_a.tree, *ma, pa, tree_b.tree, *mb, poses, options, threads);
  }
  const auto n = static_cast<py::ssize_t>(results.size());
  py::array_t<double> distances(n), points_a({n, py::ssize_t{3}}), points_b({n, py::ssize_t{3}});
  py::array_t<std::int64_t> pairs({n, py::ssize_t{2}});
  auto d = distances.mutable_unchecked<1>();
  auto p = pairs.mutable_unchecked<2>();
  auto qa = points_a.mutable_unchecked<2>(), qb = points_b.mutable_unchecked<2>();
  constexpr double kNoPoint = std::numeric_limits<double>::quiet_NaN();
  for (py::ssize_t i = 0; i < n; ++i) {
    const DistanceResult& r = results[i];
    d(i) = r.distance;
    const bool pair = has_pair(r);
    p(i, 0) = pair ? std::int64_t{r.pair.a} : -1;
    p(i, 1) = pair ? std::int64_t{r.pair.b} : -1;
    for (int k = 0; k < 3; ++k) {
      qa(i, k) = r.beyond_upper_bound ? kNoPoint : r.point_a[k];
      qb(i, k) = r.beyond_upper_bound ? kNoPoint : r.point_b[k];
    }
  }
  return py::make_tuple(distances, pairs, points_a, points_b);
}

DistanceResult brute_force_py(py::handle mesh_a, py::handle pose_a, py::handle mesh_b, py::handle pose_b, bool solid,
                              bool signed_distance) {
  const std::shared_ptr<const Mesh> ma = to_mesh(mesh_a, "mesh_a");
  const std::shared_ptr<const Mesh> mb = to_mesh(mesh_b, "mesh_b");
  const Pose pa = to_pose(pose_a, "pose_a");
  const Pose pb = to_pose(pose_b, "pose_b");
  const py::gil_scoped_release release;
  return distance_brute_force(*ma, pa, *mb, pb, distance_options(0.0, 0.0, std::numeric_limits<double>::infinity(), solid,
                                                               signed_distance));
}

// A deforming mesh's new frame: the same faces, moved vertices. Returns a new Tree over `mesh`
// with the old tree's topology (refit.hpp); the old tree and its mesh are unchanged (Meshes are
// immutable in Python).
PyTree refit_py(const PyTree& tree, py::handle mesh_object, const std::string& fitter, py::handle threads_object) {
  RefitOptions options;
  const auto parsed = parse_fitter(fitter);
  if (!parsed) throw py::value_error("fitter: unknown fitter '" + fitter + "' (see fitter_names())");
  options.fitter = *parsed;
  options.threads = thread_count(threads_object, "threads");
  PyTree result{{}, to_mesh(mesh_object, "mesh"), std::nullopt, fitter};
  const py::gil_scoped_release release;
  result.tree = refitted(tree.tree, *result.mesh, options);
  return result;
}

}  // namespace

void bind_distance(py::module_& m) {
  py::class_<DistanceResult>(m, "Distance",
                             "A distance query's answer: distance, triangles, the closest points (world and each "
                             "mesh's frame), beyond_upper_bound, inside, stats")
      .def_readonly("distance", &DistanceResult::distance,
                    "the minimum distance (0 when touching), or upper_bound when beyond_upper_bound; with "
                    "signed_distance, minus the penetration depth of the deepest vertex when the solids overlap")
      .def_readonly("beyond_upper_bound", &DistanceResult::beyond_upper_bound)
      .def_property_readonly("triangles", &triangles,
                             "(triangle of A, triangle of B), or None (beyond the upper bound, or a solid inside "
                             "the other)")
      .def_property_readonly(
          "point_a", [](const DistanceResult& r) { return point(r, r.point_a); }, "closest point on A, world (3,)")
      .def_property_readonly(
          "point_b", [](const DistanceResult& r) { return point(r, r.point_b); }, "closest point on B, world (3,)")
      .def_property_readonly(
          "point_a_local", [](const DistanceResult& r) { return point(r, r.point_a_local); },
          "the same point in A's mesh frame")
      .def_property_readonly(
          "point_b_local", [](const DistanceResult& r) { return point(r, r.point_b_local); },
          "the same point in B's mesh frame")
      .def_property_readonly("inside", [](const DistanceResult& r) { return std::string(to_string(r.inside)); },
                             "solid only: 'b_in_a' or 'a_in_b' when the distance is 0 by containment, else 'none'")
      .def_property_readonly("deepest", [](const DistanceResult& r) { return std::string(to_string(r.deepest)); },
                             "signed_distance only, the solids overlap (distance < 0): 'a_in_b' (point_a is A's "
                             "vertex inside B, point_b its closest point on B's surface) or 'b_in_a' (point_b is "
                             "B's vertex inside A, point_a on A's surface); else 'none'")
      .def_readonly("deepest_vertex", &DistanceResult::deepest_vertex,
                    "the deepest vertex's index (into A's vertices for 'a_in_b', B's for 'b_in_a'); 0 for 'none'")
      .def_readonly("penetration_lower_bound_is_zero", &DistanceResult::penetration_lower_bound_is_zero,
                    "signed_distance only: the surfaces touch but no vertex lies inside the other solid (touching, "
                    "or crossing edges only): the distance is 0, a lower bound of the penetration depth")
      .def_readonly("curve_length", &DistanceResult::curve_length,
                    "penetration_lower_bound_is_zero only: the length of the surfaces' intersection curve (as "
                    "collide's contacts); 0 otherwise")
      .def_property_readonly("stats",
                             [](const DistanceResult& r) {
                               py::dict d;
                               d["node_pairs"] = r.stats.node_pairs;
                               d["triangle_pairs"] = r.stats.triangle_pairs;
                               return d;
                             })
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&distance_state, &distance_from_state))
      .def("__repr__", [](const DistanceResult& r) {
        return "<tightbvh.Distance " + std::string(r.beyond_upper_bound ? ">= " : "") + std::to_string(r.distance) +
               ">";
      });
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  m.def("distance", &distance_py, py::arg("tree_a"), py::arg("mesh_a"), py::arg("pose_a"), py::arg("tree_b"),
        py::arg("mesh_b"), py::arg("pose_b"), py::arg("absolute_error") = 0.0, py::arg("relative_error") = 0.0,
        py::arg("upper_bound") = kInfinity, py::arg("solid") = false, py::arg("signed_distance") = false,
        "Minimum distance between A at pose_a and B at pose_b, with the closest points and triangles "
        "(distance.hpp). Errors: d_true <= d <= d_true * (1 + relative_error) + absolute_error. upper_bound: "
        "stop early when nothing is closer. solid: closed meshes as solids (0 when one is inside the other). "
        "signed_distance: closed meshes; when the solids overlap, minus the largest depth of a vertex of either "
        "inside the other solid (deepest, deepest_vertex; point_a and point_b the vertex and its closest point).");
  m.def("distance_batch", &distance_batch_py, py::arg("tree_a"), py::arg("mesh_a"), py::arg("pose_a"),
        py::arg("tree_b"), py::arg("mesh_b"), py::arg("poses"), py::arg("absolute_error") = 0.0,
        py::arg("relative_error") = 0.0, py::arg("upper_bound") = kInfinity, py::arg("solid") = false,
        py::arg("signed_distance") = false, py::arg("threads") = 0,
        "One distance per pose of B, on `threads` threads (0: all cores). Returns (distances (N,), triangles "
        "(N, 2) int64, -1 where no pair is the answer, points_a (N, 3), points_b (N, 3) world, NaN beyond the "
        "upper bound), identical for any thread count.");
  m.def("distance_brute_force", &brute_force_py, py::arg("mesh_a"), py::arg("pose_a"), py::arg("mesh_b"),
        py::arg("pose_b"), py::arg("solid") = false, py::arg("signed_distance") = false,
        "The reference: every triangle pair, the same triangle distance and transform as distance(); "
        "signed_distance: every vertex classified and measured without a tree.");
  m.def("refit", &refit_py, py::arg("tree"), py::arg("mesh"), py::arg("fitter") = "pca", py::arg("threads") = 0,
        "A new Tree over `mesh` (the tree's faces, moved vertices) with the tree's topology and every box "
        "fitted again (refit.hpp); ValueError when the face count differs.");
}

void bind_model_distance(py::module_& m) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  m.def("distance", &distance_models_py, py::arg("model_a"), py::arg("pose_a"), py::arg("model_b"), py::arg("pose_b"),
        py::arg("absolute_error") = 0.0, py::arg("relative_error") = 0.0, py::arg("upper_bound") = kInfinity,
        py::arg("solid") = false, py::arg("signed_distance") = false,
        "The same query on two Models (each its mesh and tree, built once; solid and signed_distance take "
        "each model's closedness).");
}

}  // namespace tightbvh::python
