// One bind function per solver area, each in its own bind_<area>.cpp.
#pragma once

#include <pybind11/pybind11.h>

namespace kodawari::bind {
// void bind_<area>(pybind11::module_& m);  declared here as each area lands
void bind_gait(pybind11::module_& m);
}  // namespace kodawari::bind
