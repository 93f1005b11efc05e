#pragma once
// Conversions between Python objects (NumPy arrays, array-likes, trimesh-like meshes, poses) and
// the library's value types. Every check names the Python argument it is about, so a wrong input
// is a TypeError (wrong kind of object or dtype) or a ValueError (wrong shape, NaN/Inf, index out
// of range) that says which argument, never a crash. Inputs are always copied into the library's
// own types, so non-contiguous, strided or read-only arrays are fine everywhere.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tightbvh/mesh.hpp"
#include "tightbvh/pose.hpp"

namespace tightbvh::python {

namespace py = pybind11;

// (N, 3) real numbers (any float or integer dtype) -> points; N may be 0 (the callers decide).
[[nodiscard]] std::vector<Vec3> to_points(py::handle object, const std::string& name);

// A tightbvh.Mesh (shared, not copied), or any object with `.vertices` (N, 3) and `.faces`
// (M, 3) arrays, such as a trimesh.Trimesh (copied and checked).
[[nodiscard]] std::shared_ptr<const Mesh> to_mesh(py::handle object, const std::string& name);

// Checks and copies vertices (N, 3) and faces (M, 3) into a Mesh (check_mesh named `name`).
[[nodiscard]] Mesh make_mesh(py::handle vertices, py::handle faces, const std::string& name);

// None (identity), a 4x4 matrix (last row 0 0 0 1) or a (R, t) pair with R 3x3 and t of length 3.
// The rotation must be proper (orthonormal within 1e-6, determinant +1), as for the CLI's --pose.
[[nodiscard]] Pose to_pose(py::handle object, const std::string& name);

// An (N, 4, 4) array of matrices, or an (Rs, ts) pair with Rs (N, 3, 3) and ts (N, 3).
[[nodiscard]] std::vector<Pose> to_poses(py::handle object, const std::string& name);

// A thread count (a Python int in [0, 4096]; 0: all cores). TypeError for bools and non-integers.
[[nodiscard]] unsigned thread_count(py::handle object, const std::string& name);

// Copies to new NumPy arrays.
[[nodiscard]] py::array_t<double> to_array(const Vec3& v);
[[nodiscard]] py::array_t<double> to_array(const Mat3& m);                 // m(i, j) at [i, j]: columns stay columns
[[nodiscard]] py::array_t<double> to_array(std::span<const Vec3> points);  // (N, 3)

// A read-only (N, 3) view of `values` (3 numbers each), kept alive by `owner`.
template <class T, class Row>
[[nodiscard]] py::array_t<T> readonly_rows(const std::vector<Row>& values, py::handle owner) {
  static_assert(sizeof(Row) == 3 * sizeof(T), "rows must be three packed numbers");
  py::array_t<T> array({static_cast<py::ssize_t>(values.size()), py::ssize_t{3}},
                       {static_cast<py::ssize_t>(sizeof(Row)), static_cast<py::ssize_t>(sizeof(T))},
                       reinterpret_cast<const T*>(values.data()), owner);
  // Trees built over a mesh rely on it never changing: the views must not write into it.
  array.attr("flags").attr("writeable") = false;
  return array;
}

}  // namespace tightbvh::python
