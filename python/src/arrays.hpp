// What the bindings need from the binding library, in one place: NumPy arrays in and out, the
// GIL, and Python's exception types. Everything else in python/src/ calls these helpers, so that
// a move from pybind11 to nanobind rewrites this file and the def() lines, not the logic.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace rccx::python {

namespace py = pybind11;

/// A float64 array argument, C-contiguous and aligned: lists, tuples and arrays of other number
/// types, layouts or unaligned data are converted to it (a copy); a float64 C-contiguous aligned
/// array is taken as it is. (Without NumPy's ALIGNED flag an unaligned float64 buffer, such as a
/// view into bytes, would be read through misaligned double pointers.)
using InArray = py::array_t<double, py::array::c_style | py::array::forcecast |
                                        py::detail::npy_api::NPY_ARRAY_ALIGNED_>;
/// A float64 array returned to Python.
using OutArray = py::array_t<double>;

/// A new, uninitialised C-contiguous float64 array of this shape. Made by NumPy's
/// PyArray_NewFromDescr directly: pybind11's array constructor puts the shape and the strides
/// in heap vectors first, a good part of a small result's cost (one forward(q)'s (4, 4)).
inline OutArray new_array(std::initializer_list<std::size_t> shape) {
  constexpr std::size_t kMaxDims = 4;
  Py_intptr_t dims[kMaxDims] = {};
  if (shape.size() > kMaxDims) throw std::length_error("new_array: more than 4 dimensions");
  std::size_t n = 0;
  for (const std::size_t d : shape) dims[n++] = static_cast<Py_intptr_t>(d);
  const auto& api = py::detail::npy_api::get();
  PyObject* a = api.PyArray_NewFromDescr_(api.PyArray_Type_,
                                          py::dtype::of<double>().release().ptr(),  // stolen
                                          static_cast<int>(n), dims, nullptr, nullptr, 0, nullptr);
  if (a == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<OutArray>(a);
}
/// A new 1-D array holding `values`.
inline OutArray to_array(std::span<const double> values) {
  OutArray out = new_array({values.size()});
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

/// The fast path of one-call functions (Kinematics.forward): `h` read in place when it is a
/// float64 (native order), C-contiguous, aligned NumPy array of shape (n,): its values, without
/// the conversion InArray makes (a new reference through NumPy's PyArray_FromAny), else nullptr
/// (a list, another dtype, shape or layout: the caller converts it to an InArray).
inline const double* f64_vector(py::handle h, std::size_t n) {
  if (!py::array_t<double, py::array::c_style>::check_(h)) return nullptr;
  const auto a = py::reinterpret_borrow<py::array>(h);
  if (a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != n) return nullptr;
  const auto* data = static_cast<const double*>(a.data());
  return reinterpret_cast<std::uintptr_t>(data) % alignof(double) == 0 ? data : nullptr;
}
/// Any argument as an InArray (the conversion pybind11 makes for an InArray parameter); a
/// TypeError naming `what` when NumPy cannot make float64 values of it.
inline InArray to_in_array(py::handle h, const char* what) {
  InArray a = InArray::ensure(h);
  if (!a) throw py::type_error(std::string(what) + ": expected an array of numbers (float64)");
  return a;
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

/// Registers a C++ exception type as a Python exception of module rccx deriving from `bases`
/// (a type or a tuple of types); what() becomes its message.
template <typename E>
py::object add_exception(py::module_& m, const char* name, py::handle bases, const char* doc) {
  auto e = py::register_exception<E>(m, name, bases.ptr());
  e.attr("__module__") = "rccx";
  e.attr("__doc__") = doc;
  return e;
}

}  // namespace rccx::python
