// The extension module tightbvh._tightbvh; python/tightbvh/__init__.py re-exports it.
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "tightbvh/error.hpp"

PYBIND11_MODULE(_tightbvh, m) {
  namespace py = pybind11;
  m.doc() =
      "Bounding-volume hierarchies of tight oriented boxes over triangle meshes, for collision detection. "
      "NumPy arrays in and out; the GIL is released while building, fitting and querying.";
  m.attr("__version__") = TIGHTBVH_VERSION;
  // Bad input data is a ValueError with the library's message (which names the source).
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const tightbvh::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  tightbvh::python::bind_mesh(m);
  tightbvh::python::bind_fit(m);
  tightbvh::python::bind_tree(m);
  tightbvh::python::bind_collide(m);
  tightbvh::python::bind_distance(m);
  tightbvh::python::bind_scene(m);
  tightbvh::python::bind_model_collide(m);
  tightbvh::python::bind_model_distance(m);
  tightbvh::python::bind_points(m);
  tightbvh::python::bind_shapes(m);
}
