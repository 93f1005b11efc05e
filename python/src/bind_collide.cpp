// tightbvh.collide (on trees and meshes, or on two Models), collide_batch and Result.
#include <pybind11/stl.h>

#include <cstring>
#include <limits>
#include <utility>

#include "arrays.hpp"
#include "bindings.hpp"
#include "state.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/model.hpp"

namespace tightbvh::python {
namespace {

// A QueryResult with the pairs as a (K, 2) uint32 array (columns: triangle of A, triangle of B).
struct PyResult {
  bool hit = false;
  py::array_t<std::uint32_t> pairs;
  QueryStats stats;
  Inside inside = Inside::none;
  // contacts=True only (else None): (segments (K, 2, 3), normals_a (K, 3), normals_b (K, 3),
  // kind (K,) uint8, coplanar (K,) bool, curve_length, polygons {row: (n, 3)}).
  py::object contacts = py::none();
};

// The contacts as arrays (rows parallel to the pairs): a point is stored as a segment of two equal
// ends; a polygon's row holds NaN and its corners are in `polygons`.
py::object contacts_to_python(const QueryResult& r) {
  const auto k = static_cast<py::ssize_t>(r.contacts.size());
  py::array_t<double> segments({k, py::ssize_t{2}, py::ssize_t{3}});
  py::array_t<double> normals_a({k, py::ssize_t{3}}), normals_b({k, py::ssize_t{3}});
  py::array_t<std::uint8_t> kind(k);
  py::array_t<bool> coplanar(k);
  py::dict polygons;
  auto sg = segments.mutable_unchecked<3>();
  auto na = normals_a.mutable_unchecked<2>();
  auto nb = normals_b.mutable_unchecked<2>();
  auto kd = kind.mutable_unchecked<1>();
  auto cp = coplanar.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < k; ++i) {
    const Contact& c = r.contacts[static_cast<std::size_t>(i)];
    kd(i) = static_cast<std::uint8_t>(c.kind);
    cp(i) = c.coplanar;
    for (int j = 0; j < 3; ++j) {
      na(i, j) = c.normal_a[j];
      nb(i, j) = c.normal_b[j];
      const double nan = std::numeric_limits<double>::quiet_NaN();
      sg(i, 0, j) = c.kind == ContactKind::point || c.kind == ContactKind::segment ? c.points[0][j] : nan;
      sg(i, 1, j) = c.kind == ContactKind::segment ? c.points[1][j] : sg(i, 0, j);
    }
    if (c.kind == ContactKind::polygon) {
      py::array_t<double> corners({static_cast<py::ssize_t>(c.count), py::ssize_t{3}});
      auto co = corners.mutable_unchecked<2>();
      for (int v = 0; v < c.count; ++v)
        for (int j = 0; j < 3; ++j) co(v, j) = c.points[static_cast<std::size_t>(v)][j];
      polygons[py::int_(i)] = corners;
    }
  }
  return py::make_tuple(segments, normals_a, normals_b, kind, coplanar, r.curve_length, polygons);
}

static_assert(sizeof(TrianglePair) == 2 * sizeof(std::uint32_t), "pairs are copied as (K, 2) rows");

PyResult to_python(const QueryResult& r, bool contacts) {
  py::array_t<std::uint32_t> pairs({static_cast<py::ssize_t>(r.pairs.size()), py::ssize_t{2}});
  if (!r.pairs.empty()) std::memcpy(pairs.mutable_data(), r.pairs.data(), r.pairs.size() * sizeof(TrianglePair));
  return {r.hit, std::move(pairs), r.stats, r.inside, contacts ? contacts_to_python(r) : py::object(py::none())};
}

// State: (hit, pairs (K, 2) uint32, box_tests, triangle_tests, inside, contacts or None); a
// five-field state (no contacts) is read too.
py::object result_state(const PyResult& r) {
  py::object contacts = r.contacts;
  if (!contacts.is_none()) contacts = py::module_::import("copy").attr("deepcopy")(contacts);
  return py::make_tuple(r.hit, r.pairs.attr("copy")(), r.stats.box_tests, r.stats.triangle_tests,
                        to_string(r.inside), contacts);
}

PyResult result_from_state(const py::object& state) {
  const bool with_contacts = py::isinstance<py::tuple>(state) && py::len(state) == 6;
  const py::tuple f = state_tuple(state, with_contacts ? 6 : 5, "Result");
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
  if (with_contacts) {
    if (!f[5].is_none() && !(py::isinstance<py::tuple>(f[5]) && py::len(f[5]) == 7))
      throw py::value_error(what + ": contacts must be None or a 7-tuple");
    r.contacts = py::reinterpret_borrow<py::object>(f[5]);
  }
  return r;
}

QueryOptions query_options(bool all_pairs, double margin, bool solid, bool contacts = false) {
  QueryOptions options;
  options.contacts = contacts;  // all_pairs and margin 0 only: InputError -> ValueError naming it
  options.solid = solid;  // open meshes: InputError -> ValueError naming the mesh
  options.mode = all_pairs ? QueryMode::all_pairs : QueryMode::first_hit;
  options.margin = margin;  // checked by the query (InputError -> ValueError)
  return options;
}

PyResult collide_py(const PyTree& tree_a, py::handle mesh_a, py::handle pose_a, const PyTree& tree_b, py::handle mesh_b,
                    py::handle pose_b, bool all_pairs, double margin, bool solid, bool contacts) {
  const std::shared_ptr<const Mesh> ma = mesh_for(tree_a, mesh_a, "mesh_a");
  const std::shared_ptr<const Mesh> mb = mesh_for(tree_b, mesh_b, "mesh_b");
  const Pose pa = to_pose(pose_a, "pose_a");
  const Pose pb = to_pose(pose_b, "pose_b");
  QueryResult result;
  {
    const py::gil_scoped_release release;
    result = collide(tree_a.tree, *ma, pa, tree_b.tree, *mb, pb, query_options(all_pairs, margin, solid, contacts));
  }
  return to_python(result, contacts);
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
                        double margin, bool solid, bool contacts) {
  const std::shared_ptr<const Mesh> ma = to_mesh(mesh_a, "mesh_a");
  const std::shared_ptr<const Mesh> mb = to_mesh(mesh_b, "mesh_b");
  const Pose pa = to_pose(pose_a, "pose_a");
  const Pose pb = to_pose(pose_b, "pose_b");
  QueryResult result;
  {
    const py::gil_scoped_release release;
    result = collide_brute_force(*ma, pa, *mb, pb, query_options(all_pairs, margin, solid, contacts));
  }
  return to_python(result, contacts);
}

// collide() on two Models (model.hpp): the wide descent, the same pairs as on their trees.
PyResult collide_models_py(const PyModel& model_a, py::handle pose_a, const PyModel& model_b, py::handle pose_b,
                           bool all_pairs, double margin, bool solid, bool contacts) {
  if (!model_a.model || !model_b.model) throw py::value_error("collide: a Model without a mesh");
  const Pose pa = to_pose(pose_a, "pose_a");
  const Pose pb = to_pose(pose_b, "pose_b");
  QueryResult result;
  {
    const py::gil_scoped_release release;
    result = collide(*model_a.model, pa, *model_b.model, pb, query_options(all_pairs, margin, solid, contacts));
  }
  return to_python(result, contacts);
}

py::object contact_field(const PyResult& r, int i) {
  if (r.contacts.is_none()) return py::none();
  return r.contacts.cast<py::tuple>()[static_cast<std::size_t>(i)];
}

}  // namespace

void bind_collide(py::module_& m) {
  m.attr("CONTACT_KINDS") = py::make_tuple("none", "point", "segment", "polygon");
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
      .def_property_readonly("segments", [](const PyResult& r) { return contact_field(r, 0); },
                             "contacts=True: (K, 2, 3) float64, the contact of each pair (world frame): "
                             "a segment's ends, a point twice, NaN for a coplanar polygon (see polygons); else None")
      .def_property_readonly("normals_a", [](const PyResult& r) { return contact_field(r, 1); },
                             "contacts=True: (K, 3) unit face normals of A's triangles (world frame; zero if "
                             "degenerate)")
      .def_property_readonly("normals_b", [](const PyResult& r) { return contact_field(r, 2); },
                             "contacts=True: (K, 3) unit face normals of B's triangles (world frame; zero if "
                             "degenerate)")
      .def_property_readonly("kind", [](const PyResult& r) { return contact_field(r, 3); },
                             "contacts=True: (K,) uint8, 1 point, 2 segment, 3 polygon (tightbvh.CONTACT_KINDS "
                             "names them)")
      .def_property_readonly("coplanar", [](const PyResult& r) { return contact_field(r, 4); },
                             "contacts=True: (K,) bool, the pair's triangles lie in one plane (exact)")
      .def_property_readonly("curve_length", [](const PyResult& r) { return contact_field(r, 5); },
                             "contacts=True: the intersection curve's length (sum of the segments; polygons add 0)")
      .def_property_readonly("polygons", [](const PyResult& r) { return contact_field(r, 6); },
                             "contacts=True: {row: (n, 3) corners} for the coplanar overlap polygons")
      .def("__bool__", [](const PyResult& r) { return r.hit; })
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&result_state, &result_from_state))
      .def("__repr__", [](const PyResult& r) {
        return std::string("<tightbvh.Result hit=") + (r.hit ? "True" : "False") +
               " pairs=" + std::to_string(r.pairs.shape(0)) + ">";
      });
  m.def("collide", &collide_py, py::arg("tree_a"), py::arg("mesh_a"), py::arg("pose_a"), py::arg("tree_b"),
        py::arg("mesh_b"), py::arg("pose_b"), py::arg("all_pairs") = false, py::arg("margin") = 0.0, py::arg("solid") = false,
        py::arg("contacts") = false,
        "Touching triangle pairs of A at pose_a and B at pose_b (poses: 4x4, (R, t) or None for the identity; "
        "a mesh of None means the tree's own). first hit by default; all_pairs=True: every pair, sorted. "
        "margin > 0: the pairs at distance <= margin (the safety margin of collide.hpp). "
        "solid: closed meshes as solids, a hit also when one is wholly inside the other (Result.inside). "
        "contacts=True (all_pairs, margin 0): also where each pair meets (Result.segments, normals_a, normals_b, "
        "kind, coplanar, curve_length, polygons).");
  m.def("collide_batch", &collide_batch_py, py::arg("tree_a"), py::arg("mesh_a"), py::arg("pose_a"), py::arg("tree_b"),
        py::arg("mesh_b"), py::arg("poses"), py::arg("all_pairs") = false, py::arg("threads") = 0,
        py::arg("margin") = 0.0, py::arg("solid") = false,
        "One query per pose of B ((N, 4, 4) or (Rs (N, 3, 3), ts (N, 3))), on `threads` threads (0: all cores). "
        "Returns (hits (N,) bool, pair_counts (N,) int64), identical for any thread count.");
  m.def("collide_brute_force", &brute_force_py, py::arg("mesh_a"), py::arg("pose_a"), py::arg("mesh_b"),
        py::arg("pose_b"), py::arg("all_pairs") = false, py::arg("margin") = 0.0, py::arg("solid") = false,
        py::arg("contacts") = false,
        "The reference: every triangle pair tested, the same predicate and arithmetic as collide() (for small "
        "meshes and tests).");
}

void bind_model_collide(py::module_& m) {
  m.def("collide", &collide_models_py, py::arg("model_a"), py::arg("pose_a"), py::arg("model_b"), py::arg("pose_b"),
        py::arg("all_pairs") = false, py::arg("margin") = 0.0, py::arg("solid") = false, py::arg("contacts") = false,
        "The same query on two Models (each its mesh and tree, built once): the fastest route for repeated "
        "queries (the models' wide nodes); the same hit and pairs as on their trees, stats counting that "
        "descent's box tests. solid takes each model's closedness.");
}

}  // namespace tightbvh::python
