// One bind function per solver area, each in its own bind_<area>.cpp.
//
// The binding idiom every area follows (checked by the fuzz tier, tests/fuzz):
//  - Arguments are keyword arguments named as in the core (py::arg on every one).
//    Arrays are NumPy, C-contiguous, of the documented dtype and shape; structured
//    inputs (a gait rig, a gait table, a ground grid) are dicts of such arrays and
//    numbers. Nothing is copied or converted silently: a wrong dtype is an error.
//  - Every argument is checked with the helpers in arrays.hpp (shape, dtype, layout,
//    finite, within ±kMaxMagnitude; dict keys present and of the right type) and a
//    bad one raises ValueError naming it: "gravity ...", "ground['cell'] ...".
//  - Results are returned as new arrays, or written into a caller's array named `out`
//    or `*_out` (checked_output; it must not share memory with an input: no_overlap).
//    A result that is not finite is a ValueError, never returned.
//  - The GIL is released around the core's work. An object whose methods release it
//    takes ExclusiveUse for the whole call: a second thread gets RuntimeError.
//  - Converters between NumPy and the core's types (to_points, points_array, ...) live
//    in arrays.hpp only; a bind file keeps just what is specific to its area.
#pragma once

#include <pybind11/pybind11.h>

namespace kodawari::bind {
void bind_swim(pybind11::module_& m);
void bind_ffd(pybind11::module_& m);
void bind_rod(pybind11::module_& m);
void bind_gait(pybind11::module_& m);
void bind_pose(pybind11::module_& m);
}  // namespace kodawari::bind
