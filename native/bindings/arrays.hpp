// Checked views of NumPy arrays for the bindings. Every entry point validates
// shape, dtype, layout and finiteness here and raises ValueError naming the
// argument, so bad input never reaches the core.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstddef>
#include <string>

namespace kodawari::bind {

namespace py = pybind11;

template <typename T>
const char* dtype_name();
template <>
inline const char* dtype_name<float>() { return "float32"; }
template <>
inline const char* dtype_name<double>() { return "float64"; }

// Returns `obj` as a C-contiguous array of T without copying; raises ValueError
// when it is another dtype, not contiguous, or not of shape (rows, cols).
// rows < 0 accepts any row count; cols == 0 means a 1-D array.
template <typename T>
py::array_t<T> checked_array(const py::handle& obj, const char* name, py::ssize_t rows, py::ssize_t cols,
                             bool require_finite = true) {
  if (!py::isinstance<py::array>(obj)) {
    throw py::value_error(std::string(name) + " must be a numpy array of " + dtype_name<T>());
  }
  auto arr = py::reinterpret_borrow<py::array>(obj);
  if (!arr.dtype().is(py::dtype::of<T>())) {
    throw py::value_error(std::string(name) + " must have dtype " + dtype_name<T>() + ", got " +
                          std::string(py::str(arr.dtype())));
  }
  if (!(arr.flags() & py::array::c_style)) {
    throw py::value_error(std::string(name) + " must be C-contiguous (use numpy.ascontiguousarray)");
  }
  const py::ssize_t want_ndim = cols == 0 ? 1 : 2;
  auto shape_text = [&] {
    std::string s = "(";
    s += rows < 0 ? "N" : std::to_string(rows);
    if (cols != 0) s += ", " + std::to_string(cols);
    return s + (cols == 0 ? ",)" : ")");
  };
  if (arr.ndim() != want_ndim || (rows >= 0 && arr.shape(0) != rows) || (cols != 0 && arr.shape(1) != cols)) {
    throw py::value_error(std::string(name) + " must have shape " + shape_text());
  }
  auto typed = py::reinterpret_borrow<py::array_t<T>>(arr);
  if (require_finite) {
    const T* data = typed.data();
    const std::size_t count = static_cast<std::size_t>(typed.size());
    for (std::size_t i = 0; i < count; ++i) {
      if (!std::isfinite(data[i])) throw py::value_error(std::string(name) + " contains NaN or inf");
    }
  }
  return typed;
}

// The same for an output array: must be writeable; finiteness is not checked.
template <typename T>
py::array_t<T> checked_output(const py::handle& obj, const char* name, py::ssize_t rows, py::ssize_t cols) {
  auto typed = checked_array<T>(obj, name, rows, cols, false);
  if (!typed.writeable()) throw py::value_error(std::string(name) + " must be writeable");
  return typed;
}

}  // namespace kodawari::bind
