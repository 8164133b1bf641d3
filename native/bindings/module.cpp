// The kodawari_native extension: thin bindings over the core, one file per area.
#include <pybind11/pybind11.h>

#include "bind.hpp"
#include "kodawari/version.hpp"

namespace kodawari {
const char* core_version();
}

PYBIND11_MODULE(kodawari_native, m) {
  m.doc() = "Kodawari's C++ core: control-axis FFD, view-dependent rods, quadruped gaits";
  m.attr("__version__") = kodawari::core_version();
  // The add-on compares this with its own version to refuse a stale build.
  m.attr("PYTHON_ABI") = PY_MAJOR_VERSION * 100 + PY_MINOR_VERSION;
  kodawari::bind::bind_swim(m);
  kodawari::bind::bind_ffd(m);
  kodawari::bind::bind_rod(m);
  kodawari::bind::bind_gait(m);
  kodawari::bind::bind_pose(m);
}
