// kodawari_native: view weights and the rod system (one crossing per frame for all rods).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <stdexcept>

#include "arrays.hpp"
#include "bind.hpp"
#include "kodawari/rod/rod_system.hpp"
#include "kodawari/rod/view_weights.hpp"

namespace kodawari::bind {

template <>
inline const char* dtype_name<std::int32_t>() { return "int32"; }

namespace {

using namespace kodawari::rod;

py::array_t<double> to_array(const std::vector<Real>& values) {
  py::array_t<double> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

py::array_t<double> to_array(const Vec3List& values) {
  py::array_t<double> out({static_cast<py::ssize_t>(values.size()), py::ssize_t(3)});
  double* d = out.mutable_data();
  for (std::size_t i = 0; i < values.size(); ++i) {
    for (int c = 0; c < 3; ++c) d[3 * i + c] = values[i][c];
  }
  return out;
}

Vec3 vec3_arg(const py::handle& obj, const char* name) {
  auto a = checked_array<double>(obj, name, 3, 0);
  return Vec3(a.data()[0], a.data()[1], a.data()[2]);
}

// The frame inputs shared by reset() and step(); validates every array.
FrameInput frame_input(const RodSystem& system, const py::handle& bone_matrices, const py::handle& armature_matrix,
                       const py::handle& camera, const py::handle& gravity, double time, double frame_dt,
                       py::array_t<float>& matrices_keep) {
  const auto rows = static_cast<py::ssize_t>(system.bone_count());
  matrices_keep = checked_array<float>(bone_matrices, "bone_matrices", rows, 16);
  auto arm = checked_array<double>(armature_matrix, "armature_matrix", 4, 4);
  FrameInput in;
  in.bone_matrices = matrices_keep.data();
  in.bone_count = system.bone_count();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) in.armature_matrix(r, c) = arm.data()[4 * r + c];
  }
  if (std::abs(in.armature_matrix.block<3, 3>(0, 0).determinant()) < 1e-12) {
    throw py::value_error("armature_matrix is singular");
  }
  in.has_camera = !camera.is_none();
  if (in.has_camera) in.camera = vec3_arg(camera, "camera");
  in.gravity = vec3_arg(gravity, "gravity");
  if (!std::isfinite(time)) throw py::value_error("time must be finite");
  if (!std::isfinite(frame_dt) || frame_dt < 0) throw py::value_error("frame_dt must be finite and >= 0");
  in.time = time;
  in.frame_dt = frame_dt;
  return in;
}

std::size_t add_rod(RodSystem& system, int parent_bone, int reference_bone, const py::handle& bones,
                    const py::handle& offsets, const py::handle& rest_rotations, double stiffness, double damping,
                    double gravity, int substeps, int iterations, double radius, const py::handle& wind,
                    const py::handle& key_conditions, const py::handle& key_directions,
                    const py::handle& key_rotations, const py::handle& key_speeds, const py::handle& key_influences,
                    const py::handle& key_shapes, bool momentum_control) {
  auto b = checked_array<std::int32_t>(bones, "bones", -1, 0);
  const py::ssize_t n = b.shape(0);
  if (n == 0) throw py::value_error("bones is empty: a rod needs at least one joint");
  auto off = checked_array<double>(offsets, "offsets", n + 1, 3);
  auto rot = checked_array<double>(rest_rotations, "rest_rotations", n, 4);
  auto cond = checked_array<std::int32_t>(key_conditions, "key_conditions", -1, 0);
  const py::ssize_t m = cond.shape(0);
  auto dirs = checked_array<double>(key_directions, "key_directions", m, 3);
  auto krot = checked_array<double>(key_rotations, "key_rotations", m, 4);
  auto speeds = checked_array<double>(key_speeds, "key_speeds", m, 0);
  auto infl = checked_array<double>(key_influences, "key_influences", m, 0);
  auto shapes = checked_array<double>(key_shapes, "key_shapes", m * n, 4);
  RodDefinition rod;
  rod.parent_bone = parent_bone;
  rod.reference_bone = reference_bone;
  rod.bones.assign(b.data(), b.data() + n);
  for (py::ssize_t i = 0; i <= n; ++i) {
    rod.geometry.offsets.emplace_back(off.data()[3 * i], off.data()[3 * i + 1], off.data()[3 * i + 2]);
  }
  for (py::ssize_t i = 0; i < n; ++i) {
    const double* q = rot.data() + 4 * i;
    rod.geometry.rest_rotations.emplace_back(q[0], q[1], q[2], q[3]);
  }
  rod.params.stiffness = stiffness;
  rod.params.damping = damping;
  rod.params.gravity = gravity;
  rod.params.substeps = substeps;
  rod.params.iterations = iterations;
  rod.params.radius = radius;
  rod.params.wind = vec3_arg(wind, "wind");
  rod.params.momentum_control = momentum_control;
  for (py::ssize_t i = 0; i < m; ++i) {
    RodKey key;
    const int c = cond.data()[i];
    if (c < 0 || c > 2) throw py::value_error("key_conditions must be 0 (VIEW), 1 (POSE) or 2 (SPEED)");
    key.condition = static_cast<Condition>(c);
    key.direction = Vec3(dirs.data()[3 * i], dirs.data()[3 * i + 1], dirs.data()[3 * i + 2]);
    const double* q = krot.data() + 4 * i;
    key.rotation = Quat(q[0], q[1], q[2], q[3]);
    key.speed = speeds.data()[i];
    key.influence = infl.data()[i];
    for (py::ssize_t k = 0; k < n; ++k) {
      const double* s = shapes.data() + 4 * (i * n + k);
      key.shape.emplace_back(s[0], s[1], s[2], s[3]);
    }
    rod.keys.push_back(std::move(key));
  }
  try {
    return system.add_rod(std::move(rod));
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

}  // namespace

void bind_rod(py::module_& m) {
  m.def(
      "view_weights",
      [](const py::handle& key_directions, const py::handle& influences, const py::handle& view) {
        auto dirs = checked_array<double>(key_directions, "key_directions", -1, 3);
        const py::ssize_t count = dirs.shape(0);
        auto infl = checked_array<double>(influences, "influences", count, 0);
        const Vec3 v = vec3_arg(view, "view");
        Vec3List d;
        std::vector<Real> p(infl.data(), infl.data() + count);
        for (py::ssize_t i = 0; i < count; ++i) d.emplace_back(dirs.data()[3 * i], dirs.data()[3 * i + 1], dirs.data()[3 * i + 2]);
        try {
          return to_array(view_weights(d, p, v));
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("key_directions"), py::arg("influences"), py::arg("view"),
      "Blend weights of view keys (docs/algorithms.md §3.2): w_i = ((dot(d_i, d) + 1) / 2)^p_i, normalised when\n"
      "their sum s >= 1, w_0 = 1 - s. key_directions (m, 3) float64, influences (m,) float64 > 0, view (3,)\n"
      "float64. Returns float64 (m + 1,), w[0] (the base shape) first.");

  m.def(
      "condition_weights",
      [](const py::handle& similarities, const py::handle& influences) {
        auto s = checked_array<double>(similarities, "similarities", -1, 0);
        auto p = checked_array<double>(influences, "influences", s.shape(0), 0);
        try {
          return to_array(condition_weights(std::vector<Real>(s.data(), s.data() + s.shape(0)),
                                            std::vector<Real>(p.data(), p.data() + p.shape(0))));
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("similarities"), py::arg("influences"),
      "The seed's weights for any condition: similarities in [0, 1] (m,), influences (m,) -> (m + 1,).");

  py::class_<RodSystem>(m, "RodSystem",
                        "Every rod of one armature. Frame inputs and outputs are flat arrays for all bones:\n"
                        "bone_matrices (B, 16) float32 as pose.bones.foreach_get('matrix') gives them,\n"
                        "rotations_out (B, 4) float32 (w, x, y, z) as foreach_get('rotation_quaternion').")
      .def(py::init<std::size_t, unsigned>(), py::arg("bone_count"), py::arg("threads") = 0)
      .def_property_readonly("rod_count", &RodSystem::rod_count)
      .def_property_readonly("bone_count", &RodSystem::bone_count)
      .def("add_rod", &add_rod, py::arg("parent_bone"), py::arg("reference_bone"), py::arg("bones"),
           py::arg("offsets"), py::arg("rest_rotations"), py::arg("stiffness") = 0.5, py::arg("damping") = 1.0,
           py::arg("gravity") = 1.0, py::arg("substeps") = 4, py::arg("iterations") = 1, py::arg("radius") = 0.01,
           py::arg("wind"), py::arg("key_conditions"), py::arg("key_directions"), py::arg("key_rotations"),
           py::arg("key_speeds"), py::arg("key_influences"), py::arg("key_shapes"),
           py::arg("momentum_control") = true,
           "Adds one rod (root first). offsets (n+1, 3): root head in the parent's rest frame, each next head in\n"
           "the previous bone's rest frame, the tip in the last bone's frame. rest_rotations (n, 4) (w, x, y, z):\n"
           "each bone's rest frame in its parent's. Keys: conditions (m,) int32 0 VIEW / 1 POSE / 2 SPEED,\n"
           "directions (m, 3), rotations (m, 4), speeds (m,), influences (m,), shapes (m * n, 4).")
      .def(
          "set_colliders",
          [](RodSystem& self, const py::handle& bones, const py::handle& capsule, const py::handle& offsets,
             const py::handle& radii, const py::handle& lengths) {
            auto b = checked_array<std::int32_t>(bones, "bones", -1, 0);
            const py::ssize_t c = b.shape(0);
            auto cap = checked_array<std::int32_t>(capsule, "capsule", c, 0);
            auto off = checked_array<double>(offsets, "offsets", c, 3);
            auto rad = checked_array<double>(radii, "radii", c, 0);
            auto len = checked_array<double>(lengths, "lengths", c, 0);
            std::vector<ColliderDefinition> list;
            for (py::ssize_t i = 0; i < c; ++i) {
              ColliderDefinition d;
              d.bone = b.data()[i];
              d.capsule = cap.data()[i] != 0;
              d.offset = Vec3(off.data()[3 * i], off.data()[3 * i + 1], off.data()[3 * i + 2]);
              d.radius = rad.data()[i];
              d.length = len.data()[i];
              list.push_back(d);
            }
            try {
              self.set_colliders(std::move(list));
            } catch (const std::invalid_argument& e) {
              throw py::value_error(e.what());
            }
          },
          py::arg("bones"), py::arg("capsule"), py::arg("offsets"), py::arg("radii"), py::arg("lengths"),
          "Spheres (capsule 0) and capsules (1, along the bone's Y for `length`) that follow pose bones.")
      .def(
          "reset",
          [](RodSystem& self, const py::handle& bone_matrices, const py::handle& armature_matrix,
             const py::handle& camera, const py::handle& gravity, double time, const py::handle& rotations_out) {
            py::array_t<float> keep;
            const FrameInput in = frame_input(self, bone_matrices, armature_matrix, camera, gravity, time, 0.0, keep);
            auto out = checked_output<float>(rotations_out, "rotations_out", static_cast<py::ssize_t>(self.bone_count()), 4);
            float* out_data = out.mutable_data();
            py::gil_scoped_release release;
            self.reset(in, out_data);
          },
          py::arg("bone_matrices"), py::arg("armature_matrix"), py::arg("camera"), py::arg("gravity"),
          py::arg("time"), py::arg("rotations_out"),
          "Every rod at rest in its blended rest shape; writes the rod bones' rotations.")
      .def(
          "step",
          [](RodSystem& self, const py::handle& bone_matrices, const py::handle& armature_matrix,
             const py::handle& camera, const py::handle& gravity, double time, double frame_dt,
             const py::handle& rotations_out) {
            py::array_t<float> keep;
            const FrameInput in =
                frame_input(self, bone_matrices, armature_matrix, camera, gravity, time, frame_dt, keep);
            auto out = checked_output<float>(rotations_out, "rotations_out", static_cast<py::ssize_t>(self.bone_count()), 4);
            float* out_data = out.mutable_data();
            py::gil_scoped_release release;
            self.step(in, out_data);
          },
          py::arg("bone_matrices"), py::arg("armature_matrix"), py::arg("camera"), py::arg("gravity"),
          py::arg("time"), py::arg("frame_dt"), py::arg("rotations_out"),
          "Advances every rod by frame_dt seconds (camera: world position (3,) float64, or None).")
      .def("joint_positions", [](const RodSystem& self, std::size_t rod) {
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             return to_array(self.joint_positions(rod));
           }, py::arg("rod"), "Joint positions (heads and tip, (n + 1, 3)) in armature space.")
      .def("joint_velocities", [](const RodSystem& self, std::size_t rod) {
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             return to_array(self.joint_velocities(rod));
           }, py::arg("rod"))
      .def("weights", [](const RodSystem& self, std::size_t rod) {
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             return to_array(self.weights(rod));
           }, py::arg("rod"), "This frame's weights (m + 1,), base shape first.")
      .def("reference_speed", [](const RodSystem& self, std::size_t rod) {
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             return self.reference_speed(rod);
           }, py::arg("rod"))
      .def("rest_shape", [](const RodSystem& self, std::size_t rod) {
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             const QuatList& q = self.rest_shape(rod);
             py::array_t<double> out({static_cast<py::ssize_t>(q.size()), py::ssize_t(4)});
             double* d = out.mutable_data();
             for (std::size_t i = 0; i < q.size(); ++i) {
               d[4 * i] = q[i].w(); d[4 * i + 1] = q[i].x(); d[4 * i + 2] = q[i].y(); d[4 * i + 3] = q[i].z();
             }
             return out;
           }, py::arg("rod"), "The rest shape blended this frame, (n, 4) rotations.")
      .def("save_state", [](const RodSystem& self) { return to_array(self.save_state()); },
           "The full simulation state (float64), for exact per-frame caches.")
      .def("load_state", [](RodSystem& self, const py::handle& state) {
             auto s = checked_array<double>(state, "state", -1, 0, false);
             try {
               self.load_state(std::vector<Real>(s.data(), s.data() + s.shape(0)));
             } catch (const std::invalid_argument& e) {
               throw py::value_error(e.what());
             }
           }, py::arg("state"))
      // The exact per-frame cache (scrubbing), kept natively: see rod/frame_cache.hpp.
      .def("store_frame", [](RodSystem& self, int frame, const py::handle& rotations) {
             auto r = checked_array<float>(rotations, "rotations", static_cast<py::ssize_t>(self.bone_count()), 4);
             const float* data = r.data();
             py::gil_scoped_release release;
             self.store_frame(frame, data);
           }, py::arg("frame"), py::arg("rotations"),
           "Caches this frame: the full state and the rod bones' rows of rotations (B, 4).")
      .def("recall_frame", [](RodSystem& self, int frame, const py::handle& rotations_out, bool load_state) {
             float* out_data = nullptr;
             py::array_t<float> out;
             if (!rotations_out.is_none()) {
               out = checked_output<float>(rotations_out, "rotations_out", static_cast<py::ssize_t>(self.bone_count()), 4);
               out_data = out.mutable_data();
             }
             py::gil_scoped_release release;
             return self.recall_frame(frame, out_data, load_state);
           }, py::arg("frame"), py::arg("rotations_out") = py::none(), py::arg("load_state") = true,
           "Loads a cached frame's state (if load_state) and writes its rod-bone rows into rotations_out;\n"
           "False when the frame is not cached.")
      .def("cached_frames", [](const RodSystem& self) { return self.frame_cache().frames(); },
           "The cached frames, ascending.")
      .def("latest_cached_frame_before", [](const RodSystem& self, int frame) {
             return self.frame_cache().latest_before(frame);
           }, py::arg("frame"), "The latest cached frame before `frame`, or None.")
      .def("clear_cache", [](RodSystem& self) { self.frame_cache().clear(); })
      .def("cached_state", [](const RodSystem& self, int frame) -> py::object {
             const FrameCache::Entry* e = self.frame_cache().find(frame);
             if (e == nullptr) return py::none();
             py::array_t<double> out(static_cast<py::ssize_t>(e->state_size));
             std::copy_n(e->state.get(), e->state_size, out.mutable_data());
             return out;
           }, py::arg("frame"), "A cached frame's full state (as save_state gives it), or None.")
      .def("cached_rotations", [](const RodSystem& self, int frame) -> py::object {
             const FrameCache::Entry* e = self.frame_cache().find(frame);
             if (e == nullptr) return py::none();
             py::array_t<float> out({static_cast<py::ssize_t>(e->rotations.size() / 4), py::ssize_t(4)});
             std::copy(e->rotations.begin(), e->rotations.end(), out.mutable_data());
             return out;
           }, py::arg("frame"), "A cached frame's rod-bone rotations (rod bones, 4), rod by rod, root first.");
}

}  // namespace kodawari::bind
