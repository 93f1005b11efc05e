// tightbvh.build, Tree (stats, save/load, validate, node arrays), TreeCheck.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <span>

#include "arrays.hpp"
#include "bindings.hpp"
#include "state.hpp"
#include "tightbvh/serialize.hpp"
#include "tightbvh/tree_stats.hpp"
#include "tightbvh/validate_tree.hpp"

namespace tightbvh::python {
namespace {

// The same keys as `tightbvh build --json` (apps/cmd_build.cpp), plus the build time.
py::dict stats_dict(const PyTree& t) {
  const TreeStats s = t.build_stats ? t.build_stats->tree : tree_stats(t.tree);
  py::dict d;
  d["nodes"] = s.nodes;
  d["leaves"] = s.leaves;
  d["depth"] = py::dict(py::arg("min") = s.depth_min, py::arg("max") = s.depth_max);
  d["leaf_triangles"] = py::dict(py::arg("min") = s.leaf_triangles_min, py::arg("avg") = s.leaf_triangles_avg,
                                 py::arg("max") = s.leaf_triangles_max);
  d["sum_volume"] = s.sum_volume;
  d["volume_per_level"] = s.volume_per_level;
  d["bytes"] = s.bytes;
  d["bytes_per_triangle"] = s.bytes_per_triangle;
  d["triangles"] = t.tree.triangle_order.size();
  if (t.build_stats) d["seconds"] = t.build_stats->seconds;
  return d;
}

// Node arrays (copies): center (n, 3), axes (n, 3, 3) with the box axes as columns, half_extents
// (n, 3), first and count (n,) uint32 (tree.hpp: leaves have count > 0).
py::dict node_arrays(const Tree& tree) {
  const auto n = static_cast<py::ssize_t>(tree.nodes.size());
  py::array_t<double> center({n, py::ssize_t{3}}), half({n, py::ssize_t{3}}), axes({n, py::ssize_t{3}, py::ssize_t{3}});
  py::array_t<std::uint32_t> first(n), count(n);
  auto c = center.mutable_unchecked<2>(), h = half.mutable_unchecked<2>();
  auto a = axes.mutable_unchecked<3>();
  auto f = first.mutable_unchecked<1>(), k = count.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const Node& node = tree.nodes[i];
    for (int r = 0; r < 3; ++r) {
      c(i, r) = node.box.center[r];
      h(i, r) = node.box.half_extents[r];
      for (int col = 0; col < 3; ++col) a(i, r, col) = node.box.axes(r, col);
    }
    f(i) = node.first;
    k(i) = node.count;
  }
  py::dict d;
  d["center"] = center;
  d["axes"] = axes;
  d["half_extents"] = half;
  d["first"] = first;
  d["count"] = count;
  return d;
}

// Python ints checked here, so that -1 is "leaf_size: must be >= 1", not a signature mismatch.
std::uint64_t bounded(py::handle value, const char* name, long long low, long long high) {
  if (py::isinstance<py::bool_>(value) || !py::isinstance<py::int_>(value))
    throw py::type_error(std::string(name) + ": expected an integer");
  const long long v = value.cast<long long>();
  if (v < low || v > high)
    throw py::value_error(std::string(name) + ": must be in [" + std::to_string(low) + ", " + std::to_string(high) +
                          "], got " + std::to_string(v));
  return static_cast<std::uint64_t>(v);
}

PyTree build_tree(py::handle mesh_object, const std::string& fitter, const std::string& split, py::handle leaf_size,
                  py::handle threads, py::handle grid, py::handle epsilon, bool improve) {
  const BuildOptions options = build_options(fitter, split, leaf_size, threads, grid, epsilon, improve);
  PyTree result{{}, to_mesh(mesh_object, "mesh"), std::nullopt, to_string(options.fitter)};
  const py::gil_scoped_release release;
  BuildResult built = build_with_stats(*result.mesh, options);
  result.tree = std::move(built.tree);
  result.build_stats = built.stats;
  return result;
}

PyTree load(const std::filesystem::path& path, py::handle mesh) {
  PyTree result;
  if (!mesh.is_none()) result.mesh = to_mesh(mesh, "mesh");
  const py::gil_scoped_release release;
  result.tree = load_tree(path);
  if (result.mesh) {
    const TreeCheck check = validate(result.tree, *result.mesh);
    if (!check.ok()) throw InputError(path.string() + ": not a tree of this mesh: " + check.errors.front());
  }
  return result;
}

TreeCheck check(const PyTree& tree, py::handle mesh_object) {
  if (mesh_object.is_none() && !tree.mesh) {
    const py::gil_scoped_release release;
    return check_structure(tree.tree);
  }
  const std::shared_ptr<const Mesh> mesh = mesh_for(tree, mesh_object, "mesh");
  const py::gil_scoped_release release;
  return validate(tree.tree, *mesh);
}

// BuildStats as a flat tuple, every TreeStats field in declaration order.
py::object build_stats_state(const BuildStats& b) {
  const TreeStats& s = b.tree;
  return py::make_tuple(b.seconds, s.nodes, s.leaves, s.depth_min, s.depth_max, s.leaf_triangles_min,
                        s.leaf_triangles_max, s.leaf_triangles_avg, s.sum_volume,
                        py::tuple(py::cast(s.volume_per_level)), s.bytes, s.bytes_per_triangle);
}

BuildStats state_build_stats(py::handle state) {
  const py::tuple f = state_tuple(state, 12, "Tree build stats");
  const std::string what = "Tree.__setstate__: build stats";
  BuildStats b;
  TreeStats& s = b.tree;
  b.seconds = state_real(f[0], what);
  s.nodes = state_count(f[1], what);
  s.leaves = state_count(f[2], what);
  s.depth_min = state_count(f[3], what);
  s.depth_max = state_count(f[4], what);
  s.leaf_triangles_min = state_count(f[5], what);
  s.leaf_triangles_max = state_count(f[6], what);
  s.leaf_triangles_avg = state_real(f[7], what);
  s.sum_volume = state_real(f[8], what);
  if (!py::isinstance<py::tuple>(f[9])) throw py::type_error(what + ": volume_per_level must be a tuple");
  for (const py::handle v : py::reinterpret_borrow<py::tuple>(f[9])) s.volume_per_level.push_back(state_real(v, what));
  s.bytes = state_count(f[10], what);
  s.bytes_per_triangle = state_real(f[11], what);
  return b;
}

// State: (the tree format's bytes (serialize.hpp), the Mesh or None, the fitter name or None, the
// build stats or None). The mesh is a field of its own, so pickling a tree together with its
// mesh stores the mesh once and the unpickled tree shares the unpickled mesh.
py::object tree_state(const PyTree& t) {
  std::vector<std::byte> bytes;
  {
    const py::gil_scoped_release release;
    bytes = serialize(t.tree);
  }
  return py::make_tuple(py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                        t.mesh ? py::cast(std::const_pointer_cast<Mesh>(t.mesh)) : py::none(),
                        t.fitter ? py::object(py::str(*t.fitter)) : py::none(),
                        t.build_stats ? py::object(build_stats_state(*t.build_stats)) : py::none());
}

PyTree tree_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 4, "Tree");
  if (!py::isinstance<py::bytes>(f[0])) throw py::type_error("Tree.__setstate__: the tree must be bytes");
  const std::string bytes = f[0].cast<std::string>();
  PyTree result;
  if (!f[1].is_none()) {
    if (!py::isinstance<Mesh>(f[1])) throw py::type_error("Tree.__setstate__: the mesh must be a Mesh or None");
    result.mesh = f[1].cast<std::shared_ptr<Mesh>>();
  }
  if (!f[2].is_none()) {
    result.fitter = state_string(f[2], "Tree.__setstate__: fitter");
    if (!parse_fitter(*result.fitter))
      throw py::value_error("Tree.__setstate__: unknown fitter '" + *result.fitter + "'");
  }
  if (!f[3].is_none()) result.build_stats = state_build_stats(f[3]);
  const py::gil_scoped_release release;
  // The tree format's checks (magic, version, sizes, checksum, structure): InputError -> ValueError.
  result.tree = deserialize(std::as_bytes(std::span(bytes.data(), bytes.size())), "Tree.__setstate__");
  if (result.mesh) {
    const TreeCheck check = validate(result.tree, *result.mesh);
    if (!check.ok()) throw InputError("Tree.__setstate__: not a tree of this mesh: " + check.errors.front());
  }
  return result;
}

void bind_tree_class(py::module_& m) {
  py::class_<TreeCheck>(m, "TreeCheck", "The result of Tree.validate: true when valid; errors lists the problems")
      .def_readonly("errors", &TreeCheck::errors)
      .def_property_readonly("ok", &TreeCheck::ok)
      .def("__bool__", &TreeCheck::ok)
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle([](const TreeCheck& c) -> py::object { return py::make_tuple(py::tuple(py::cast(c.errors))); },
                      [](const py::object& state) {
                        const py::tuple f = state_tuple(state, 1, "TreeCheck");
                        if (!py::isinstance<py::tuple>(f[0]))
                          throw py::type_error("TreeCheck.__setstate__: errors must be a tuple of strings");
                        TreeCheck c;
                        for (const py::handle e : py::reinterpret_borrow<py::tuple>(f[0]))
                          c.errors.push_back(state_string(e, "TreeCheck.__setstate__: errors"));
                        return c;
                      }))
      .def("__repr__", [](const TreeCheck& c) {
        return c.ok() ? std::string("<tightbvh.TreeCheck: valid>") : "<tightbvh.TreeCheck: " + c.summary() + ">";
      });
  py::class_<PyTree>(m, "Tree", "A tree of oriented boxes over a mesh (build() or Tree.load()); holds its mesh. Pickles, copies "
                            "and deep-copies (with its mesh, fitter and build stats; the tree in its file format)")
      .def_property_readonly("stats", &stats_dict, "dict: the keys of `tightbvh build --json`, and seconds if built")
      .def_property_readonly(
          "mesh", [](const PyTree& t) { return std::const_pointer_cast<Mesh>(t.mesh); },
          "the Mesh the tree was built over (or loaded with), or None")
      .def_readonly("fitter", &PyTree::fitter, "the fitter it was built with (None for a loaded tree)")
      .def_property_readonly("node_count", [](const PyTree& t) { return t.tree.nodes.size(); })
      .def_property_readonly("triangle_count", [](const PyTree& t) { return t.tree.triangle_order.size(); })
      .def_property_readonly(
          "triangle_order",
          [](const PyTree& t) {
            return py::array_t<std::uint32_t>(static_cast<py::ssize_t>(t.tree.triangle_order.size()),
                                              t.tree.triangle_order.data());
          },
          "(n,) uint32: the leaves' triangle ranges index this (a copy)")
      .def(
          "nodes", [](const PyTree& t) { return node_arrays(t.tree); },
          "dict of arrays (copies): center, axes (columns), half_extents, first, count")
      .def(
          "save",
          [](const PyTree& t, const std::filesystem::path& path) {
            const py::gil_scoped_release release;
            save_tree(t.tree, path);
          },
          py::arg("path"), "Writes the versioned binary format of `tightbvh build -o` (serialize.hpp).")
      .def_static("load", &load, py::arg("path"), py::arg("mesh") = py::none(),
                  "Reads a tree file; with a mesh, checks the tree against it (ValueError if it does not fit) "
                  "and keeps it.")
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&tree_state, &tree_from_state))
      .def("validate", &check, py::arg("mesh") = py::none(),
           "Structure, and with a mesh (given or the tree's own) that every box contains its triangles.")
      .def("__repr__", [](const PyTree& t) {
        return "<tightbvh.Tree: " + std::to_string(t.tree.nodes.size()) + " nodes, " +
               std::to_string(t.tree.triangle_order.size()) + " triangles>";
      });
}

}  // namespace

BuildOptions build_options(const std::string& fitter, const std::string& split, py::handle leaf_size,
                           py::handle threads, py::handle grid, py::handle epsilon, bool improve) {
  BuildOptions options;
  const auto parsed_fitter = parse_fitter(fitter);
  if (!parsed_fitter) throw py::value_error("fitter: unknown fitter '" + fitter + "' (see fitter_names())");
  options.fitter = *parsed_fitter;
  const auto parsed_split = parse_split_method(split);
  if (!parsed_split) throw py::value_error("split: unknown split '" + split + "' (see split_names())");
  options.split = *parsed_split;
  options.leaf_size = static_cast<std::uint32_t>(bounded(leaf_size, "leaf_size", 1, 0xFFFFFFFFLL));
  options.threads = static_cast<unsigned>(bounded(threads, "threads", 0, 4096));
  if (!grid.is_none() && !epsilon.is_none()) throw py::value_error("grid and epsilon exclude each other");
  if (!grid.is_none()) options.fit.grid = static_cast<int>(bounded(grid, "grid", 1, 64));
  if (!epsilon.is_none()) {
    if (py::isinstance<py::bool_>(epsilon) ||
        !(py::isinstance<py::float_>(epsilon) || py::isinstance<py::int_>(epsilon)))
      throw py::type_error("epsilon: expected a number");
    const double e = epsilon.cast<double>();
    if (!(e > 0.0) || !std::isfinite(e)) throw py::value_error("epsilon: must be a positive finite number");
    options.fit.epsilon = e;
  }
  options.fit.improve = improve;
  return options;
}

std::shared_ptr<const Mesh> mesh_for(const PyTree& tree, py::handle mesh, const std::string& name) {
  if (!mesh.is_none()) return to_mesh(mesh, name);
  if (!tree.mesh) throw py::type_error(name + ": None, and the tree has no mesh of its own (loaded without one)");
  return tree.mesh;
}

void bind_tree(py::module_& m) {
  bind_tree_class(m);
  const BuildOptions defaults;
  m.def("build", &build_tree, py::arg("mesh"), py::arg("fitter") = to_string(defaults.fitter),
        py::arg("split") = std::string(to_string(defaults.split)), py::arg("leaf_size") = defaults.leaf_size,
        py::arg("threads") = defaults.threads, py::arg("grid") = py::none(), py::arg("epsilon") = py::none(),
        py::arg("improve") = defaults.fit.improve,
        "Builds a Tree over a mesh (a Mesh or anything with .vertices and .faces). The result is the same "
        "bit for bit for any thread count (threads=0: all cores).");
  m.def("fitter_names", [] {
    const auto names = fitter_names();
    return std::vector<std::string>(names.begin(), names.end());
  });
  m.def("split_names", [] {
    const auto names = split_method_names();
    return std::vector<std::string>(names.begin(), names.end());
  });
}

}  // namespace tightbvh::python
