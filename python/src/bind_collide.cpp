// tightbvh.collide, collide_batch and Result.
#include <pybind11/stl.h>

#include <cstring>
#include <utility>

#include "arrays.hpp"
#include "bindings.hpp"
#include "state.hpp"
#include "tightbvh/collide.hpp"

namespace tightbvh::python {
namespace {

// A QueryResult with the pairs as a (K, 2) uint32 array (columns: triangle of A, triangle of B).
struct PyResult {
  bool hit = false;
  py::array_t<std::uint32_t> pairs;
  QueryStats stats;
  Inside inside = Inside::none;
};

static_assert(sizeof(TrianglePair) == 2 * sizeof(std::uint32_t), "pairs are copied as (K, 2) rows");

PyResult to_python(const QueryResult& r) {
  py::array_t<std::uint32_t> pairs({static_cast<py::ssize_t>(r.pairs.size()), py::ssize_t{2}});
  if (!r.pairs.empty()) std::memcpy(pairs.mutable_data(), r.pairs.data(), r.pairs.size() * sizeof(TrianglePair));
  return {r.hit, std::move(pairs), r.stats, r.inside};
}

// State: (hit, pairs (K, 2) uint32, box_tests, triangle_tests, inside).
py::object result_state(const PyResult& r) {
  return py::make_tuple(r.hit, r.pairs.attr("copy")(), r.stats.box_tests, r.stats.triangle_tests,
                        to_string(r.inside));
}

PyResult result_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 5, "Result");
  const std::string what = "Result.__setstate__";
  PyResult r;
  r.hit = state_bool(f[0], what + ": hit");
  if (!py::isinstance<py::array>(f[1])) throw py::type_error(what + ": pairs must be a NumPy array");
  const py::array pairs = py::reinterpret_borrow<py::array>(f[1]);
  if (pairs.dtype().kind() != 'u' || pairs.dtype().itemsize() != 4)
    throw py::type_error(what + ": pairs must be uint32, got " + py::str(pairs.dtype()).cast<std::string>());
  if (pairs.ndim() != 2 || pairs.shape(1) != 2) throw py::value_error(what + ": pairs must have shape (K, 2)");
  r.pairs = py::array_t<std::uint32_t>::ensure(pairs.attr("copy")());  // own, C-contiguous
  r.stats.box_tests = state_count(f[2], what + ": box_tests");
  r.stats.triangle_tests = state_count(f[3], what + ": triangle_tests");
  r.inside = state_inside(f[4], what + ": inside");
  return r;
}

QueryOptions query_options(bool all_pairs, double margin, bool solid) {
  QueryOptions options;
  options.solid = solid;  // open meshes: InputError -> ValueError naming the mesh
  options.mode = all_pairs ? QueryMode::all_pairs : QueryMode::first_hit;
  options.margin = margin;  // checked by the query (InputError -> ValueError)
  return options;
}

PyResult collide_py(const PyTree& tree_a, py::handle mesh_a, py::handle pose_a, const PyTree& tree_b, py::handle mesh_b,
                    py::handle pose_b, bool all_pairs, double margin, bool solid) {
  const std::shared_ptr<const Mesh> ma = mesh_for(tree_a, mesh_a, "mesh_a");
  const std::shared_ptr<const Mesh> mb = mesh_for(tree_b, mesh_b, "mesh_b");
  const Pose pa = to_pose(pose_a, "pose_a");
  const Pose pb = to_pose(pose_b, "pose_b");
  QueryResult result;
  {
    const py::gil_scoped_release release;
    result = collide(tree_a.tree, *ma, pa, tree_b.tree, *mb, pb, query_options(all_pairs, margin, solid));
  }
  return to_python(result);
}

py::tuple collide_batch_py(const PyTree& tree_a, py::handle mesh_a, py::handle pose_a, const PyTree& tree_b,
                           py::handle mesh_b, py::handle poses_b, bool all_pairs, py::handle threads_object,
                           double margin, bool solid) {
  const std::shared_ptr<const Mesh> ma = mesh_for(tree_a, mesh_a, "mesh_a");
  const std::shared_ptr<const Mesh> mb = mesh_for(tree_b, mesh_b, "mesh_b");
  const Pose pa = to_pose(pose_a, "pose_a");
  const std::vector<Pose> poses = to_poses(poses_b, "poses");
  const unsigned threads = thread_count(threads_object, "threads");
  std::vector<QueryResult> results;
  {
    const py::gil_scoped_release release;
    results = collide_batch(tree_a.tree, *ma, pa, tree_b.tree, *mb, poses, query_options(all_pairs, margin, solid), threads);
  }
  const auto n = static_cast<py::ssize_t>(results.size());
  py::array_t<bool> hits(n);
  py::array_t<std::int64_t> counts(n);
  auto h = hits.mutable_unchecked<1>();
  auto c = counts.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    h(i) = results[i].hit;
    c(i) = static_cast<std::int64_t>(results[i].pairs.size());
  }
  return py::make_tuple(hits, counts);
}

PyResult brute_force_py(py::handle mesh_a, py::handle pose_a, py::handle mesh_b, py::handle pose_b, bool all_pairs,
                        double margin, bool solid) {
  const std::shared_ptr<const Mesh> ma = to_mesh(mesh_a, "mesh_a");
  const std::shared_ptr<const Mesh> mb = to_mesh(mesh_b, "mesh_b");
  const Pose pa = to_pose(pose_a, "pose_a");
  const Pose pb = to_pose(pose_b, "pose_b");
  QueryResult result;
  {
    const py::gil_scoped_release release;
    result = collide_brute_force(*ma, pa, *mb, pb, query_options(all_pairs, margin, solid));
  }
  return to_python(result);
}

}  // namespace

void bind_collide(py::module_& m) {
  py::class_<PyResult>(m, "Result", "A collision query's answer: hit, pairs (K, 2) uint32 (A's triangle, B's), stats")
      .def_readonly("hit", &PyResult::hit)
      .def_readonly("pairs", &PyResult::pairs)
      .def_property_readonly("stats",
                             [](const PyResult& r) {
                               py::dict d;
                               d["box_tests"] = r.stats.box_tests;
                               d["triangle_tests"] = r.stats.triangle_tests;
                               return d;
                             })
      .def_property_readonly("inside", [](const PyResult& r) { return std::string(to_string(r.inside)); },
                             "solid only: 'b_in_a' or 'a_in_b' when the hit is a containment, else 'none'")
      .def("__bool__", [](const PyResult& r) { return r.hit; })
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&result_state, &result_from_state))
      .def("__repr__", [](const PyResult& r) {
        return std::string("<tightbvh.Result hit=") + (r.hit ? "True" : "False") +
               " pairs=" + std::to_string(r.pairs.shape(0)) + ">";
      });
  m.def("collide", &collide_py, py::arg("tree_a"), py::arg("mesh_a"), py::arg("pose_a"), py::arg("tree_b"),
        py::arg("mesh_b"), py::arg("pose_b"), py::arg("all_pairs") = false, py::arg("margin") = 0.0, py::arg("solid") = false,
        "Touching triangle pairs of A at pose_a and B at pose_b (poses: 4x4, (R, t) or None for the identity; "
        "a mesh of None means the tree's own). first hit by default; all_pairs=True: every pair, sorted. "
        "margin > 0: the pairs at distance <= margin (the safety margin of collide.hpp). "
        "solid: closed meshes as solids, a hit also when one is wholly inside the other (Result.inside).");
  m.def("collide_batch", &collide_batch_py, py::arg("tree_a"), py::arg("mesh_a"), py::arg("pose_a"), py::arg("tree_b"),
        py::arg("mesh_b"), py::arg("poses"), py::arg("all_pairs") = false, py::arg("threads") = 0,
        py::arg("margin") = 0.0, py::arg("solid") = false,
        "One query per pose of B ((N, 4, 4) or (Rs (N, 3, 3), ts (N, 3))), on `threads` threads (0: all cores). "
        "Returns (hits (N,) bool, pair_counts (N,) int64), identical for any thread count.");
  m.def("collide_brute_force", &brute_force_py, py::arg("mesh_a"), py::arg("pose_a"), py::arg("mesh_b"),
        py::arg("pose_b"), py::arg("all_pairs") = false, py::arg("margin") = 0.0, py::arg("solid") = false,
        "The reference: every triangle pair tested, the same predicate and arithmetic as collide() (for small "
        "meshes and tests).");
}

}  // namespace tightbvh::python
