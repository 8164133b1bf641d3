// One bind function per solver area, each in its own bind_<area>.cpp.
#pragma once

#include <pybind11/pybind11.h>

namespace kodawari::bind {
void bind_swim(pybind11::module_& m);
void bind_ffd(pybind11::module_& m);
void bind_rod(pybind11::module_& m);
void bind_gait(pybind11::module_& m);
}  // namespace kodawari::bind
