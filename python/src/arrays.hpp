// What the bindings need from the binding library, in one place: NumPy arrays in and out, the
// GIL, and Python's exception types. Everything else in python/src/ calls these helpers, so that
// a move from pybind11 to nanobind rewrites this file and the def() lines, not the logic.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

namespace rccx::python {

namespace py = pybind11;

/// A float64 array argument, C-contiguous: lists, tuples and arrays of other number types are
/// converted to it (a copy); a float64 C-contiguous array is taken as it is.
using InArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
/// A float64 array returned to Python.
using OutArray = py::array_t<double>;

/// A new, uninitialised C-contiguous float64 array of this shape.
inline OutArray new_array(std::initializer_list<std::size_t> shape) {
  return OutArray(std::vector<py::ssize_t>(shape.begin(), shape.end()));
}
/// A new 1-D array holding `values`.
inline OutArray to_array(std::span<const double> values) {
  OutArray out = new_array({values.size()});
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

inline std::size_t ndim(const InArray& a) {
  return static_cast<std::size_t>(a.ndim());
}
inline std::size_t extent(const InArray& a, std::size_t axis) {
  return static_cast<std::size_t>(a.shape(static_cast<py::ssize_t>(axis)));
}
/// "(3, 4)", as NumPy prints a shape.
inline std::string shape_text(const InArray& a) {
  std::string s = "(";
  for (std::size_t i = 0; i < ndim(a); ++i) {
    s += (i ? ", " : "") + std::to_string(extent(a, i));
  }
  return s + (ndim(a) == 1 ? ",)" : ")");
}

/// Lets other Python threads run while a long computation runs; it touches no Python object.
using ReleaseGil = py::gil_scoped_release;

/// Python's ValueError, KeyError and FileNotFoundError with `message`.
[[noreturn]] inline void raise_value_error(const std::string& message) {
  throw py::value_error(message);
}
[[noreturn]] inline void raise_key_error(const std::string& message) {
  throw py::key_error(message);
}
[[noreturn]] inline void raise_file_not_found(const std::string& message) {
  PyErr_SetString(PyExc_FileNotFoundError, message.c_str());
  throw py::error_already_set();
}

}  // namespace rccx::python
