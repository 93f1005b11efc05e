#pragma once
// The pieces of the Python module `tightbvh._tightbvh` (module.cpp puts them together), and the
// Tree as Python sees it: the library's Tree plus the mesh it belongs to, held so that a Tree
// never outlives its mesh.
#include <pybind11/pybind11.h>

#include <memory>
#include <optional>
#include <string>

#include "tightbvh/build.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/shape.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh::python {

namespace py = pybind11;

struct PyTree {
  Tree tree;
  std::shared_ptr<const Mesh> mesh;       // null for a tree loaded without one
  std::optional<BuildStats> build_stats;  // built trees only
  std::optional<std::string> fitter;      // built trees only
};

// tightbvh.Model (bind_scene.cpp; bind_points.cpp adds its point queries).
struct PyModel {
  ModelPtr model;
  std::optional<std::string> fitter;  // built models only
};

// The mesh to use for `tree`: `mesh` converted (to_mesh), or the tree's own mesh when `mesh` is
// None. Throws TypeError naming `name` when neither exists.
[[nodiscard]] std::shared_ptr<const Mesh> mesh_for(const PyTree& tree, py::handle mesh, const std::string& name);

// BuildOptions from tightbvh.build's keyword arguments (ValueError/TypeError naming the argument).
[[nodiscard]] BuildOptions build_options(const std::string& fitter, const std::string& split, py::handle leaf_size,
                                         py::handle threads, py::handle grid, py::handle epsilon, bool improve);

// A shape argument at `pose` (bind_shapes.cpp): a tightbvh.shapes Sphere, Box or Capsule at
// `pose`, or a fitted tightbvh.Box placed where it was fitted and then moved by `pose`; none for
// anything else.
struct ShapeAt {
  Shape shape;
  Pose pose;
};
[[nodiscard]] std::optional<ShapeAt> shape_at(py::handle object, const Pose& pose);

void bind_mesh(py::module_& m);
void bind_fit(py::module_& m);
void bind_tree(py::module_& m);
void bind_collide(py::module_& m);
void bind_distance(py::module_& m);
void bind_scene(py::module_& m);
void bind_points(py::module_& m);  // after bind_scene: methods of tightbvh.Model
void bind_shapes(py::module_& m);
void bind_model_collide(py::module_& m);   // after bind_scene: collide() on two tightbvh.Model
void bind_model_distance(py::module_& m);  // after bind_scene: distance() on two tightbvh.Model

}  // namespace tightbvh::python
