#include "arrays.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

namespace tightbvh::python {
namespace {

using RealArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::string shape_text(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < array.ndim(); ++d) text += (d ? ", " : "") + std::to_string(array.shape(d));
  return text + (array.ndim() == 1 ? ",)" : ")");
}

std::string dtype_text(const py::array& array) { return py::str(array.dtype()).cast<std::string>(); }

// numpy.asarray, with the argument named when the object cannot be read as one array (ragged
// lists and the like).
py::array as_numpy(py::handle object, const std::string& name) {
  try {
    return py::module_::import("numpy").attr("asarray")(object);
  } catch (py::error_already_set& e) {
    throw py::value_error(name + ": cannot be read as an array (" + std::string(e.what()) + ")");
  }
}

// Float or integer dtypes are converted to float64; anything else (bool, complex, object,
// strings) is a TypeError.
RealArray real_array(py::handle object, const std::string& name) {
  const py::array array = as_numpy(object, name);
  const char kind = array.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error(name + ": expected real numbers (a float or integer array), got dtype " + dtype_text(array));
  return RealArray::ensure(array);
}

// `shape` with -1 for "any length"; `expected` is how the message spells it, e.g. "(N, 3)".
void require_shape(const py::array& array, std::initializer_list<py::ssize_t> shape, const std::string& name,
                   const std::string& expected) {
  bool ok = array.ndim() == static_cast<py::ssize_t>(shape.size());
  py::ssize_t d = 0;
  for (const py::ssize_t extent : shape) {
    ok = ok && (extent < 0 || array.shape(d) == extent);
    ++d;
  }
  if (!ok) throw py::value_error(name + ": expected shape " + expected + ", got " + shape_text(array));
}

void require_finite(const double* values, std::size_t count, const std::string& name, const std::string& what) {
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i])) throw py::value_error(name + ": " + what + " has a non-finite value (NaN or Inf)");
}

// Face indices as int64 (or uint64 for unsigned dtypes, so that huge values are not wrapped).
template <class Index>
std::vector<Triangle> checked_faces(const py::array& array, std::size_t vertex_count) {
  const auto faces = py::array_t<Index, py::array::c_style | py::array::forcecast>::ensure(array);
  const auto view = faces.template unchecked<2>();
  std::vector<Triangle> triangles(static_cast<std::size_t>(view.shape(0)));
  for (py::ssize_t r = 0; r < view.shape(0); ++r) {
    for (py::ssize_t c = 0; c < 3; ++c) {
      const Index index = view(r, c);
      if (index < 0 || static_cast<std::uint64_t>(index) >= vertex_count) {
        std::ostringstream msg;
        msg << "faces: row " << r << " has vertex index " << index << ", out of range (there are " << vertex_count
            << " vertices)";
        throw py::value_error(msg.str());
      }
      triangles[r][c] = static_cast<std::uint32_t>(index);
    }
  }
  return triangles;
}

// Proper rotation, the same rule as parse_pose (pose_text.hpp) for the CLI's --pose.
void require_rotation(const Mat3& rotation, const std::string& name) {
  const double error = (rotation.transpose() * rotation - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (error > 1e-6) {
    std::ostringstream msg;
    msg << name << ": rotation is not orthonormal (max |R^T R - I| = " << error << ")";
    throw py::value_error(msg.str());
  }
  if (rotation.determinant() < 0) throw py::value_error(name + ": rotation has determinant -1 (a reflection)");
}

// A (R, t) pair: a tuple or list of exactly two entries (a 4x4 nested list has four).
bool is_pair(py::handle object) {
  return (py::isinstance<py::tuple>(object) || py::isinstance<py::list>(object)) && py::len(object) == 2;
}

Pose pose_from_matrix(const double* m, const std::string& name) {
  require_finite(m, 16, name, "the matrix");
  if (m[12] != 0.0 || m[13] != 0.0 || m[14] != 0.0 || m[15] != 1.0)
    throw py::value_error(name + ": the last row of a 4x4 pose must be (0, 0, 0, 1)");
  Pose pose;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.rotation(r, c) = m[4 * r + c];
    pose.translation[r] = m[4 * r + 3];
  }
  require_rotation(pose.rotation, name);
  return pose;
}

Pose pose_from_parts(const double* r, const double* t, const std::string& name) {
  require_finite(r, 9, name, "the rotation");
  require_finite(t, 3, name, "the translation");
  Pose pose;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) pose.rotation(i, j) = r[3 * i + j];
    pose.translation[i] = t[i];
  }
  require_rotation(pose.rotation, name);
  return pose;
}

}  // namespace

std::vector<Vec3> to_points(py::handle object, const std::string& name) {
  const RealArray array = real_array(object, name);
  require_shape(array, {-1, 3}, name, "(N, 3)");
  const auto view = array.unchecked<2>();
  std::vector<Vec3> points(static_cast<std::size_t>(view.shape(0)));
  for (py::ssize_t i = 0; i < view.shape(0); ++i) {
    points[i] = Vec3(view(i, 0), view(i, 1), view(i, 2));
    if (!points[i].allFinite())
      throw py::value_error(name + ": row " + std::to_string(i) + " has a non-finite coordinate (NaN or Inf)");
  }
  return points;
}

Mesh make_mesh(py::handle vertices, py::handle faces, const std::string& name) {
  Mesh mesh;
  mesh.vertices = to_points(vertices, "vertices");
  const py::array face_array = as_numpy(faces, "faces");
  const char kind = face_array.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::type_error("faces: expected integer vertex indices, got dtype " + dtype_text(face_array));
  require_shape(face_array, {-1, 3}, "faces", "(M, 3)");
  mesh.triangles = kind == 'u' ? checked_faces<std::uint64_t>(face_array, mesh.vertices.size())
                               : checked_faces<std::int64_t>(face_array, mesh.vertices.size());
  (void)check_mesh(mesh, name);  // what is left: no triangles
  return mesh;
}

std::shared_ptr<const Mesh> to_mesh(py::handle object, const std::string& name) {
  if (py::isinstance<Mesh>(object)) return object.cast<std::shared_ptr<Mesh>>();
  if (!py::hasattr(object, "vertices") || !py::hasattr(object, "faces"))
    throw py::type_error(name + ": expected a tightbvh.Mesh or an object with .vertices and .faces arrays, got " +
                         py::str(py::type::of(object).attr("__name__")).cast<std::string>());
  return std::make_shared<const Mesh>(make_mesh(object.attr("vertices"), object.attr("faces"), name));
}

Pose to_pose(py::handle object, const std::string& name) {
  if (object.is_none()) return Pose::identity();
  if (is_pair(object)) {
    const py::tuple parts = py::tuple(py::reinterpret_borrow<py::object>(object));
    const RealArray r = real_array(parts[0], name + "[0]");
    const RealArray t = real_array(parts[1], name + "[1]");
    require_shape(r, {3, 3}, name + "[0]", "(3, 3)");
    require_shape(t, {3}, name + "[1]", "(3,)");
    return pose_from_parts(r.data(), t.data(), name);
  }
  const RealArray m = real_array(object, name);
  require_shape(m, {4, 4}, name, "(4, 4) or a (R, t) pair");
  return pose_from_matrix(m.data(), name);
}

std::vector<Pose> to_poses(py::handle object, const std::string& name) {
  std::vector<Pose> poses;
  // (Rs, ts), not a list of two 4x4 matrices: the first entry is a stack of rotations.
  if (is_pair(object) && as_numpy(py::reinterpret_borrow<py::object>(object)[py::int_(0)], name).ndim() == 3) {
    const py::tuple parts = py::tuple(py::reinterpret_borrow<py::object>(object));
    const RealArray r = real_array(parts[0], name + "[0]");
    const RealArray t = real_array(parts[1], name + "[1]");
    require_shape(r, {-1, 3, 3}, name + "[0]", "(N, 3, 3)");
    require_shape(t, {r.shape(0), 3}, name + "[1]", "(N, 3) with N = " + std::to_string(r.shape(0)));
    for (py::ssize_t i = 0; i < r.shape(0); ++i)
      poses.push_back(pose_from_parts(r.data() + 9 * i, t.data() + 3 * i, name + "[" + std::to_string(i) + "]"));
    return poses;
  }
  const RealArray m = real_array(object, name);
  require_shape(m, {-1, 4, 4}, name, "(N, 4, 4) or a (Rs, ts) pair");
  poses.reserve(static_cast<std::size_t>(m.shape(0)));
  for (py::ssize_t i = 0; i < m.shape(0); ++i)
    poses.push_back(pose_from_matrix(m.data() + 16 * i, name + "[" + std::to_string(i) + "]"));
  return poses;
}

py::array_t<double> to_array(const Vec3& v) { return py::array_t<double>(3, v.data()); }

py::array_t<double> to_array(const Mat3& m) {
  py::array_t<double> array({3, 3});
  auto out = array.mutable_unchecked<2>();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out(i, j) = m(i, j);
  return array;
}

py::array_t<double> to_array(std::span<const Vec3> points) {
  py::array_t<double> array({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  auto out = array.mutable_unchecked<2>();
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int j = 0; j < 3; ++j) out(i, j) = points[i][j];
  return array;
}

unsigned thread_count(py::handle object, const std::string& name) {
  if (py::isinstance<py::bool_>(object) || !py::isinstance<py::int_>(object))
    throw py::type_error(name + ": expected an integer");
  const long long threads = object.cast<long long>();
  if (threads < 0 || threads > 4096)
    throw py::value_error(name + ": must be in [0, 4096], got " + std::to_string(threads));
  return static_cast<unsigned>(threads);
}

}  // namespace tightbvh::python
