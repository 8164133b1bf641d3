// The one set of converters and validators every bind_<area>.cpp uses. Every entry
// point checks its arguments here and raises ValueError naming the argument (or the
// dict key, as "ground['cell']"), so bad input never reaches the core:
//   arrays    checked_array / checked_output: dtype, shape, layout, finite, bounded;
//             no_overlap: an output must not share memory with an input
//   numbers   require_finite: finite and within ±kMaxMagnitude
//   dicts     dict_arg / item / number_item / int_item / bool_item / sequence_item
//   vectors   NumPy -> core: vec3, unit_vector, to_points, to_quats, to_vector;
//             core -> NumPy: vec3_array, points_array, quats_array, to_array
//   results   require_finite_result: a non-finite result is a ValueError, never returned
//   threads   ExclusiveUse: refuses a second thread on an object whose methods release the GIL
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::bind {

namespace py = pybind11;

// Largest magnitude an input number may have. Blender scenes live far inside it
// (a kilometre in millimetres is 1e6); beyond it squared lengths and products of
// coordinates in the solvers lose all precision or overflow to inf, so the result
// would be NaN or garbage. Checked on every array and scalar the core reads.
constexpr double kMaxMagnitude = 1e9;
inline const char* kMaxMagnitudeText = "1e9";
// Most worker threads an entry point may be asked for (0 = as many as the hardware has).
constexpr unsigned kMaxThreads = 1024;

template <typename T>
const char* dtype_name();
template <>
inline const char* dtype_name<float>() { return "float32"; }
template <>
inline const char* dtype_name<double>() { return "float64"; }
template <>
inline const char* dtype_name<std::int32_t>() { return "int32"; }

inline std::string type_name(const py::handle& obj) { return std::string(py::str(py::type::of(obj).attr("__name__"))); }

// ---------------------------------------------------------------- numbers

// A finite scalar within ±kMaxMagnitude; ValueError naming it otherwise.
inline double require_finite(double value, const std::string& name) {
  if (!std::isfinite(value)) throw py::value_error(name + " must be finite, got " + std::to_string(value));
  if (std::abs(value) > kMaxMagnitude) {
    throw py::value_error(name + " is out of range (|value| must be <= " + kMaxMagnitudeText + ")");
  }
  return value;
}

// ---------------------------------------------------------------- arrays

// Returns `obj` as a C-contiguous array of T without copying; raises ValueError
// when it is another dtype, not contiguous, or not of shape (rows, cols), or (with
// require_finite) holds NaN, inf or a value beyond ±kMaxMagnitude.
// rows < 0 accepts any row count; cols == 0 means a 1-D array.
template <typename T>
py::array_t<T> checked_array(const py::handle& obj, const std::string& name, py::ssize_t rows, py::ssize_t cols,
                             bool require_finite = true) {
  if (!py::isinstance<py::array>(obj)) {
    throw py::value_error(name + " must be a numpy array of " + dtype_name<T>() + ", got " + type_name(obj));
  }
  auto arr = py::reinterpret_borrow<py::array>(obj);
  if (!arr.dtype().is(py::dtype::of<T>())) {
    throw py::value_error(name + " must have dtype " + dtype_name<T>() + ", got " + std::string(py::str(arr.dtype())));
  }
  if (!(arr.flags() & py::array::c_style)) {
    throw py::value_error(name + " must be C-contiguous (use numpy.ascontiguousarray)");
  }
  const py::ssize_t want_ndim = cols == 0 ? 1 : 2;
  auto shape_text = [&] {
    std::string s = "(";
    s += rows < 0 ? "N" : std::to_string(rows);
    if (cols != 0) s += ", " + std::to_string(cols);
    return s + (cols == 0 ? ",)" : ")");
  };
  if (arr.ndim() != want_ndim || (rows >= 0 && arr.shape(0) != rows) || (cols != 0 && arr.shape(1) != cols)) {
    throw py::value_error(name + " must have shape " + shape_text());
  }
  auto typed = py::reinterpret_borrow<py::array_t<T>>(arr);
  if (require_finite) {
    const T* data = typed.data();
    const std::size_t count = static_cast<std::size_t>(typed.size());
    for (std::size_t i = 0; i < count; ++i) {
      const double value = static_cast<double>(data[i]);
      if (!std::isfinite(value)) throw py::value_error(name + " contains NaN or inf");
      if (std::abs(value) > kMaxMagnitude) {
        throw py::value_error(name + " holds a value out of range (|value| must be <= " + kMaxMagnitudeText + ")");
      }
    }
  }
  return typed;
}

// The same for an output array: must be writeable; finiteness is not checked.
template <typename T>
py::array_t<T> checked_output(const py::handle& obj, const std::string& name, py::ssize_t rows, py::ssize_t cols) {
  auto typed = checked_array<T>(obj, name, rows, cols, false);
  if (!typed.writeable()) throw py::value_error(name + " must be writeable");
  return typed;
}

// An output written while the core still reads an input must not share memory with
// it (a view of the input, or the input itself): the core would read its own results.
inline void no_overlap(const py::array& out, const std::string& out_name, const py::array& in,
                       const std::string& in_name) {
  const auto* o = static_cast<const char*>(out.data());
  const auto* i = static_cast<const char*>(in.data());
  const auto o_end = o + out.nbytes(), i_end = i + in.nbytes();
  if (out.nbytes() > 0 && in.nbytes() > 0 && o < i_end && i < o_end) {
    throw py::value_error(out_name + " shares memory with " + in_name + ": pass a separate output array");
  }
}

// ---------------------------------------------------------------- dicts

inline py::dict dict_arg(const py::handle& obj, const std::string& name) {
  if (!py::isinstance<py::dict>(obj)) throw py::value_error(name + " must be a dict, got " + type_name(obj));
  return py::reinterpret_borrow<py::dict>(obj);
}

// d[key]; `where` is how the dict is named in messages ("ground" -> "ground['cell']").
inline std::string key_name(const std::string& where, const char* key) { return where + "['" + key + "']"; }

inline py::object item(const py::dict& d, const char* key, const std::string& where) {
  if (!d.contains(key)) throw py::value_error(where + " is missing key '" + key + "'");
  return d[key];
}

inline double number_item(const py::dict& d, const char* key, const std::string& where) {
  const py::object v = item(d, key, where);
  const std::string name = key_name(where, key);
  if (py::isinstance<py::str>(v) || py::isinstance<py::bytes>(v) || !PyNumber_Check(v.ptr())) {
    throw py::value_error(name + " must be a number, got " + type_name(v));
  }
  double value = 0;
  try {
    value = v.cast<double>();
  } catch (const py::cast_error&) {
    throw py::value_error(name + " must be a number, got " + type_name(v));
  }
  return require_finite(value, name);
}

inline int int_item(const py::dict& d, const char* key, const std::string& where) {
  const py::object v = item(d, key, where);
  const std::string name = key_name(where, key);
  if (!PyIndex_Check(v.ptr())) throw py::value_error(name + " must be an integer, got " + type_name(v));
  try {
    return v.cast<int>();
  } catch (const py::cast_error&) {
    throw py::value_error(name + " is out of range for an integer");
  }
}

inline bool bool_item(const py::dict& d, const char* key, const std::string& where) {
  const py::object v = item(d, key, where);
  if (py::isinstance<py::str>(v) || py::isinstance<py::bytes>(v) || !PyNumber_Check(v.ptr())) {
    throw py::value_error(key_name(where, key) + " must be a bool, got " + type_name(v));
  }
  const int truth = PyObject_IsTrue(v.ptr());
  if (truth < 0) {
    PyErr_Clear();
    throw py::value_error(key_name(where, key) + " must be a bool, got " + type_name(v));
  }
  return truth == 1;
}

inline py::sequence sequence_item(const py::dict& d, const char* key, const std::string& where) {
  const py::object v = item(d, key, where);
  if (!py::isinstance<py::list>(v) && !py::isinstance<py::tuple>(v)) {
    throw py::value_error(key_name(where, key) + " must be a list, got " + type_name(v));
  }
  return py::reinterpret_borrow<py::sequence>(v);
}

// ---------------------------------------------------------------- vectors

inline Vec3 vec3(const py::handle& obj, const std::string& name) {
  const auto a = checked_array<double>(obj, name, 3, 0);
  return Vec3(a.data()[0], a.data()[1], a.data()[2]);
}

inline Vec3 unit_vector(const py::handle& obj, const std::string& name) {
  const Vec3 v = vec3(obj, name);
  if (v.norm() < 1e-12) throw py::value_error(name + " must not be the zero vector");
  return v.normalized();
}

// An already checked float64 (N, 3) array -> points.
inline Vec3List to_points(const py::array_t<double>& checked) {
  const double* d = checked.data();
  Vec3List points(static_cast<std::size_t>(checked.shape(0)));
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = Vec3(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
  return points;
}

// float64 (rows, 3) -> points (rows < 0: any count).
inline Vec3List to_points(const py::handle& obj, const std::string& name, py::ssize_t rows = -1) {
  return to_points(checked_array<double>(obj, name, rows, 3));
}

// float64 (rows, 4) (w, x, y, z) -> quaternions, as written (not normalised).
inline QuatList to_quats(const py::handle& obj, const std::string& name, py::ssize_t rows = -1) {
  const auto a = checked_array<double>(obj, name, rows, 4);
  const double* d = a.data();
  QuatList quats;
  quats.reserve(static_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) quats.emplace_back(d[4 * i], d[4 * i + 1], d[4 * i + 2], d[4 * i + 3]);
  return quats;
}

// float64 (rows,) -> values (rows < 0: any count).
inline std::vector<Real> to_vector(const py::handle& obj, const std::string& name, py::ssize_t rows = -1) {
  const auto a = checked_array<double>(obj, name, rows, 0);
  return std::vector<Real>(a.data(), a.data() + a.shape(0));
}

// v -> float64 (3,).
inline py::array_t<double> vec3_array(const Vec3& v) {
  py::array_t<double> out(3);
  for (int c = 0; c < 3; ++c) out.mutable_data()[c] = v[c];
  return out;
}

// quaternions -> float64 (N, 4) (w, x, y, z).
inline py::array_t<double> quats_array(const QuatList& quats) {
  py::array_t<double> out({static_cast<py::ssize_t>(quats.size()), py::ssize_t(4)});
  double* d = out.mutable_data();
  for (std::size_t i = 0; i < quats.size(); ++i) {
    d[4 * i] = quats[i].w();
    d[4 * i + 1] = quats[i].x();
    d[4 * i + 2] = quats[i].y();
    d[4 * i + 3] = quats[i].z();
  }
  return out;
}

// points -> float64 (N, 3).
inline py::array_t<double> points_array(const Vec3List& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t(3)});
  double* d = out.mutable_data();
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int c = 0; c < 3; ++c) d[3 * i + c] = points[i][c];
  }
  return out;
}

// values -> an array of `shape` (1-D of values.size() when shape is empty).
template <typename T>
py::array_t<T> to_array(const std::vector<T>& values, std::vector<py::ssize_t> shape = {}) {
  if (shape.empty()) shape.push_back(static_cast<py::ssize_t>(values.size()));
  py::array_t<T> out(shape);
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

// ---------------------------------------------------------------- results

// Finite inputs must give finite results; when the core cannot (a near-degenerate
// shape, a diverged solve), the caller gets a ValueError saying which input to change.
template <typename T>
void require_finite_result(const T* data, std::size_t count, const std::string& message) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(static_cast<double>(data[i]))) throw py::value_error(message);
  }
}

// ---------------------------------------------------------------- threads

// Held for the whole of a method call on an object whose methods release the GIL
// (RodSystem): a second thread calling any method of the same object meanwhile gets
// RuntimeError instead of racing on its state. Entered and left with the GIL held.
class ExclusiveUse {
 public:
  ExclusiveUse(const void* object, const char* type) : object_(object) {
    std::lock_guard<std::mutex> lock(mutex());
    if (!busy().insert(object).second) {
      throw std::runtime_error(std::string(type) +
                               " is in use by another thread: call it from one thread at a time");
    }
  }
  ~ExclusiveUse() {
    std::lock_guard<std::mutex> lock(mutex());
    busy().erase(object_);
  }
  ExclusiveUse(const ExclusiveUse&) = delete;
  ExclusiveUse& operator=(const ExclusiveUse&) = delete;

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static std::unordered_set<const void*>& busy() {
    static std::unordered_set<const void*> objects;
    return objects;
  }
  const void* object_;
};

}  // namespace kodawari::bind
