// tightbvh.Mesh, load_mesh, as_mesh.
#include <pybind11/stl/filesystem.h>

#include <cstring>

#include "arrays.hpp"
#include "bindings.hpp"
#include "state.hpp"

namespace tightbvh::python {
namespace {

// A new (N, 3) array holding `values` (3 numbers each).
template <class T, class Row>
py::array_t<T> rows_copy(const std::vector<Row>& values) {
  static_assert(sizeof(Row) == 3 * sizeof(T), "rows must be three packed numbers");
  py::array_t<T> array({static_cast<py::ssize_t>(values.size()), py::ssize_t{3}});
  if (!values.empty()) std::memcpy(array.mutable_data(), values.data(), values.size() * sizeof(Row));
  return array;
}

}  // namespace

void bind_mesh(py::module_& m) {
  py::class_<Mesh, std::shared_ptr<Mesh>>(m, "Mesh",
                                          "A triangle soup: float64 vertices (N, 3) and uint32 faces (M, 3). "
                                          "Immutable: trees built over it rely on it not changing. Pickles bit for bit.")
      .def(py::init([](py::handle vertices, py::handle faces) {
             return std::make_shared<Mesh>(make_mesh(vertices, faces, "Mesh"));
           }),
           py::arg("vertices"), py::arg("faces"),
           "Copies and checks the arrays: vertices (N, 3) real and finite, faces (M, 3) integers in [0, N), M > 0.")
      .def_property_readonly(
          "vertices", [](py::object self) { return readonly_rows<double>(self.cast<const Mesh&>().vertices, self); },
          "(N, 3) float64, a read-only view")
      .def_property_readonly(
          "faces",
          [](py::object self) { return readonly_rows<std::uint32_t>(self.cast<const Mesh&>().triangles, self); },
          "(M, 3) uint32, a read-only view")
      // State: (vertices (N, 3) float64, faces (M, 3) uint32), copies: the same bits come back,
      // checked again as by the constructor.
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(
          [](const Mesh& mesh) -> py::object {
            return py::make_tuple(rows_copy<double>(mesh.vertices), rows_copy<std::uint32_t>(mesh.triangles));
          },
          [](const py::object& state) {
            const py::tuple fields = state_tuple(state, 2, "Mesh");
            return std::make_shared<Mesh>(make_mesh(fields[0], fields[1], "Mesh.__setstate__"));
          }))
      .def_property_readonly("vertex_count", [](const Mesh& mesh) { return mesh.vertices.size(); })
      .def_property_readonly("face_count", [](const Mesh& mesh) { return mesh.triangles.size(); })
      .def("__repr__", [](const Mesh& mesh) {
        return "<tightbvh.Mesh: " + std::to_string(mesh.vertices.size()) + " vertices, " +
               std::to_string(mesh.triangles.size()) + " faces>";
      });

  m.def(
      "load_mesh",
      [](const std::filesystem::path& path) {
        const py::gil_scoped_release release;
        return std::make_shared<Mesh>(load_mesh(path));
      },
      py::arg("path"), "Loads an OBJ, OFF, STL or PLY file (ValueError naming the file on bad input).");
  m.def(
      "as_mesh", [](py::handle mesh) { return std::const_pointer_cast<Mesh>(to_mesh(mesh, "mesh")); }, py::arg("mesh"),
      "A tightbvh.Mesh itself, or a checked copy of any object with .vertices and .faces (e.g. a "
      "trimesh.Trimesh): convert once when the same mesh goes into many calls.");
}

}  // namespace tightbvh::python
