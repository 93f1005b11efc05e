#pragma once
// Pickle states (py::pickle's __getstate__ / __setstate__) of the module's classes: tuples of
// Python floats, ints, strings, bytes and NumPy arrays, so that pickle (protocol 2+), copy.copy
// and copy.deepcopy work. Python floats and float64 arrays carry their 64 bits exactly, so every
// value comes back bit for bit. __setstate__ gets whatever a pickle stream holds: every reader
// here checks the kind (TypeError) and the size or range (ValueError) and names the class and
// the field, so a malformed state is an exception, never a crash.
#include <pybind11/pybind11.h>

#include <cstdint>
#include <limits>
#include <string>

#include "tightbvh/collide.hpp"
#include "tightbvh/math.hpp"

namespace tightbvh::python {

namespace py = pybind11;

// __reduce_ex__ of every class with a state, for every protocol: rebuild as cls.__new__(cls), then
// __setstate__(state). Python's own path for protocols 0 and 1 (copyreg._reduce_ex) would rebuild
// through object's constructor, which a pybind11 class cannot use (loading such a pickle aborts
// the process); protocols 2+ and copy / deepcopy take this path anyway.
[[nodiscard]] inline py::tuple reduce_ex(const py::object& self, int /*protocol*/) {
  return py::make_tuple(py::module_::import("copyreg").attr("__newobj__"), py::make_tuple(py::type::of(self)),
                        self.attr("__getstate__")());
}

// `state` as a tuple of exactly `size` fields; `type` names the class in messages.
[[nodiscard]] inline py::tuple state_tuple(py::handle state, std::size_t size, const std::string& type) {
  if (!py::isinstance<py::tuple>(state))
    throw py::type_error(type + ".__setstate__: expected a tuple, got " +
                         py::str(py::type::of(state).attr("__name__")).cast<std::string>());
  const py::tuple fields = py::reinterpret_borrow<py::tuple>(state);
  if (fields.size() != size)
    throw py::value_error(type + ".__setstate__: expected " + std::to_string(size) + " fields, got " +
                          std::to_string(fields.size()));
  return fields;
}

[[nodiscard]] inline double state_real(py::handle value, const std::string& what) {
  if (py::isinstance<py::bool_>(value) || !(py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)))
    throw py::type_error(what + ": expected a number");
  return value.cast<double>();
}

[[nodiscard]] inline bool state_bool(py::handle value, const std::string& what) {
  if (!py::isinstance<py::bool_>(value)) throw py::type_error(what + ": expected True or False");
  return value.cast<bool>();
}

// A Python int in [0, max].
[[nodiscard]] inline std::uint64_t state_count(py::handle value, const std::string& what,
                                               std::uint64_t max = std::numeric_limits<std::uint64_t>::max()) {
  if (py::isinstance<py::bool_>(value) || !py::isinstance<py::int_>(value))
    throw py::type_error(what + ": expected an integer");
  if (py::int_(0).attr("__gt__")(value).cast<bool>() || py::int_(max).attr("__lt__")(value).cast<bool>())
    throw py::value_error(what + ": must be in [0, " + std::to_string(max) + "]");
  return value.cast<std::uint64_t>();
}

[[nodiscard]] inline std::string state_string(py::handle value, const std::string& what) {
  if (!py::isinstance<py::str>(value)) throw py::type_error(what + ": expected a string");
  return value.cast<std::string>();
}

// `size` numbers in a tuple (or list), read into out[0..size).
inline void state_reals(py::handle value, double* out, std::size_t size, const std::string& what) {
  if (!py::isinstance<py::tuple>(value) && !py::isinstance<py::list>(value))
    throw py::type_error(what + ": expected a tuple of " + std::to_string(size) + " numbers");
  const py::sequence values = py::reinterpret_borrow<py::sequence>(value);
  if (values.size() != size)
    throw py::value_error(what + ": expected " + std::to_string(size) + " numbers, got " +
                          std::to_string(values.size()));
  for (std::size_t i = 0; i < size; ++i) out[i] = state_real(values[i], what);
}

[[nodiscard]] inline py::tuple reals_state(const double* values, std::size_t size) {
  py::tuple t(size);
  for (std::size_t i = 0; i < size; ++i) t[i] = py::float_(values[i]);
  return t;
}

// Eigen's column-major storage, 3 and 9 numbers.
[[nodiscard]] inline py::tuple vec3_state(const Vec3& v) { return reals_state(v.data(), 3); }
[[nodiscard]] inline py::tuple mat3_state(const Mat3& m) { return reals_state(m.data(), 9); }
[[nodiscard]] inline Vec3 state_vec3(py::handle value, const std::string& what) {
  Vec3 v;
  state_reals(value, v.data(), 3, what);
  return v;
}
[[nodiscard]] inline Mat3 state_mat3(py::handle value, const std::string& what) {
  Mat3 m;
  state_reals(value, m.data(), 9, what);
  return m;
}

// Inside by its name (to_string(Inside)).
[[nodiscard]] inline Inside state_inside(py::handle value, const std::string& what) {
  const std::string name = state_string(value, what);
  for (const Inside inside : {Inside::none, Inside::b_in_a, Inside::a_in_b})
    if (name == to_string(inside)) return inside;
  throw py::value_error(what + ": unknown '" + name + "' (expected none, b_in_a or a_in_b)");
}

}  // namespace tightbvh::python
