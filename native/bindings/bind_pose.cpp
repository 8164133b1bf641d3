// Python face of the pose forward kinematics (docs/algorithms.md §3.7): the armature-space
// matrices of a few bones from their channels. Thin: checks arrays, converts, releases the GIL.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "arrays.hpp"
#include "bind.hpp"
#include "kodawari/pose/forward_kinematics.hpp"

namespace kodawari::bind {

void bind_pose(py::module_& m) {
  m.def(
      "pose_forward_kinematics",
      [](const py::handle& parents, const py::handle& rest, const py::handle& channels, const py::handle& rotation_modes,
         const py::handle& inherit_rotation, const py::handle& inherit_scale) {
        auto p = checked_array<std::int32_t>(parents, "parents", -1, 0);
        const py::ssize_t n = p.shape(0);
        auto r = checked_array<double>(rest, "rest", n, 16);
        auto c = checked_array<double>(channels, "channels", n, 10);
        auto modes = checked_array<std::int32_t>(rotation_modes, "rotation_modes", n, 0);
        auto rot = checked_array<std::int32_t>(inherit_rotation, "inherit_rotation", n, 0);
        auto sc = checked_array<std::int32_t>(inherit_scale, "inherit_scale", n, 0);
        std::vector<pose::BoneChannels> bones(static_cast<std::size_t>(n));
        for (py::ssize_t i = 0; i < n; ++i) {
          pose::BoneChannels& b = bones[static_cast<std::size_t>(i)];
          b.parent = p.data()[i];
          for (int k = 0; k < 16; ++k) b.rest[k] = r.data()[i * 16 + k];
          for (int k = 0; k < 10; ++k) b.channels[k] = c.data()[i * 10 + k];
          b.rotation_mode = modes.data()[i];
          b.inherit_rotation = rot.data()[i] != 0;
          const std::int32_t s = sc.data()[i];
          if (s < 0 || s > 3) throw py::value_error("inherit_scale[" + std::to_string(i) + "] must be 0..3");
          b.inherit_scale = static_cast<pose::InheritScale>(s);
        }
        py::array_t<double> out({n, py::ssize_t(16)});
        try {
          py::gil_scoped_release release;
          pose::forward_kinematics(bones, out.mutable_data());
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
        require_finite_result(out.data(), static_cast<std::size_t>(out.size()), "channels and rest give a non-finite pose matrix (a scale or location too large)");
        return out;
      },
      py::arg("parents"), py::arg("rest"), py::arg("channels"), py::arg("rotation_modes"), py::arg("inherit_rotation"),
      py::arg("inherit_scale"),
      "Armature-space pose matrices (N, 16), row-major, of N bones (parents first) from their rest matrices "
      "(N, 16) and channels (N, 10: location, rotation, scale); rotation modes 0 quaternion, 1..6 Euler "
      "XYZ..ZYX, -1 axis-angle; inherit_scale 0 FULL, 1 AVERAGE, 2 NONE, 3 NONE_LEGACY.");
}

}  // namespace kodawari::bind
